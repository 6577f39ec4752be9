#pragma once
/// @file
/// The BwS debug picture: the left image with every planar region tinted
/// (grey = dropped, green = book-front candidate, red = the selected right-most
/// front), region borders, PI as a cross and P1 written in base and grasp.

#include <string>

#include <opencv2/core.hpp>

#include "services/bws_detector/bws_pipeline.h"

namespace bookgrasp::bws {

/// Draws the overlay on a copy of `left` (CV_8UC1 or CV_8UC3 RGB); returns CV_8UC3 RGB.
/// `title` is written in the top-left corner (e.g. implementation and utime).
cv::Mat draw_bws_overlay(const cv::Mat& left, const BwsOutput& result, const std::string& title);

}  // namespace bookgrasp::bws
