#pragma once
/// @file
/// The arm driver's logic, free of LCM: accepts or refuses commands against the
/// limits, executes joint trajectories and Cartesian velocities in message
/// time, stops at once on STOP or when commands/heartbeats stop arriving, and
/// produces the joint and gripper setpoints to stream to the arm.

#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/kinematics/arm_kinematics.h"
#include "services/arm_driver/joint_trajectory.h"

namespace bookgrasp {

/// Driver state, as in arm_state_t.
enum class DriverState { kIdle = 0, kExecuting = 1, kStopped = 2, kFault = 3 };

/// Timing and gripper parameters of the driver.
struct DriverParams {
  double heartbeat_timeout_s = 0.5;  ///< stop when no command/heartbeat for this long (message time)
  double cartesian_damping = 0.01;   ///< damped least squares lambda for Cartesian velocity
  /// Null-space pull towards `preferred_posture` during Cartesian velocity (1/s; 0 = none): the redundant
  /// joint motion that leaves the TCP twist unchanged is used to keep the arm near that posture (the swivel
  /// the planner chose, away from the wrist's limits) instead of drifting while a servo runs.
  double nullspace_gain = 0.0;
  double nullspace_max_speed = 0.3;   ///< rad/s, largest null-space joint speed (norm)
  Eigen::VectorXd preferred_posture;  ///< rad, one value per arm joint (empty = no null-space term)
  /// Null-space push away from the joint limits during Cartesian velocity: a joint nearer than this to a
  /// limit (rad; 0 = none) is pushed away with a speed rising linearly to `nullspace_limit_gain` at the
  /// limit, within the redundancy (the TCP twist is unchanged), so a straight move or a servo does not stop
  /// at a wrist limit the redundant joint could have avoided. Added to the posture pull before projection.
  double nullspace_limit_margin = 0.0;
  double nullspace_limit_gain = 0.0;   ///< rad/s at the limit (the push at the margin's edge is 0)
  double gripper_max_width = 0.0602;   ///< m
  double gripper_min_width = 0.0;      ///< m
  double gripper_default_force = 100;  ///< N, used when a command gives 0
  double gripper_open_margin = 0.003;  ///< m: plates this near max_width that touch something are open (a
                                       ///< neighbour), not holding a book, when a (re)started driver takes over
};

/// What to send to the arm now.
struct DriverSetpoint {
  Eigen::VectorXd q;         ///< joint positions (rad)
  Eigen::VectorXd qd;        ///< joint velocities (rad/s)
  double gripper_width = 0;  ///< m
  double gripper_force = 0;  ///< N
};

/// The arm driver's state machine.
class ArmDriverCore {
 public:
  /// `kinematics` gives FK/Jacobian for workspace checks and Cartesian motion.
  ArmDriverCore(ArmKinematics kinematics, ArmLimits limits, DriverParams params);

  /// New measurement of the arm at message time `now_utime` (from SIM_STATE or the hardware).
  /// The first one initialises the setpoint to where the arm is; the gripper's to its measured width, or,
  /// when the plates are in contact short of fully open (`gripper_contact`: a driver restarted while they
  /// hold a book), to closing with the default force, so what they hold is not let go.
  void on_measurement(int64_t now_utime, const Eigen::VectorXd& q, double gripper_width, bool gripper_contact = false);

  /// The arm's source restarted (a restarted simulation: its clock jumped back and the arm is
  /// somewhere else): any motion stops (state STOPPED, with the reason) and the setpoint becomes
  /// the new measurement (the gripper's as in on_measurement), so the arm is never pulled back to
  /// where the old world had it.
  void restart(int64_t now_utime, const Eigen::VectorXd& q, double gripper_width, bool gripper_contact = false);

  /// Executes `traj` from now. Returns "" if accepted, else why not (nothing changes then).
  std::string command_trajectory(const JointTrajectory& traj, int64_t command_id);
  /// Moves the TCP with `twist` (vx vy vz wx wy wz) in `frame` ("base" or "gripper"). "" if accepted.
  std::string command_cartesian_velocity(const Eigen::Matrix<double, 6, 1>& twist, const std::string& frame,
                                         int64_t command_id);
  /// Stops at once: the setpoint holds the current commanded position.
  void command_stop(const std::string& reason);
  /// A heartbeat: proves the commander is alive.
  void heartbeat();
  /// Gripper: move to `width` (m) with `force` (N; 0 = default). "" if accepted.
  std::string command_gripper(double width, double force);

  /// Advances to `now_utime` (message time) and returns the setpoint to stream.
  /// Ends trajectories, integrates Cartesian velocity, enforces the heartbeat.
  DriverSetpoint update(int64_t now_utime);

  /// Current state.
  DriverState state() const { return state_; }
  /// Reason of the last stop, refusal or fault ("" if none).
  const std::string& message() const { return message_; }
  /// Id of the command being executed (or last executed).
  int64_t active_command_id() const { return active_id_; }
  /// True once a measurement has been received.
  bool initialised() const { return q_cmd_.size() > 0; }
  /// The kinematics.
  const ArmKinematics& kinematics() const { return kin_; }
  /// The limits.
  const ArmLimits& limits() const { return limits_; }

 private:
  /// The joint velocity the null space should realise as far as it can (rad/s): the posture pull plus the
  /// push away from the joint limits (DriverParams); zero when neither is configured.
  Eigen::VectorXd nullspace_objective() const;
  /// A measured plate distance as a gripper target: clamped to [gripper_min_width, gripper_max_width].
  double hold_width(double measured) const;
  /// The gripper's setpoint from a measurement: hold the width, or keep squeezing what the plates touch.
  void hold_gripper(double measured_width, bool contact);
  /// A measured posture as the held setpoint: clamped to the joint limits.
  Eigen::VectorXd hold_posture(const Eigen::VectorXd& measured) const;
  enum class Mode { kHold, kTrajectory, kCartesian };
  void stop(const std::string& reason);

  ArmKinematics kin_;
  ArmLimits limits_;
  DriverParams params_;
  DriverState state_ = DriverState::kIdle;
  Mode mode_ = Mode::kHold;
  std::string message_;
  int64_t active_id_ = 0;
  int64_t now_ = 0;
  int64_t last_update_ = -1;
  int64_t last_heard_ = 0;
  Eigen::VectorXd q_measured_, q_cmd_, qd_cmd_;
  JointTrajectory traj_;
  int64_t traj_start_ = 0;
  Eigen::Matrix<double, 6, 1> twist_ = Eigen::Matrix<double, 6, 1>::Zero();
  std::string twist_frame_ = "base";
  double gripper_width_ = -1, gripper_force_ = 0;
};

/// Name of a driver state ("IDLE", "EXECUTING", "STOPPED", "FAULT").
std::string driver_state_name(DriverState s);

}  // namespace bookgrasp
