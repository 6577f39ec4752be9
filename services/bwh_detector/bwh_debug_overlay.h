#pragma once
/// @file
/// The BwH debug picture: the hand image with every book candidate's box
/// (grey = rejected, green = accepted, red = the book at the reported rank),
/// its corner R as a cross and its slope as a short line, the stripe's centre
/// line when it was used, and a caption.

#include <string>

#include <opencv2/core.hpp>

#include "services/bwh_detector/book_detection_hand.h"

namespace bookgrasp {

/// Draws the overlay on a copy of `image` (CV_8UC1 or CV_8UC3 RGB); returns CV_8UC3 RGB.
/// `rank_from_right` marks the book reported (ranking[rank]); `title` is the caption's start.
cv::Mat draw_bwh_overlay(const cv::Mat& image, const BookDetection& detection, int rank_from_right,
                         const std::string& title);

}  // namespace bookgrasp
