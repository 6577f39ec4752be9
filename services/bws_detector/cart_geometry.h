#pragma once
/// @file
/// Where the upper shelf is, from the cart marker: the cart frame in `base`
/// from the detected cart marker pose and the cart geometry of the
/// configuration (never from ground truth), the upper-shelf volume the book
/// fronts must lie in, and the paper's `grasp` frame.
///
/// Cart frame (as in the scene, docs/SCENE.md): origin at the middle of the
/// front edge of the upper shelf's top surface; x into the shelf (towards the
/// rear board), y to the left as seen from the robot, z up.
/// Marker frame (AprilTag convention, as MARKERS publishes it): origin at the
/// tag centre, x to the tag's right, y to the tag's bottom, z into the tag.
/// The cart marker is on the rear board's front face, upright, facing the
/// robot, so in the cart frame its axes are x = -y_cart, y = -z_cart, z = +x_cart.

#include <Eigen/Geometry>

#include "services/bws_detector/book_front_selection.h"

namespace bookgrasp {
class Config;
}

namespace bookgrasp::bws {

/// Cart geometry the detector needs (config section `cart`).
struct CartGeometry {
  /// Cart marker centre in the cart frame, metres.
  Eigen::Vector3d marker_in_cart = Eigen::Vector3d::Zero();
  /// Upper-shelf volume in the cart frame: lower corner (x, y, z), metres.
  Eigen::Vector3d shelf_min_cart = Eigen::Vector3d::Zero();
  /// Upper-shelf volume in the cart frame: upper corner, metres.
  Eigen::Vector3d shelf_max_cart = Eigen::Vector3d::Zero();
  /// Max age of the cart marker relative to the stereo frame, seconds of message time.
  double max_marker_age_s = 0.0;

  /// Reads every key of the `cart` section; throws ConfigError naming a bad key
  /// (also when a min corner is not below its max corner).
  static CartGeometry from_config(const Config& section);
};

/// The cart frame in base from the cart marker's pose in base (AprilTag convention).
Eigen::Isometry3d cart_from_marker(const Eigen::Isometry3d& marker_in_base, const CartGeometry& geometry);

/// The upper-shelf volume (box axes = cart axes) for a cart at `cart_in_base`.
ShelfVolume shelf_volume(const Eigen::Isometry3d& cart_in_base, const CartGeometry& geometry);

/// The `grasp` frame for a cart at `cart_in_base`: Z = into the shelf (the cart's
/// x, the rear board's normal), X = base up, Y = Z x X (to the right as seen from
/// the robot); origin at the cart frame's origin (as the arbiter's). Throws
/// std::invalid_argument for a cart whose x axis is vertical.
Eigen::Isometry3d grasp_frame_of_cart(const Eigen::Isometry3d& cart_in_base);

}  // namespace bookgrasp::bws
