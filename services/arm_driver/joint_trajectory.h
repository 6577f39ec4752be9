#pragma once
/// @file
/// A joint trajectory as plain values, its validation against the arm's limits
/// and its sampling (cubic Hermite between waypoints). No LCM in here.

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace bookgrasp {

/// Waypoints of a trajectory: time from start (s), positions (rad), velocities
/// (rad/s; empty = unknown, then interpolation is linear).
struct JointTrajectory {
  std::vector<std::string> joint_names;   ///< empty = the driver's order
  std::vector<double> times;              ///< strictly increasing, first >= 0
  std::vector<Eigen::VectorXd> positions;
  std::vector<Eigen::VectorXd> velocities;     ///< same count as positions, or empty
  std::vector<Eigen::VectorXd> accelerations;  ///< same count as positions, or empty
  /// Duration: time of the last waypoint.
  double duration() const { return times.empty() ? 0.0 : times.back(); }
};

/// Limits every command must respect.
struct ArmLimits {
  std::vector<std::string> joint_names;
  Eigen::VectorXd lower, upper;          ///< position limits (rad)
  Eigen::VectorXd max_velocity;          ///< rad/s
  Eigen::VectorXd max_acceleration;      ///< rad/s^2
  Eigen::Vector3d workspace_min, workspace_max;  ///< box the TCP must stay in (base, m)
  double start_tolerance = 0.02;         ///< |first waypoint - current| allowed (rad)
  double max_linear_speed = 0.1;         ///< Cartesian commands (m/s)
  double max_angular_speed = 0.5;        ///< Cartesian commands (rad/s)
  double relative_tolerance = 1e-6;      ///< slack on velocity/acceleration checks
};

/// Tool-centre-point position for joint values (forward kinematics), for workspace checks.
using TcpPosition = std::function<Eigen::Vector3d(const Eigen::VectorXd& q)>;

/// Checks `traj` against `limits`, starting from `current` joints. Returns ""
/// if it may be executed, else the first problem found, naming the waypoint and
/// joint (e.g. "waypoint 3: joint arm_2_joint velocity 2.4 rad/s > limit 2.0").
std::string validate_trajectory(const JointTrajectory& traj, const Eigen::VectorXd& current, const ArmLimits& limits,
                                const TcpPosition& tcp);

/// Position and velocity of `traj` at time `t` (clamped to [0, duration]):
/// cubic Hermite between waypoints when velocities are given, linear otherwise.
void sample_trajectory(const JointTrajectory& traj, double t, Eigen::VectorXd* q, Eigen::VectorXd* qd);

}  // namespace bookgrasp
