#include "common/kinematics/inverse_kinematics.h"

#include <cmath>
#include <random>
#include <stdexcept>

#include <Eigen/Cholesky>

namespace bookgrasp {

InverseKinematics::InverseKinematics(ArmKinematics kinematics, IkParams params)
    : kin_(std::move(kinematics)), params_(std::move(params)) {
  const int n = kin_.num_joints();
  if (params_.preferred_posture.size() == 0) params_.preferred_posture = Eigen::VectorXd::Zero(n);
  if (params_.preferred_posture.size() != n)
    throw std::invalid_argument("IK preferred posture has " + std::to_string(params_.preferred_posture.size()) +
                                " values, the arm has " + std::to_string(n) + " joints");
  if (!kin_.within_limits(params_.preferred_posture))
    throw std::invalid_argument("IK preferred posture is outside the joint limits");
  if (params_.position_tolerance_m <= 0 || params_.orientation_tolerance_rad <= 0 || params_.max_iterations <= 0 ||
      params_.damping <= 0 || params_.max_step_rad <= 0 || params_.max_restarts < 0 ||
      params_.orientation_weight_m <= 0 || params_.nullspace_gain < 0 || params_.posture_iterations < 0)
    throw std::invalid_argument("IK parameters must be positive (tolerances, iterations, damping, step, weight)");
}

IkResult InverseKinematics::solve_once(const Eigen::Isometry3d& target, const Eigen::VectorXd& seed_q,
                                       int max_iterations, int posture_iterations) const {
  const int posture_budget = posture_iterations >= 0 ? posture_iterations : params_.posture_iterations;
  const int n = kin_.num_joints();
  const Eigen::VectorXd& lo = kin_.lower_limits();
  const Eigen::VectorXd& hi = kin_.upper_limits();
  IkResult r;
  r.attempts = 1;
  Eigen::VectorXd q = seed_q.cwiseMax(lo).cwiseMin(hi);
  Eigen::Isometry3d tip;
  Jacobian jac(6, n);
  const double w = params_.orientation_weight_m;
  const double lambda2 = params_.damping * params_.damping;
  Eigen::Matrix<double, 6, 1> err;
  double pos_err = 0, rot_err = 0;
  Eigen::VectorXd best_q = q;  // last iterate within the tolerances
  int posture_left = posture_budget;
  for (int it = 0;; ++it) {
    kin_.tip_pose_and_jacobian(q, tip, jac);
    err.head<3>() = target.translation() - tip.translation();
    err.tail<3>() = orientation_error(tip.linear(), target.linear());
    const double p_err = err.head<3>().norm(), o_err = err.tail<3>().norm();
    const bool converged = p_err < params_.position_tolerance_m && o_err < params_.orientation_tolerance_rad;
    if (converged) {
      r.success = true;
      best_q = q;
      pos_err = p_err;
      rot_err = o_err;
      if (posture_left-- <= 0 || params_.nullspace_gain <= 0) break;
    } else if (r.success) {
      break;  // a posture step left the tolerance: keep the previous iterate
    } else {
      best_q = q;
      pos_err = p_err;
      rot_err = o_err;
    }
    if (it >= max_iterations + (r.success ? posture_budget : 0)) break;
    r.iterations = it + 1;
    // Weighted task: orientation rows scaled to metres so damping acts evenly.
    jac.bottomRows<3>() *= w;
    err.tail<3>() *= w;
    // Joints resting on a limit and pushed further out are removed from the task for this step.
    Eigen::VectorXd dq;
    for (int pass = 0; pass < 2; ++pass) {
      const Eigen::Matrix<double, 6, 6> jjt =
          jac * jac.transpose() + lambda2 * Eigen::Matrix<double, 6, 6>::Identity();
      dq = jac.transpose() * jjt.ldlt().solve(err);
      bool blocked = false;
      for (int k = 0; k < n; ++k) {
        if ((q[k] <= lo[k] && dq[k] < 0) || (q[k] >= hi[k] && dq[k] > 0)) {
          if (jac.col(k).squaredNorm() > 0) blocked = true;
          jac.col(k).setZero();
        }
      }
      if (!blocked) break;
    }
    // Null space: pull towards the preferred posture without disturbing the task (to first order).
    if (params_.nullspace_gain > 0) {
      const Eigen::VectorXd posture = params_.nullspace_gain * (params_.preferred_posture - q);
      // Projector from a nearly undamped pseudo-inverse: the damped one leaks into the task and
      // would stall convergence a few millimetres short of the target.
      const Eigen::Matrix<double, 6, 6> jjt_exact =
          jac * jac.transpose() + 1e-8 * Eigen::Matrix<double, 6, 6>::Identity();
      const Eigen::VectorXd projected = posture - jac.transpose() * jjt_exact.ldlt().solve(jac * posture);
      if (converged && projected.cwiseAbs().maxCoeff() < 1e-4) break;  // posture settled
      dq += projected;
    } else if (converged) {
      break;
    }
    const double step = dq.cwiseAbs().maxCoeff();
    if (step > params_.max_step_rad) dq *= params_.max_step_rad / step;
    q = (q + dq).cwiseMax(lo).cwiseMin(hi);
  }
  q = best_q;
  r.q = q;
  r.position_error_m = pos_err;
  r.orientation_error_rad = rot_err;
  if (!r.success) {
    r.reason = "did not converge in " + std::to_string(max_iterations) + " iterations (position error " +
               std::to_string(pos_err) + " m, orientation error " + std::to_string(rot_err) + " rad)";
  }
  return r;
}

IkResult InverseKinematics::solve(const Eigen::Isometry3d& target, const Eigen::VectorXd& seed_q) const {
  return solve(target, seed_q, params_.seed);
}

IkResult InverseKinematics::solve(const Eigen::Isometry3d& target, const Eigen::VectorXd& seed_q,
                                  uint64_t restart_seed) const {
  const int n = kin_.num_joints();
  if (seed_q.size() != n) {
    IkResult r;
    r.reason = "seed has " + std::to_string(seed_q.size()) + " values, the arm has " + std::to_string(n) + " joints";
    return r;
  }
  if (!target.matrix().allFinite()) {
    IkResult r;
    r.q = seed_q;
    r.reason = "target pose is not finite (NaN or infinity)";
    return r;
  }
  std::mt19937_64 rng(restart_seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  IkResult best;
  int attempts = 0, iterations = 0;
  const int total = 2 + params_.max_restarts;
  for (int a = 0; a < total; ++a) {
    Eigen::VectorXd start(n);
    if (a == 0) {
      start = seed_q;
    } else if (a == 1) {
      start = params_.preferred_posture;
    } else {
      for (int k = 0; k < n; ++k)
        start[k] = kin_.lower_limits()[k] + unit(rng) * (kin_.upper_limits()[k] - kin_.lower_limits()[k]);
    }
    IkResult r = solve_once(target, start, params_.max_iterations);
    ++attempts;
    iterations += r.iterations;
    const auto score = [](const IkResult& x) { return x.position_error_m + 0.2 * x.orientation_error_rad; };
    if (a == 0 || r.success || score(r) < score(best)) best = r;
    if (r.success) break;
  }
  best.attempts = attempts;
  best.iterations = iterations;
  if (!best.success) {
    best.reason = "no IK solution after " + std::to_string(attempts) + " attempts: best position error " +
                  std::to_string(best.position_error_m) + " m, orientation error " +
                  std::to_string(best.orientation_error_rad) + " rad (pose out of reach or outside joint limits?)";
  }
  return best;
}

}  // namespace bookgrasp
