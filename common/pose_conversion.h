#pragma once
/// @file
/// pose_t <-> Eigen::Isometry3d, with validation of NaN and non-unit quaternions.

#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

#include "bookgrasp/pose_t.hpp"

namespace bookgrasp {

/// Thrown for a pose that is not a rigid transform (NaN, zero quaternion).
class PoseError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The transform a pose message describes (child in frame). The quaternion is
/// normalised if its norm is within 1e-3 of 1; otherwise PoseError, as for NaN
/// or infinite values.
Eigen::Isometry3d pose_to_isometry(const pose_t& pose);

/// A pose message for `transform` (child in frame).
pose_t isometry_to_pose(const Eigen::Isometry3d& transform, const std::string& frame, const std::string& child,
                        int64_t utime);

/// True if every number of the pose is finite and its quaternion has a norm within 1e-3 of 1.
bool is_valid_pose(const pose_t& pose);

}  // namespace bookgrasp
