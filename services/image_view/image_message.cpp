#include "services/image_view/image_message.h"

#include <opencv2/imgproc.hpp>

#include "bookgrasp/hand_image_t.hpp"
#include "bookgrasp/image_t.hpp"
#include "bookgrasp/stereo_frame_t.hpp"
#include "common/image_conversion.h"

namespace bookgrasp {
namespace {

uint64_t fingerprint(const void* data, int size) {
  if (size < 8) return 0;
  const auto* b = static_cast<const uint8_t*>(data);
  uint64_t fp = 0;
  for (int i = 0; i < 8; ++i) fp = (fp << 8) | b[i];
  return fp;
}

/// Any decoded image as 8-bit RGB: colour kept, grey expanded, depth/disparity/labels colour-mapped.
cv::Mat to_rgb(const image_t& msg) {
  cv::Mat m = image_to_mat(msg);
  if (m.type() == CV_8UC3) return m;
  if (m.type() == CV_8UC1) {
    cv::Mat out;
    cv::cvtColor(m, out, cv::COLOR_GRAY2RGB);
    return out;
  }
  cv::Mat f;
  m.convertTo(f, CV_32F);
  cv::Mat valid = f == f;  // not NaN
  double lo = 0, hi = 1;
  cv::minMaxLoc(f, &lo, &hi, nullptr, nullptr, valid);
  cv::Mat u8;
  f.convertTo(u8, CV_8U, hi > lo ? 255.0 / (hi - lo) : 1.0, hi > lo ? -lo * 255.0 / (hi - lo) : 0.0);
  cv::Mat bgr, out;
  cv::applyColorMap(u8, bgr, cv::COLORMAP_TURBO);
  cv::cvtColor(bgr, out, cv::COLOR_BGR2RGB);
  out.setTo(cv::Scalar(0, 0, 0), ~valid);  // unknown depth is black
  return out;
}

}  // namespace

std::optional<DecodedPicture> decode_picture(const void* data, int size) {
  const uint64_t fp = fingerprint(data, size);
  DecodedPicture p;
  if (fp == static_cast<uint64_t>(image_t::getHash())) {
    image_t m;
    if (m.decode(data, 0, size) != size) return std::nullopt;
    p = {to_rgb(m), m.utime, "image_t"};
  } else if (fp == static_cast<uint64_t>(hand_image_t::getHash())) {
    hand_image_t m;
    if (m.decode(data, 0, size) != size) return std::nullopt;
    p = {to_rgb(m.image), m.utime, "hand_image_t"};
  } else if (fp == static_cast<uint64_t>(stereo_frame_t::getHash())) {
    stereo_frame_t m;
    if (m.decode(data, 0, size) != size) return std::nullopt;
    cv::Mat l = to_rgb(m.left), r = to_rgb(m.right);
    if (r.rows != l.rows) cv::resize(r, r, cv::Size(r.cols * l.rows / std::max(1, r.rows), l.rows));
    cv::hconcat(l, r, p.rgb);
    p.utime = m.utime;
    p.type = "stereo_frame_t";
  } else {
    return std::nullopt;
  }
  return p;
}

}  // namespace bookgrasp
