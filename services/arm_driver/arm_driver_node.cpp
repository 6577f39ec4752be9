#include "services/arm_driver/arm_driver_node.h"

#include <cmath>

#include "bookgrasp/arm_setpoint_t.hpp"
#include "bookgrasp/gripper_setpoint_t.hpp"
#include "common/pose_conversion.h"
#include "common/version.h"

namespace bookgrasp {
namespace {

std::string resolve(const std::string& path) {
  return path.empty() || path[0] == '/' ? path : std::string(kSourceDir) + "/" + path;
}

Eigen::VectorXd vec(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), v.size());
}

JointTrajectory from_message(const joint_trajectory_t& m) {
  JointTrajectory t;
  if (m.num_joints != static_cast<int>(m.joint_names.size()) || m.num_points != static_cast<int>(m.points.size()))
    throw std::invalid_argument("trajectory length fields do not match its arrays");
  t.joint_names = m.joint_names;
  bool has_v = true, has_a = true;
  for (const auto& p : m.points) {
    if (p.num_joints != static_cast<int>(p.positions.size())) throw std::invalid_argument("waypoint length mismatch");
    has_v = has_v && p.velocities.size() == p.positions.size();
    has_a = has_a && p.accelerations.size() == p.positions.size();
  }
  for (const auto& p : m.points) {
    t.times.push_back(p.utime * 1e-6);
    t.positions.push_back(vec(p.positions));
    if (has_v) t.velocities.push_back(vec(p.velocities));
    if (has_a) t.accelerations.push_back(vec(p.accelerations));
  }
  return t;
}

}  // namespace

ArmDriverCore make_arm_driver_core(const Config& root) {
  const Config robot = root.child("robot");
  ArmKinematics kin = ArmKinematics::from_urdf_file(
      resolve(robot.get<std::string>("urdf")), robot.get<std::string>("base_link"), robot.get<std::string>("tip_link"));
  const int n = kin.num_joints();
  const Config lim = root.child("limits");
  ArmLimits limits;
  limits.joint_names = kin.joint_names();
  limits.lower = kin.lower_limits();
  limits.upper = kin.upper_limits();
  limits.max_velocity = kin.velocity_limits() * lim.get_double("velocity_scale", 0.01, 1.0);
  limits.max_acceleration = vec(lim.get_vector("max_acceleration", static_cast<size_t>(n)));
  if ((limits.max_acceleration.array() <= 0).any())
    throw ConfigError(root.source() + ": key 'limits.max_acceleration' must be positive");
  const auto wmin = lim.get_vector("workspace_min", 3), wmax = lim.get_vector("workspace_max", 3);
  limits.workspace_min = Eigen::Vector3d(wmin[0], wmin[1], wmin[2]);
  limits.workspace_max = Eigen::Vector3d(wmax[0], wmax[1], wmax[2]);
  if ((limits.workspace_min.array() >= limits.workspace_max.array()).any())
    throw ConfigError(root.source() + ": key 'limits.workspace_min' must be below 'limits.workspace_max'");
  limits.start_tolerance = lim.get_double("start_tolerance_rad", 0.0, 0.5);
  limits.max_linear_speed = lim.get_double("max_linear_speed", 0.001, 1.0);
  limits.max_angular_speed = lim.get_double("max_angular_speed", 0.001, 3.0);
  DriverParams p;
  p.heartbeat_timeout_s = root.get_double("heartbeat_timeout_s", 0.01, 10.0);
  p.cartesian_damping = root.get_double("cartesian_damping", 0.0, 1.0);
  p.nullspace_gain = root.get_double("cartesian_nullspace.gain", 0.0, 10.0);
  p.nullspace_max_speed = root.get_double("cartesian_nullspace.max_speed", 0.0, 2.0);
  p.nullspace_limit_margin = root.get_double("cartesian_nullspace.limit_margin_rad", 0.0, 1.0);
  p.nullspace_limit_gain = root.get_double("cartesian_nullspace.limit_gain", 0.0, 10.0);
  const std::vector<double> pp = root.get_vector("cartesian_nullspace.preferred_posture", 7);
  p.preferred_posture = Eigen::Map<const Eigen::VectorXd>(pp.data(), 7);
  for (int j = 0; j < 7; ++j)
    if (pp[j] < limits.lower[j] || pp[j] > limits.upper[j])
      throw ConfigError(root.source() + ": key 'cartesian_nullspace.preferred_posture': joint " +
                        std::to_string(j + 1) + " outside its limits");
  const Config g = root.child("gripper");
  p.gripper_min_width = g.get_double("min_width", 0.0, 0.1);
  p.gripper_max_width = g.get_double("max_width", 0.0, 0.1);
  p.gripper_default_force = g.get_double("default_force_n", 0.0, 1000.0);
  p.gripper_open_margin = g.get_double("open_margin_m", 0.0, 0.05);
  return ArmDriverCore(std::move(kin), std::move(limits), p);
}

ArmDriverNode::ArmDriverNode(const Config& root)
    : Component(root.get<std::string>("service.name"), root.get_choice("backend", {"sim"})),
      core_(make_arm_driver_core(root)),
      setpoint_period_s_(1.0 / root.get_double("setpoint_rate_hz", 1.0, 1000.0)) {
  const Config c = root.child("channels");
  ch_.arm_state = c.get<std::string>("arm_state");
  ch_.arm_setpoint = c.get<std::string>("arm_setpoint");
  ch_.gripper_setpoint = c.get<std::string>("gripper_setpoint");
  ch_.arm_command = c.get<std::string>("arm_command");
  subscribe(ch_.arm_command, &ArmDriverNode::on_arm_command);
  subscribe(c.get<std::string>("gripper_command"), &ArmDriverNode::on_gripper_command);
  subscribe(c.get<std::string>("sim_state"), &ArmDriverNode::on_sim_state);
}

void ArmDriverNode::on_sim_state(const sim_state_t& msg) {
  const auto& names = core_.limits().joint_names;
  Eigen::VectorXd q(names.size()), qd(names.size());
  for (size_t j = 0; j < names.size(); ++j) {
    int found = -1;
    for (int i = 0; i < msg.num_joints && i < static_cast<int>(msg.joint_names.size()); ++i)
      if (msg.joint_names[i] == names[j]) found = i;
    if (found < 0 || found >= static_cast<int>(msg.joint_positions.size()) ||
        found >= static_cast<int>(msg.joint_velocities.size()))
      throw std::invalid_argument("SIM_STATE has no joint '" + names[j] + "'");
    q[j] = msg.joint_positions[found];
    qd[j] = msg.joint_velocities[found];
  }
  if (!q.allFinite() || !std::isfinite(msg.gripper_width_m)) throw std::invalid_argument("SIM_STATE has NaN joints");
  const TimeOrder order = measure_order_.check(msg.utime);
  if (order == TimeOrder::kStale) throw std::invalid_argument("SIM_STATE " + measure_order_.describe(msg.utime, order));
  last_measure_utime_ = msg.utime;
  q_ = q;
  qd_ = qd;
  gripper_width_ = msg.gripper_width_m;
  gripper_contact_ = msg.gripper_contact;
  if (order == TimeOrder::kRestarted) {
    report_error("SIM_STATE " + measure_order_.describe(msg.utime, order));
    core_.restart(msg.utime, q, msg.gripper_width_m, msg.gripper_contact);
    last_setpoint_utime_ = -1;
  } else {
    core_.on_measurement(msg.utime, q, msg.gripper_width_m, msg.gripper_contact);
  }
  if (last_setpoint_utime_ >= 0 && (msg.utime - last_setpoint_utime_) * 1e-6 < setpoint_period_s_ - 1e-9) return;
  last_setpoint_utime_ = msg.utime;
  const DriverSetpoint sp = core_.update(msg.utime);
  arm_setpoint_t a{};
  a.utime = msg.utime;
  a.num_joints = static_cast<int32_t>(sp.q.size());
  a.positions.assign(sp.q.data(), sp.q.data() + sp.q.size());
  a.velocities.assign(sp.qd.data(), sp.qd.data() + sp.qd.size());
  publish(ch_.arm_setpoint, a);
  gripper_setpoint_t g{};
  g.utime = msg.utime;
  g.width_m = sp.gripper_width;
  g.max_force_n = sp.gripper_force;
  publish(ch_.gripper_setpoint, g);
  publish_state(msg.utime);
}

void ArmDriverNode::on_arm_command(const arm_command_t& msg) {
  std::string why;
  switch (msg.mode) {
    case arm_command_t::HEARTBEAT:
      core_.heartbeat();
      return;
    case arm_command_t::STOP:
      core_.command_stop("stop commanded (command " + std::to_string(msg.command_id) + ")");
      break;
    case arm_command_t::TRAJECTORY:
      why = core_.command_trajectory(from_message(msg.trajectory), msg.command_id);
      break;
    case arm_command_t::CARTESIAN_VELOCITY: {
      Eigen::Matrix<double, 6, 1> tw;
      for (int i = 0; i < 6; ++i) tw[i] = msg.twist[i];
      why = core_.command_cartesian_velocity(tw, msg.twist_frame, msg.command_id);
      break;
    }
    default:
      why = "unknown arm command mode " + std::to_string(static_cast<int>(msg.mode));
  }
  if (!why.empty()) reject(ch_.arm_command, "command " + std::to_string(msg.command_id) + " refused: " + why);
  publish_state(last_measure_utime_);
}

void ArmDriverNode::on_gripper_command(const gripper_command_t& msg) {
  std::string why;
  switch (msg.mode) {
    case gripper_command_t::MOVE:
      why = core_.command_gripper(msg.width_m, msg.force_n);
      break;
    case gripper_command_t::GRASP:
      why = core_.command_gripper(0.0, msg.force_n);
      break;
    case gripper_command_t::STOP:
      why = core_.command_gripper(gripper_width_, msg.force_n);
      break;
    default:
      why = "unknown gripper command mode " + std::to_string(static_cast<int>(msg.mode));
  }
  if (!why.empty())
    throw std::invalid_argument("gripper command " + std::to_string(msg.command_id) + " refused: " + why);
}

void ArmDriverNode::publish_state(int64_t utime) {
  if (q_.size() == 0) return;
  arm_state_t s{};
  s.utime = utime;
  s.num_joints = static_cast<int32_t>(q_.size());
  s.joint_names = core_.limits().joint_names;
  s.positions.assign(q_.data(), q_.data() + q_.size());
  s.velocities.assign(qd_.data(), qd_.data() + qd_.size());
  s.end_effector = isometry_to_pose(core_.kinematics().tip_pose(q_), "base", "gripper", utime);
  s.gripper_width_m = gripper_width_;
  s.gripper_contact = gripper_contact_;
  s.state = static_cast<int8_t>(core_.state());
  s.active_command_id = core_.active_command_id();
  s.message = core_.message();
  publish(ch_.arm_state, s);
}

}  // namespace bookgrasp
