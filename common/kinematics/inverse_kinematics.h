#pragma once
/// @file
/// Inverse kinematics of a redundant arm: damped least squares (Levenberg-
/// Marquardt style) on the 6-D pose error, joint limits enforced by clamping,
/// a null-space term pulling towards a preferred posture, and several
/// restarts from deterministic pseudo-random seeds.

#include <cstdint>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/kinematics/arm_kinematics.h"

namespace bookgrasp {

/// Tuning of the IK solver (all from configuration; see docs/PLANNER.md).
struct IkParams {
  int max_iterations = 200;            ///< iterations per attempt
  int max_restarts = 8;                ///< extra attempts from random seeds after the given seed(s)
  double position_tolerance_m = 1e-4;  ///< success: position error below this
  double orientation_tolerance_rad = 1e-3;  ///< success: rotation error below this
  double damping = 0.05;               ///< DLS damping lambda (in metres-equivalent)
  double max_step_rad = 0.3;           ///< largest joint change per iteration
  double nullspace_gain = 0.1;         ///< posture pull (fraction of the posture error per iteration)
  double orientation_weight_m = 0.2;   ///< metres per radian when mixing position and orientation errors
  int posture_iterations = 30;         ///< extra iterations after convergence that only improve the posture
  Eigen::VectorXd preferred_posture;   ///< posture the null-space term pulls towards (num_joints values)
  uint64_t seed = 1;                   ///< seed of the restart generator (same seed -> same answer)
};

/// Result of one IK query.
struct IkResult {
  bool success = false;
  Eigen::VectorXd q;                 ///< best solution found (within limits), even on failure
  double position_error_m = 0.0;     ///< of `q`
  double orientation_error_rad = 0.0;
  int attempts = 0;                  ///< attempts made (1 + restarts used)
  int iterations = 0;                ///< total iterations over all attempts
  std::string reason;                ///< why it failed ("" on success)
};

/// IK solver for ArmKinematics. Deterministic: the same target, seed and
/// parameters give the same answer. Thread-safe (const, no shared state).
class InverseKinematics {
 public:
  /// Throws std::invalid_argument if params are inconsistent with the arm
  /// (preferred posture size or outside the limits, non-positive tolerances).
  InverseKinematics(ArmKinematics kinematics, IkParams params);

  /// Tip pose `target` (base frame) from a first guess `seed_q` (clamped to
  /// the limits), then the preferred posture, then up to max_restarts random
  /// configurations. Among converged attempts the first is returned.
  IkResult solve(const Eigen::Isometry3d& target, const Eigen::VectorXd& seed_q) const;
  /// Same with an explicit restart seed (overrides params.seed).
  IkResult solve(const Eigen::Isometry3d& target, const Eigen::VectorXd& seed_q, uint64_t restart_seed) const;
  /// One attempt from `seed_q` only (no restarts), at most `max_iterations`
  /// iterations. Used by samplers that make their own seeds. `posture_iterations`
  /// overrides params.posture_iterations when >= 0 (0 = stop at the first
  /// converged iterate, staying close to the seed).
  IkResult solve_once(const Eigen::Isometry3d& target, const Eigen::VectorXd& seed_q, int max_iterations,
                      int posture_iterations = -1) const;

  /// The arm.
  const ArmKinematics& kinematics() const { return kin_; }
  /// The parameters.
  const IkParams& params() const { return params_; }

 private:
  ArmKinematics kin_;
  IkParams params_;
};

}  // namespace bookgrasp
