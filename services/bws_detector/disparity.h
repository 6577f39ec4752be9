#pragma once
/// @file
/// Disparity of a rectified stereo pair with OpenCV block matching (StereoBM,
/// the paper's choice, or StereoSGBM) and its 3D reconstruction in the left
/// camera frame and in `base`.
///
/// Disparity convention: CV_32F in pixels, left image as reference
/// (x_right = x_left - d); invalid pixels (no match, left border of
/// num_disparities columns, speckles) are NaN. Valid values are > 0 only if
/// min_disparity >= 1; pixels with d <= 0 are treated as invalid by every
/// consumer (point at infinity).

#include <string>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

namespace bookgrasp {
class Config;
}

namespace bookgrasp::bws {

/// Block-matching algorithm.
enum class StereoAlgorithm {
  /// cv::StereoBM (paper [6]).
  kBlockMatching,
  /// cv::StereoSGBM (semi-global, MODE_SGBM_3WAY).
  kSemiGlobal,
};

/// Parameters of the disparity computation (config section `disparity`).
struct DisparityParams {
  /// Algorithm.
  StereoAlgorithm algorithm = StereoAlgorithm::kBlockMatching;
  /// Smallest disparity searched (pixels).
  int min_disparity = 0;
  /// Number of disparities searched (multiple of 16).
  int num_disparities = 64;
  /// Matching block size (odd; StereoBM: 5..255).
  int block_size = 15;
  /// StereoBM: pre-filter cap (1..63); SGBM: preFilterCap too.
  int pre_filter_cap = 31;
  /// StereoBM: texture threshold (0 = off).
  int texture_threshold = 10;
  /// Uniqueness ratio in percent (0 = off).
  int uniqueness_ratio = 10;
  /// Speckle filter window (0 = off) and allowed disparity variation within it (pixels).
  int speckle_window_size = 100;
  /// Allowed disparity variation in a speckle (pixels, multiplied by 16 for OpenCV).
  int speckle_range = 2;
  /// Max allowed left-right difference (pixels), -1 = off.
  int disp12_max_diff = 1;
  /// SGBM smoothness penalties P1, P2 as multiples of channels * block_size^2 (OpenCV's usual 8 and 32).
  int sgbm_p1_factor = 8;
  /// See sgbm_p1_factor.
  int sgbm_p2_factor = 32;

  /// Reads every key of the `disparity` section.
  static DisparityParams from_config(const Config& section);
  /// Throws std::invalid_argument naming the field on a bad value.
  void validate() const;
};

/// Pinhole intrinsics of the rectified left camera and the stereo baseline.
struct StereoGeometry {
  /// Focal lengths in pixels.
  double fx = 0.0;
  /// See fx.
  double fy = 0.0;
  /// Principal point in pixels.
  double cx = 0.0;
  /// See cx.
  double cy = 0.0;
  /// Distance between the optical centres, metres (> 0).
  double baseline_m = 0.0;
};

/// Disparity (CV_32F, NaN = invalid) of a rectified pair. Colour inputs
/// (CV_8UC3, any channel order) are converted to grey; CV_8UC1 is used as is.
/// Throws std::invalid_argument for empty, mismatched or unsupported images.
cv::Mat compute_disparity(const cv::Mat& left, const cv::Mat& right, const DisparityParams& params);

/// Depth z = fx * baseline / d (metres, CV_32F); NaN where d is invalid or <= 0.
cv::Mat disparity_to_depth(const cv::Mat& disparity, const StereoGeometry& geometry);

/// 3D points (CV_32FC3, metres) in the left optical frame (x right, y down,
/// z forward): z = fx B / d, x = (u - cx) z / fx, y = (v - cy) z / fy. NaN where d is invalid.
cv::Mat disparity_to_points(const cv::Mat& disparity, const StereoGeometry& geometry);

/// Every point of a CV_32FC3 image transformed by `transform` (e.g. camera_in_base);
/// NaN points stay NaN.
cv::Mat transform_points(const cv::Mat& points, const Eigen::Isometry3d& transform);

}  // namespace bookgrasp::bws
