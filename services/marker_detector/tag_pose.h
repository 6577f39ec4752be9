#pragma once
/// @file
/// Pose of a square tag from its four image corners and the camera
/// intrinsics (IPPE for squares, refined by Levenberg-Marquardt), and the
/// choice between IPPE's two solutions (the planar pose ambiguity: a small or
/// distant tag fits a mirrored tilt almost as well) by the tag's known mounting.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

namespace bookgrasp {

/// Pinhole intrinsics and distortion of the image the corners come from.
struct TagCameraIntrinsics {
  double fx = 0.0;  ///< focal length x, pixels
  double fy = 0.0;  ///< focal length y, pixels
  double cx = 0.0;  ///< principal point x, pixels
  double cy = 0.0;  ///< principal point y, pixels
  /// Distortion coefficients in OpenCV order (k1 k2 p1 p2 k3); empty = none.
  std::vector<double> distortion;
};

/// The estimated pose of one tag.
struct TagPose {
  /// The tag frame in the camera optical frame (x right, y down, z forward).
  /// Tag frame (AprilTag convention): origin at the tag centre, x towards the
  /// tag's right, y towards the tag's bottom, z into the tag (away from a
  /// camera that sees it). Corner k of TagDetection lies at
  /// (-s/2, s/2), (s/2, s/2), (s/2, -s/2), (-s/2, -s/2) for k = 0..3.
  Eigen::Isometry3d tag_in_camera = Eigen::Isometry3d::Identity();
  /// RMS distance between the detected corners and the corners reprojected
  /// with the pose, pixels.
  double reprojection_error_px = 0.0;
};

/// Estimates the pose of a square tag of side `tag_size_m` (outer edge of the
/// black border, metres) from its corners in AprilTag order. Throws
/// std::invalid_argument for a non-positive size, non-finite corners or
/// intrinsics, and std::runtime_error if no pose is found (degenerate quad).
TagPose estimate_tag_pose(const std::array<cv::Point2d, 4>& corners, double tag_size_m,
                          const TagCameraIntrinsics& intrinsics);

/// Both poses IPPE finds for the corners (the planar ambiguity), each refined by
/// Levenberg-Marquardt, sorted by reprojection error (best first); one or two.
/// Throws as estimate_tag_pose.
std::vector<TagPose> estimate_tag_pose_candidates(const std::array<cv::Point2d, 4>& corners, double tag_size_m,
                                                  const TagCameraIntrinsics& intrinsics);

/// Angle between a tag's "down" axis (its y axis: towards the tag's bottom edge) and straight down
/// (-z of `base`), radians, for the tag at `tag_in_camera` seen by a camera at `camera_in_base`.
double tag_tilt_from_upright(const Eigen::Isometry3d& tag_in_camera, const Eigen::Isometry3d& camera_in_base);

/// The pose of a tag mounted upright (its bottom edge down, on a vertical or leaning board): among
/// `candidates` (sorted by reprojection error) whose error is within `ambiguity_px` of the best, the
/// one tilted least from upright. Nothing when that one is tilted more than `max_tilt_rad` (no
/// pose fits the mounting: a wrong id, a tag knocked over, or both solutions bad).
std::optional<TagPose> choose_upright_pose(const std::vector<TagPose>& candidates,
                                           const Eigen::Isometry3d& camera_in_base, double max_tilt_rad,
                                           double ambiguity_px);

/// Projects the four tag corners of a tag of `tag_size_m` at `tag_in_camera`
/// into the image (same order as TagDetection::corners).
std::array<cv::Point2d, 4> project_tag_corners(const Eigen::Isometry3d& tag_in_camera, double tag_size_m,
                                               const TagCameraIntrinsics& intrinsics);

}  // namespace bookgrasp
