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

/// The space the cloud handed to PCL lives in (config `pcl.space`).
enum class PclSpace {
  /// The metric points in the camera frame; distances in metres.
  kPoints,
  /// (column, row, disparity) per pixel, all in pixels: a 3D plane is a plane there too, and the stereo
  /// noise is about the same everywhere (in metres it grows with the square of the depth), as GoD's
  /// `merge_space: image`. Distances and depth changes in pixels.
  kImage,
};

/// Parameters (config section `pcl` of bws_detector_pcl.yaml).
struct PclPlaneParams {
  /// The space PCL segments in.
  PclSpace space = PclSpace::kPoints;
  /// In image space, the disparity axis is stretched by this factor: the disparity gradients of a scene's
  /// planes are a few hundredths of a pixel per pixel, so unstretched every normal lies within a few
  /// degrees of the viewing axis and the angular threshold separates nothing.
  double disparity_scale = 1.0;
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
  /// Max distance between a point and the plane of its neighbours, metres (pixels in image space).
  double distance_threshold_m = 0.02;
  /// Max surface curvature of a plane point.
  double maximum_curvature = 0.001;
  /// Regions with fewer pixels are dropped from the output.
  int min_region_px = 50;

  /// Reads every key of the section.
  static PclPlaneParams from_config(const Config& section);
};

/// Segments the organized cloud `points` (CV_32FC3, metres in the camera frame,
/// NaN = invalid) into planes, in metric space whatever `params.space` says. Throws
/// std::invalid_argument on a wrong type.
SegmentationResult segment_pcl_planes(const cv::Mat& points, const PclPlaneParams& params);

/// Segments in the space `params.space` names: the metric `points`, or the image space of `disparity`
/// (CV_32F, NaN or <= 0 = invalid, the size of `points`); the regions are described with `points`
/// (planes in metres) either way. Throws std::invalid_argument on wrong types or sizes.
SegmentationResult segment_pcl_planes(const cv::Mat& disparity, const cv::Mat& points, const PclPlaneParams& params);

}  // namespace bookgrasp::bws
