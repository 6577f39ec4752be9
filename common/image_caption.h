#pragma once
/// @file
/// Caption lines on debug pictures: readable on any background (outlined in black).

#include <string>

#include <opencv2/core.hpp>

namespace bookgrasp {

/// Writes `text` as caption line `line` (0 = top) in the top-left corner of an 8-bit
/// 3-channel image, in `colour` outlined in black.
void draw_caption_line(cv::Mat* image, int line, const std::string& text, const cv::Scalar& colour);

}  // namespace bookgrasp
