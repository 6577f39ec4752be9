#pragma once
/// @file
/// Caption lines on debug pictures: readable on any background (outlined in black),
/// wrapped at the image's right edge.

#include <string>

#include <opencv2/core.hpp>

namespace bookgrasp {

/// Writes `text` from caption line `line` (0 = top) in the top-left corner of an 8-bit
/// 3-channel image, in `colour` outlined in black, wrapped at spaces onto further lines when
/// it is wider than the image. Returns the line after the last one written.
int draw_caption(cv::Mat* image, int line, const std::string& text, const cv::Scalar& colour);

}  // namespace bookgrasp
