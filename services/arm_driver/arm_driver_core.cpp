#include "services/arm_driver/arm_driver_core.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Dense>

namespace bookgrasp {

std::string driver_state_name(DriverState s) {
  switch (s) {
    case DriverState::kIdle:
      return "IDLE";
    case DriverState::kExecuting:
      return "EXECUTING";
    case DriverState::kStopped:
      return "STOPPED";
    case DriverState::kFault:
      return "FAULT";
  }
  return "?";
}

ArmDriverCore::ArmDriverCore(ArmKinematics kinematics, ArmLimits limits, DriverParams params)
    : kin_(std::move(kinematics)), limits_(std::move(limits)), params_(params) {}

void ArmDriverCore::on_measurement(int64_t now_utime, const Eigen::VectorXd& q, double gripper_width,
                                   bool gripper_contact) {
  if (now_utime > now_) now_ = now_utime;
  q_measured_ = q;
  if (q_cmd_.size() == 0) {
    q_cmd_ = hold_posture(q);
    qd_cmd_ = Eigen::VectorXd::Zero(q.size());
    last_heard_ = now_;
  }
  if (gripper_width_ < 0) hold_gripper(gripper_width, gripper_contact);
}

Eigen::VectorXd ArmDriverCore::hold_posture(const Eigen::VectorXd& measured) const {
  // A joint pushed a little past its limit (the elbow after a Cartesian motion into it) would make the
  // held posture a setpoint the arm rejects: hold the nearest posture within the limits.
  if (limits_.lower.size() != measured.size() || limits_.upper.size() != measured.size()) return measured;
  return measured.cwiseMax(limits_.lower).cwiseMin(limits_.upper);
}

double ArmDriverCore::hold_width(double measured) const {
  // The plates can read a little beyond the stroke (contact, numerical slack): holding that value
  // would be a setpoint the gripper rejects.
  return std::clamp(measured, params_.gripper_min_width, params_.gripper_max_width);
}

void ArmDriverCore::hold_gripper(double measured_width, bool contact) {
  // Holding the measured width of plates that squeeze a book is holding it with no force at all: a driver
  // restarted while the arm carried a book dropped it (tests/deploy/kill_restart_test.sh).
  // Open plates touching a neighbour (within gripper_open_margin of the full stroke) hold nothing: they stay open.
  const bool holding = contact && measured_width < params_.gripper_max_width - params_.gripper_open_margin;
  gripper_width_ = holding ? params_.gripper_min_width : hold_width(measured_width);
  gripper_force_ = holding ? params_.gripper_default_force : 0.0;
}

void ArmDriverCore::restart(int64_t now_utime, const Eigen::VectorXd& q, double gripper_width, bool gripper_contact) {
  now_ = now_utime;
  last_update_ = -1;
  last_heard_ = now_utime;
  q_measured_ = q;
  q_cmd_ = hold_posture(q);
  qd_cmd_ = Eigen::VectorXd::Zero(q.size());
  hold_gripper(gripper_width, gripper_contact);
  stop("the arm's source restarted (simulation reset): motion stopped, holding the new position");
}

std::string ArmDriverCore::command_trajectory(const JointTrajectory& traj, int64_t id) {
  if (!initialised()) return "no measurement of the arm yet (waiting for SIM_STATE)";
  // The current state is where the arm is measured or where it is commanded to be: they differ while
  // the arm catches up with its setpoint (after a Cartesian motion or a stop, by up to a few
  // hundredths of a radian); a planner starts from the measured state (ARM_STATE). Validate against
  // whichever of the two the trajectory starts nearer.
  const Eigen::VectorXd& current = q_measured_.size() == q_cmd_.size() && !traj.positions.empty() &&
                                           traj.positions.front().size() == q_cmd_.size() &&
                                           (traj.positions.front() - q_measured_).cwiseAbs().maxCoeff() <
                                               (traj.positions.front() - q_cmd_).cwiseAbs().maxCoeff()
                                       ? q_measured_
                                       : q_cmd_;
  const std::string why = validate_trajectory(traj, current, limits_, [this](const Eigen::VectorXd& q) {
    return Eigen::Vector3d(kin_.tip_pose(q).translation());
  });
  if (!why.empty()) return why;
  traj_ = traj;
  traj_start_ = now_;
  mode_ = Mode::kTrajectory;
  state_ = DriverState::kExecuting;
  active_id_ = id;
  message_.clear();
  last_heard_ = now_;
  return "";
}

std::string ArmDriverCore::command_cartesian_velocity(const Eigen::Matrix<double, 6, 1>& twist,
                                                      const std::string& frame, int64_t id) {
  if (!initialised()) return "no measurement of the arm yet (waiting for SIM_STATE)";
  if (!twist.allFinite()) return "twist is not finite (NaN or inf)";
  if (frame != "base" && frame != "gripper") return "twist_frame must be 'base' or 'gripper', got '" + frame + "'";
  const double v = twist.head<3>().norm(), w = twist.tail<3>().norm();
  char buf[160];
  if (v > limits_.max_linear_speed * (1 + limits_.relative_tolerance)) {
    std::snprintf(buf, sizeof(buf), "linear speed %.3f m/s > limit %.3f", v, limits_.max_linear_speed);
    return buf;
  }
  if (w > limits_.max_angular_speed * (1 + limits_.relative_tolerance)) {
    std::snprintf(buf, sizeof(buf), "angular speed %.3f rad/s > limit %.3f", w, limits_.max_angular_speed);
    return buf;
  }
  twist_ = twist;
  twist_frame_ = frame;
  mode_ = Mode::kCartesian;
  state_ = DriverState::kExecuting;
  active_id_ = id;
  message_.clear();
  last_heard_ = now_;
  return "";
}

void ArmDriverCore::command_stop(const std::string& reason) {
  stop(reason);
}

void ArmDriverCore::heartbeat() {
  last_heard_ = now_;
}

std::string ArmDriverCore::command_gripper(double width, double force) {
  if (!std::isfinite(width) || !std::isfinite(force)) return "gripper width/force not finite";
  if (width < params_.gripper_min_width - 1e-9 || width > params_.gripper_max_width + 1e-9) {
    char buf[128];
    std::snprintf(buf, sizeof(buf), "gripper width %.4f m outside [%.4f, %.4f]", width, params_.gripper_min_width,
                  params_.gripper_max_width);
    return buf;
  }
  if (force < 0) return "gripper force must be >= 0";
  gripper_width_ = width;
  gripper_force_ = force > 0 ? force : params_.gripper_default_force;
  last_heard_ = now_;
  return "";
}

void ArmDriverCore::stop(const std::string& reason) {
  mode_ = Mode::kHold;
  if (qd_cmd_.size()) qd_cmd_.setZero();
  state_ = DriverState::kStopped;
  message_ = reason;
}

Eigen::VectorXd ArmDriverCore::nullspace_objective() const {
  const int n = static_cast<int>(q_cmd_.size());
  Eigen::VectorXd g = Eigen::VectorXd::Zero(n);
  if (params_.nullspace_gain > 0 && params_.preferred_posture.size() == n)
    g += params_.nullspace_gain * (params_.preferred_posture - q_cmd_);
  const double m = params_.nullspace_limit_margin;
  if (m > 0 && params_.nullspace_limit_gain > 0 && limits_.lower.size() == n && limits_.upper.size() == n) {
    for (int j = 0; j < n; ++j) {
      const double to_lower = q_cmd_[j] - limits_.lower[j], to_upper = limits_.upper[j] - q_cmd_[j];
      if (to_lower < m) g[j] += params_.nullspace_limit_gain * (m - std::max(to_lower, 0.0)) / m;
      if (to_upper < m) g[j] -= params_.nullspace_limit_gain * (m - std::max(to_upper, 0.0)) / m;
    }
  }
  return g;
}

DriverSetpoint ArmDriverCore::update(int64_t now_utime) {
  if (now_utime > now_) now_ = now_utime;
  const double dt = last_update_ < 0 ? 0.0 : (now_ - last_update_) * 1e-6;
  last_update_ = now_;
  if (state_ == DriverState::kExecuting && (now_ - last_heard_) * 1e-6 > params_.heartbeat_timeout_s) {
    char buf[128];
    std::snprintf(buf, sizeof(buf), "no command or heartbeat for %.3f s (timeout %.3f s): stopped",
                  (now_ - last_heard_) * 1e-6, params_.heartbeat_timeout_s);
    stop(buf);
  }
  if (mode_ == Mode::kTrajectory) {
    const double t = (now_ - traj_start_) * 1e-6;
    sample_trajectory(traj_, t, &q_cmd_, &qd_cmd_);
    if (t >= traj_.duration()) {
      mode_ = Mode::kHold;
      state_ = DriverState::kIdle;
      qd_cmd_.setZero();
    }
  } else if (mode_ == Mode::kCartesian && dt > 0) {
    Eigen::Isometry3d tip;
    Jacobian jac;
    kin_.tip_pose_and_jacobian(q_cmd_, tip, jac);
    Eigen::Matrix<double, 6, 1> tw = twist_;
    if (twist_frame_ == "gripper") {
      tw.head<3>() = tip.linear() * twist_.head<3>();
      tw.tail<3>() = tip.linear() * twist_.tail<3>();
    }
    // Damped least squares: qd = J^T (J J^T + lambda^2 I)^-1 twist.
    const double l2 = params_.cartesian_damping * params_.cartesian_damping;
    const Eigen::Matrix<double, 6, 6> jjt = jac * jac.transpose() + l2 * Eigen::Matrix<double, 6, 6>::Identity();
    Eigen::VectorXd qd = jac.transpose() * jjt.ldlt().solve(tw);
    const Eigen::VectorXd secondary = nullspace_objective();
    if (secondary.size() == qd.size() && secondary.squaredNorm() > 0) {
      // Null-space projector of the damped pseudo-inverse J+ = J^T (J J^T + lambda^2 I)^-1: N = I - J+ J.
      const Eigen::MatrixXd jpinv = jac.transpose() * jjt.ldlt().solve(Eigen::Matrix<double, 6, 6>::Identity());
      const Eigen::MatrixXd n = Eigen::MatrixXd::Identity(qd.size(), qd.size()) - jpinv * jac;
      Eigen::VectorXd qn = n * secondary;
      if (qn.norm() > params_.nullspace_max_speed) qn *= params_.nullspace_max_speed / qn.norm();
      qd += qn;
    }
    // Scale down uniformly if a joint would exceed its velocity limit.
    double scale = 1.0;
    for (int j = 0; j < qd.size(); ++j)
      if (std::abs(qd[j]) > limits_.max_velocity[j]) scale = std::min(scale, limits_.max_velocity[j] / std::abs(qd[j]));
    qd *= scale;
    const Eigen::VectorXd q_next = q_cmd_ + qd * dt;
    std::string why;
    for (int j = 0; j < q_next.size() && why.empty(); ++j)
      if (q_next[j] < limits_.lower[j] || q_next[j] > limits_.upper[j])
        why = "Cartesian motion reached the limit of joint " + limits_.joint_names[j] + ": stopped";
    const Eigen::Vector3d p = kin_.tip_pose(q_next).translation();
    if (why.empty() &&
        ((p.array() < limits_.workspace_min.array()).any() || (p.array() > limits_.workspace_max.array()).any()))
      why = "Cartesian motion would leave the workspace: stopped";
    if (why.empty()) {
      q_cmd_ = q_next;
      qd_cmd_ = qd;
    } else {
      stop(why);
    }
  }
  DriverSetpoint sp;
  sp.q = q_cmd_;
  sp.qd = qd_cmd_.size() ? qd_cmd_ : Eigen::VectorXd::Zero(q_cmd_.size());
  sp.gripper_width = gripper_width_ < 0 ? 0.0 : gripper_width_;
  sp.gripper_force = gripper_force_ > 0 ? gripper_force_ : params_.gripper_default_force;
  return sp;
}

}  // namespace bookgrasp
