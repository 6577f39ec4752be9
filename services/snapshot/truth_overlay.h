#pragma once
/// @file
/// Ground truth drawn on a camera image, and depth as a colour image: the
/// pictures the snapshot tool writes so a person can check a scene.

#include <opencv2/core.hpp>

#include "bookgrasp/ground_truth_t.hpp"
#include "common/sim_render/pinhole_camera.h"

namespace bookgrasp::snapshot {

/// `rgb` (CV_8UC3 RGB) with the ground truth projected through `camera`:
/// each book's front face outline and corners (green; red for the
/// right-most), P1 of the right-most book (large red circle, labelled), the
/// stripe end (yellow cross), the marker outlines (cyan, edge `cart_marker_size_m`
/// / `holder_marker_size_m`, tag x right / y up), and a legend. Points behind the
/// camera are skipped.
cv::Mat draw_ground_truth(const cv::Mat& rgb, const ground_truth_t& truth, const sim_render::PinholeCamera& camera,
                          double cart_marker_size_m, double holder_marker_size_m);

/// Depth (CV_32FC1 metres, NaN = nothing) as a colour image (CV_8UC3 RGB,
/// turbo colour map, near = red, far = blue, nothing = black) with a colour
/// bar and the range in metres written on it. The range is the 1st..99th
/// percentile of the valid depths.
cv::Mat colorize_depth(const cv::Mat& depth);

}  // namespace bookgrasp::snapshot
