#pragma once
/// @file
/// The BSwH debug picture: the hand image with the stripe's centre line
/// (magenta), its thickness band, the end as a cross (red) and a caption.

#include <string>

#include <opencv2/core.hpp>

#include "services/bswh_detector/stripe_detection.h"

namespace bookgrasp {

/// Draws the overlay on a copy of `image` (CV_8UC1 or CV_8UC3 RGB); returns CV_8UC3 RGB.
/// `title` is the caption's start (e.g. implementation and utime).
cv::Mat draw_bswh_overlay(const cv::Mat& image, const StripeDetection& detection, const std::string& title);

}  // namespace bookgrasp
