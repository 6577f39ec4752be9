#pragma once
/// @file
/// Time parameterisation of a joint-space polyline under per-joint velocity
/// and acceleration limits: on each segment every joint follows the same
/// trapezoidal (or triangular) profile of the path parameter, synchronised so
/// that the slowest joint sets the pace, at rest at every waypoint. The robot
/// therefore follows the collision-checked polyline exactly.

#include <vector>

#include <Eigen/Core>

namespace bookgrasp {

/// One sample of a timed trajectory.
struct TimedPoint {
  double time_s = 0.0;            ///< from the trajectory start
  Eigen::VectorXd position;      ///< rad
  Eigen::VectorXd velocity;      ///< rad/s
  Eigen::VectorXd acceleration;  ///< rad/s^2
};

/// A timed trajectory: samples at increasing times, first at t = 0, last at the final waypoint.
struct TimedTrajectory {
  std::vector<TimedPoint> points;
  double duration_s = 0.0;
};

/// The trajectory through `waypoints` (at least one; all of the same size
/// as the limits), sampled every `sample_period_s` plus exactly at every
/// waypoint. Zero-length segments are skipped; samples are at least 10 us apart (messages carry microseconds). Throws
/// std::invalid_argument for mismatched sizes, non-positive limits or period.
TimedTrajectory parameterize_trapezoidal(const std::vector<Eigen::VectorXd>& waypoints,
                                         const Eigen::VectorXd& max_velocity,
                                         const Eigen::VectorXd& max_acceleration, double sample_period_s);

}  // namespace bookgrasp
