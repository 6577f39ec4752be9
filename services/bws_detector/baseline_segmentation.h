#pragma once
/// @file
/// The simplest planar-segmentation baseline for the comparison with GoD:
/// connected components of a depth-like image where neighbouring values differ
/// by at most a jump threshold, each described by its least-squares plane.
/// It separates surfaces at depth jumps but not at creases (a book's top and
/// front meet without a jump), so it under-segments where GoD should not.

#include <opencv2/core.hpp>

#include "services/bws_detector/plane_region.h"

namespace bookgrasp {
class Config;
}

namespace bookgrasp::bws {

/// Parameters of the jump-component baseline (config section `jump_components`).
struct JumpComponentsParams {
  /// 4-neighbours belong together when their values differ by at most this (image units).
  double max_jump = 0.5;
  /// Regions with fewer pixels are dropped.
  int min_region_px = 50;

  /// Reads every key of the section.
  static JumpComponentsParams from_config(const Config& section);
};

/// Segments `image` (CV_32F, invalid = NaN or <= 0) into jump-free connected
/// components; planes fitted to `points` (CV_32FC3) or to (x, y, value) if empty.
SegmentationResult segment_jump_components(const cv::Mat& image, const cv::Mat& points,
                                           const JumpComponentsParams& params);

}  // namespace bookgrasp::bws
