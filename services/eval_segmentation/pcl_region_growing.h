#pragma once
/// @file
/// A third segmentation for the comparison, of the kind of Hoover's USF method ("region growing based on
/// local surface normals"): pcl::RegionGrowing on the organized cloud, with integral-image normals. Points
/// join a region while their normal is within `smoothness_deg` of the neighbour's that reached them (and,
/// for seeds of further growth, their curvature is below `curvature_threshold`). Defaults are the values of
/// PCL's region-growing and integral-image-normal tutorials (not tuned on the evaluation). PCL stays in the .cpp.

#include <opencv2/core.hpp>

namespace bookgrasp::eval_segmentation {

/// Parameters of the region growing.
struct RegionGrowingParams {
  /// Integral-image normal smoothing window, pixels.
  double normal_smoothing_size = 10.0;
  /// Depth change (relative to depth) above which normals are not smoothed across.
  double max_depth_change_factor = 0.02;
  /// Neighbours searched per point.
  int neighbours = 30;
  /// Max angle between neighbouring normals inside a region, degrees.
  double smoothness_deg = 3.0;
  /// Only points with curvature below this continue the growth.
  double curvature_threshold = 1.0;
  /// Regions with fewer points are dropped (label 0).
  int min_region_px = 50;
};

/// Labels (CV_32S, 0 = no region, 1.. in order of PCL's clusters) of the organized cloud `points`
/// (CV_32FC3, metres, NaN = invalid). Throws std::invalid_argument for a wrong type or bad parameters.
cv::Mat segment_region_growing(const cv::Mat& points, const RegionGrowingParams& params);

}  // namespace bookgrasp::eval_segmentation
