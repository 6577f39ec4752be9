#pragma once
/// @file
/// Turns any image-carrying message (image_t, stereo_frame_t, hand_image_t) into a picture,
/// whatever its type: the viewer's core, no LCM bus in here.

#include <cstdint>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

namespace bookgrasp {

/// A picture decoded from a message, ready to write as PNG (RGB or grey, 8-bit).
struct DecodedPicture {
  cv::Mat rgb;            ///< CV_8UC3 RGB (depth and labels are colour-mapped)
  int64_t utime = 0;      ///< the message's utime
  std::string type;       ///< "image_t", "stereo_frame_t" or "hand_image_t"
};

/// Decodes `data` (an encoded LCM message) if it is an image_t, stereo_frame_t (left and right side
/// by side) or hand_image_t. Returns nothing for other types. Throws ImageError for an image
/// message whose pixels cannot be decoded.
std::optional<DecodedPicture> decode_picture(const void* data, int size);

}  // namespace bookgrasp
