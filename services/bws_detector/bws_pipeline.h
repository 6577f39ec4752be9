#pragma once
/// @file
/// The whole BwS computation for one stereo frame, without LCM: disparity,
/// 3D points, planar segmentation (GoD or PCL, chosen by name), book-front
/// selection in the upper-shelf volume given by the cart marker, P1 in `base`
/// and in the `grasp` frame, and the time each stage took. The node, the
/// evaluation tools and the benchmarks call this.

#include <string>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "services/bws_detector/book_front_selection.h"
#include "services/bws_detector/cart_geometry.h"
#include "services/bws_detector/disparity.h"
#include "services/bws_detector/god_segmentation.h"
#include "services/bws_detector/pcl_plane_segmentation.h"

namespace bookgrasp {
class Config;
}

namespace bookgrasp::bws {

/// Names of the two segmentation implementations (service.implementation).
inline constexpr const char* kImplGod = "god";
/// See kImplGod.
inline constexpr const char* kImplPcl = "pcl";

/// Everything the pipeline is configured with.
struct BwsParams {
  /// "god" or "pcl" (service.implementation).
  std::string implementation = kImplGod;
  /// Disparity section.
  DisparityParams disparity;
  /// GoD section (used when implementation == "god").
  GodParams god;
  /// PCL section (used when implementation == "pcl").
  PclPlaneParams pcl;
  /// Book-front tests.
  SelectionParams selection;
  /// Cart geometry (marker -> shelf volume).
  CartGeometry cart;

  /// Reads service.implementation, disparity, the implementation's section
  /// (`god` or `pcl`), selection and cart from a service configuration root.
  static BwsParams from_config(const Config& root);
};

/// One rectified stereo frame with its geometry.
struct StereoInput {
  /// Left and right images (CV_8UC1 or CV_8UC3), same size.
  cv::Mat left;
  /// See left.
  cv::Mat right;
  /// Left intrinsics and baseline.
  StereoGeometry geometry;
  /// Left optical frame in base.
  Eigen::Isometry3d camera_in_base = Eigen::Isometry3d::Identity();
};

/// Everything a BwS run produces.
struct BwsOutput {
  /// Disparity (CV_32F, NaN = invalid).
  cv::Mat disparity;
  /// Points in the left camera frame (CV_32FC3, metres).
  cv::Mat points_camera;
  /// Planar segmentation.
  SegmentationResult segmentation;
  /// Candidates, the selected region, PI and P1 (in camera and base).
  BookFrontResult selection;
  /// Cart frame, shelf volume and grasp frame used (from the marker).
  Eigen::Isometry3d cart_in_base = Eigen::Isometry3d::Identity();
  /// See cart_in_base.
  ShelfVolume shelf;
  /// See cart_in_base.
  Eigen::Isometry3d grasp_in_base = Eigen::Isometry3d::Identity();
  /// P1 in the grasp frame (valid when selection.found).
  Eigen::Vector3d p1_grasp = Eigen::Vector3d::Zero();
  /// Pixels with a valid disparity.
  int num_valid_disparity = 0;
  /// Wall time of the stages, milliseconds (0 if not measured).
  double disparity_ms = 0.0;
  /// See disparity_ms (planar segmentation only).
  double segmentation_ms = 0.0;
  /// See disparity_ms (everything).
  double total_ms = 0.0;
};

/// Runs BwS on one frame. `cart_marker_in_base` is the cart marker's pose
/// (AprilTag convention). Wall times are measured only if `measure_time`
/// (they are the only output that is not reproducible). Throws
/// std::invalid_argument for bad images or geometry (the text says what).
BwsOutput run_bws(const StereoInput& input, const Eigen::Isometry3d& cart_marker_in_base, const BwsParams& params,
                  bool measure_time);

/// Runs only the configured segmentation on a disparity image and its points
/// (for evaluation and benchmarks).
SegmentationResult segment(const cv::Mat& disparity, const cv::Mat& points_camera, const BwsParams& params);

}  // namespace bookgrasp::bws
