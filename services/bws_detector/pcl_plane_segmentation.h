#pragma once
/// @file
/// Second planar segmentation, built on PCL: integral-image normals on the
/// organized cloud and pcl::OrganizedMultiPlaneSegmentation (connected
/// components of pixels with similar normals and plane offsets). Same output
/// as GoD (SegmentationResult). PCL headers stay in the .cpp.

#include <opencv2/core.hpp>

#include "services/bws_detector/plane_region.h"

namespace bookgrasp {
class Config;
}

namespace bookgrasp::bws {

/// Parameters (config section `pcl` of bws_detector_pcl.yaml).
struct PclPlaneParams {
  /// Integral-image normal estimation: "covariance" or "average_3d_gradient".
  bool covariance_normals = true;
  /// Depth change (relative, times depth) above which normals are not smoothed across.
  double max_depth_change_factor = 0.02;
  /// Normal smoothing window size (pixels).
  double normal_smoothing_size = 10.0;
  /// Minimum inliers of a plane (pixels).
  int min_inliers = 200;
  /// Max angle between normals of one plane, degrees.
  double angular_threshold_deg = 3.0;
  /// Max distance between a point and the plane of its neighbours, metres.
  double distance_threshold_m = 0.02;
  /// Max surface curvature of a plane point.
  double maximum_curvature = 0.001;
  /// Regions with fewer pixels are dropped from the output.
  int min_region_px = 50;

  /// Reads every key of the section.
  static PclPlaneParams from_config(const Config& section);
};

/// Segments the organized cloud `points` (CV_32FC3, metres in the camera frame,
/// NaN = invalid) into planes. Throws std::invalid_argument on a wrong type.
SegmentationResult segment_pcl_planes(const cv::Mat& points, const PclPlaneParams& params);

}  // namespace bookgrasp::bws
