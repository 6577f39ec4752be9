#pragma once
/// @file
/// image_t <-> cv::Mat. Colour images are RGB in messages and in the cv::Mat
/// returned (not OpenCV's usual BGR): convert with cv::COLOR_RGB2BGR before
/// cv::imwrite or use write_png() below.

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "bookgrasp/image_t.hpp"

namespace bookgrasp {

/// Largest image the system accepts, in pixels per side.
inline constexpr int kMaxImageSide = 8192;

/// Thrown for an image message that cannot be turned into a picture; the text
/// names the problem (size, stride, format, decoding).
class ImageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Decodes `msg` into a cv::Mat that owns its data. GRAY8 -> CV_8UC1,
/// RGB8 -> CV_8UC3 (RGB), DEPTH_F32 and DISPARITY_F32 -> CV_32FC1,
/// DEPTH_U16 -> CV_16UC1 (multiply by depth_scale for metres),
/// LABEL_I32 -> CV_32SC1, PNG/JPEG -> decoded (colour as RGB, 16-bit as
/// CV_16UC1). Throws ImageError for an inconsistent message.
cv::Mat image_to_mat(const image_t& msg);

/// Decodes a DEPTH_F32, DEPTH_U16 or PNG (16-bit) depth image into metres
/// (CV_32FC1, NaN where unknown). Throws ImageError for other formats.
cv::Mat depth_to_metres(const image_t& msg);

/// Wraps a raw cv::Mat as an image message of `pixel_format` (GRAY8, RGB8,
/// DEPTH_F32, DEPTH_U16, DISPARITY_F32, LABEL_I32); the Mat type must match.
image_t mat_to_image(const cv::Mat& mat, int8_t pixel_format, int64_t utime, const std::string& frame,
                     float depth_scale = 0.0f);

/// Encodes a CV_8UC1, CV_8UC3 (RGB) or CV_16UC1 Mat as a PNG message.
image_t encode_png(const cv::Mat& mat, int64_t utime, const std::string& frame, float depth_scale = 0.0f);

/// Encodes a CV_8UC1 or CV_8UC3 (RGB) Mat as a JPEG message of `quality` (1-100).
image_t encode_jpeg(const cv::Mat& mat, int64_t utime, const std::string& frame, int quality = 90);

/// The encodings a camera may publish: "raw" (RGB8 / GRAY8), "png" (lossless),
/// "jpeg" (quality 90; ~8x smaller, for recordings).
inline const std::vector<std::string>& image_encodings() {
  static const std::vector<std::string> names{"raw", "png", "jpeg"};
  return names;
}

/// Encodes a CV_8UC3 (RGB) or CV_8UC1 image as `encoding` (one of image_encodings()).
/// Throws ImageError for another encoding.
image_t encode_image(const cv::Mat& mat, const std::string& encoding, int64_t utime, const std::string& frame);

/// A CV_8UC3 RGB copy of a grey (CV_8UC1) or RGB (CV_8UC3) image, to draw on.
cv::Mat to_rgb_copy(const cv::Mat& image);

/// Writes a CV_8UC1, CV_8UC3 (RGB) or CV_16UC1 Mat to a PNG file. Throws ImageError on failure.
void write_png(const std::string& path, const cv::Mat& mat);

/// Bytes per pixel of a raw format; 0 for PNG/JPEG; -1 for an unknown format.
int bytes_per_pixel(int8_t pixel_format);

/// Human-readable name of a pixel format ("RGB8", ..., or "unknown(N)").
std::string pixel_format_name(int8_t pixel_format);

}  // namespace bookgrasp
