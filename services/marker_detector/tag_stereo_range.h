#pragma once
/// @file
/// Range of a detected tag from the rectified stereo pair. A tag of ~30 px (the cart's, 1.6 m from the
/// stereo camera) gives its distance from its image size to a few percent only: one pixel of corner error
/// is 3 % (~5 cm) of range. Its disparity is far better: the tag's patch of the left image is found along
/// the same rows of the right image (normalised cross-correlation, sub-pixel by a parabola through the
/// best three shifts) and depth = fx * baseline / disparity (0.2 px of disparity is ~7 mm at 1.6 m with
/// the 0.12 m baseline). The monocular pose keeps its orientation and is slid along its viewing ray to
/// that depth. Pure OpenCV, no LCM.

#include <array>
#include <string>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "common/config.h"

namespace bookgrasp {

/// Configuration `stereo_range`.
struct TagStereoRangeParams {
  bool enabled = true;             ///< range tags by disparity (false: monocular pose only)
  double margin = 0.25;            ///< patch = the corners' bounding box grown by this x its larger side
  double min_depth_m = 0.3;        ///< nearest depth searched (sets the largest disparity)
  double min_score = 0.8;          ///< best normalised cross-correlation needed
  double max_disagreement = 0.15;  ///< stereo and monocular depth may differ by this fraction at most

  /// Reads the section; throws ConfigError naming a bad or missing key.
  static TagStereoRangeParams from_config(const Config& section);
};

/// The outcome of ranging one tag.
struct TagStereoRange {
  bool ok = false;          ///< false: see `reason`; the monocular pose stands
  double disparity_px = 0;  ///< left column - right column of the tag, principal points accounted for
  double depth_m = 0;       ///< fx * baseline / disparity
  double score = 0;         ///< normalised cross-correlation at the best shift
  std::string reason;       ///< why not ok
};

/// Ranges the tag with corners `corners` (left image) in the rectified pair (CV_8UC1, same size). `fx` is the
/// focal length in pixels, `cx_left` / `cx_right` the principal points' columns, `baseline_m` the right optical
/// centre's distance along the left camera's +x. `monocular_depth_m` (> 0 when known) only names the cause when no
/// match is found: a tag whose monocular depth puts it (partly) outside the right image.
TagStereoRange range_tag_in_stereo(const cv::Mat& left_gray, const cv::Mat& right_gray,
                                   const std::array<cv::Point2d, 4>& corners, double fx, double cx_left,
                                   double cx_right, double baseline_m, const TagStereoRangeParams& params,
                                   double monocular_depth_m = 0);

/// `tag_in_camera` slid along the ray through its origin so the origin's depth (camera z) is `depth_m`;
/// orientation unchanged.
Eigen::Isometry3d tag_pose_at_depth(const Eigen::Isometry3d& tag_in_camera, double depth_m);

}  // namespace bookgrasp
