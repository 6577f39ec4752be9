#pragma once
/// @file
/// The paper's `grasp` frame: X up, Y to the right along the shelf as seen from
/// the robot, Z into the shelf. The validation rules of Section 3 are written in it.

#include <Eigen/Geometry>

namespace bookgrasp {

/// The grasp frame in `base`, with its origin at `origin_base`. `into_shelf_base`
/// is the direction into the shelf (e.g. minus the cart front's outward normal);
/// `up_base` is "up" (base +z by default). Z = into_shelf made orthogonal to up,
/// X = up, Y = Z x X (right as seen from the robot). Throws std::invalid_argument
/// if the two directions are (nearly) parallel or not finite.
Eigen::Isometry3d grasp_frame_in_base(const Eigen::Vector3d& into_shelf_base, const Eigen::Vector3d& origin_base,
                                      const Eigen::Vector3d& up_base = Eigen::Vector3d::UnitZ());

}  // namespace bookgrasp
