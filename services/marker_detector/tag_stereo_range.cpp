#include "services/marker_detector/tag_stereo_range.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

namespace bookgrasp {

TagStereoRangeParams TagStereoRangeParams::from_config(const Config& c) {
  TagStereoRangeParams p;
  p.enabled = c.get<bool>("enabled");
  p.margin = c.get_double("margin", 0.0, 2.0);
  p.min_depth_m = c.get_double("min_depth_m", 0.05, 100.0);
  p.min_score = c.get_double("min_score", 0.0, 1.0);
  p.max_disagreement = c.get_double("max_disagreement", 0.0, 1.0);
  return p;
}

TagStereoRange range_tag_in_stereo(const cv::Mat& left, const cv::Mat& right, const std::array<cv::Point2d, 4>& corners,
                                   double fx, double cx_left, double cx_right, double baseline_m,
                                   const TagStereoRangeParams& p, double monocular_depth_m) {
  TagStereoRange r;
  if (left.type() != CV_8UC1 || right.type() != CV_8UC1 || left.size() != right.size()) {
    r.reason = "the stereo pair must be two grey images of one size";
    return r;
  }
  if (!(fx > 0) || !(baseline_m > 0) || !std::isfinite(cx_left) || !std::isfinite(cx_right)) {
    r.reason = "the stereo calibration needs fx > 0, a baseline > 0 and finite principal points";
    return r;
  }
  double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
  for (const auto& c : corners) {
    if (!std::isfinite(c.x) || !std::isfinite(c.y)) {
      r.reason = "non-finite tag corner";
      return r;
    }
    x0 = std::min(x0, c.x), y0 = std::min(y0, c.y), x1 = std::max(x1, c.x), y1 = std::max(y1, c.y);
  }
  const double grow = p.margin * std::max(x1 - x0, y1 - y0);
  const cv::Rect patch(
      cv::Point(static_cast<int>(std::floor(x0 - grow)), static_cast<int>(std::floor(y0 - grow))),
      cv::Point(static_cast<int>(std::ceil(x1 + grow)) + 1, static_cast<int>(std::ceil(y1 + grow)) + 1));
  const cv::Rect image(0, 0, left.cols, left.rows);
  if ((patch & image) != patch) {
    r.reason = "the tag's patch leaves the image";
    return r;
  }
  // Shifts searched: the right image sees the tag `shift` columns further left; disparity = shift + cx_r - cx_l.
  const double offset = cx_right - cx_left;
  const int max_shift = static_cast<int>(std::ceil(fx * baseline_m / p.min_depth_m - offset)) + 1;
  const int first_col = std::max(0, patch.x - max_shift);
  const int min_shift = std::max(0, static_cast<int>(std::floor(-offset)) - 1);
  const int last_col = patch.x - min_shift;  // left edge of the patch's position in the right image
  // Where the monocular depth puts the patch's left edge in the right image: left of column 0, no match can be
  // found, and the message says so rather than blaming the match.
  const double expected_col = patch.x - (fx * baseline_m / monocular_depth_m - offset);
  const auto outside_right = [&]() {
    if (!(monocular_depth_m > 0) || !(expected_col < 0)) return false;
    char b[200];
    std::snprintf(b, sizeof b,
                  "the tag is outside the right image: at its monocular depth %.2f m, its patch would start at column "
                  "%.0f",
                  monocular_depth_m, expected_col);
    r.reason = b;
    return true;
  };
  if (last_col - first_col < 2) {
    if (outside_right()) return r;
    r.reason = "no room to search the right image (the tag is at its left edge)";
    return r;
  }
  const cv::Mat strip = right(cv::Rect(first_col, patch.y, last_col - first_col + patch.width, patch.height));
  cv::Mat score;
  cv::matchTemplate(strip, left(patch), score, cv::TM_CCOEFF_NORMED);
  cv::Point best;
  double best_score = 0;
  cv::minMaxLoc(score, nullptr, &best_score, nullptr, &best);
  r.score = best_score;
  if (!(best_score >= p.min_score)) {
    if (outside_right()) return r;
    char b[160];
    std::snprintf(b, sizeof b, "the tag's patch matches the right image at %.2f only (stereo_range.min_score %.2f)",
                  best_score, p.min_score);
    r.reason = b;
    return r;
  }
  double sub = 0;
  if (best.x > 0 && best.x + 1 < score.cols) {
    const double a = score.at<float>(0, best.x - 1), b = score.at<float>(0, best.x), c = score.at<float>(0, best.x + 1);
    const double den = a - 2 * b + c;
    if (den < 0) sub = std::clamp(0.5 * (a - c) / den, -0.5, 0.5);
  }
  const double right_col = first_col + best.x + sub;
  r.disparity_px = (patch.x - right_col) + offset;
  if (!(r.disparity_px > 0)) {
    r.reason = "the tag's disparity is not positive (at infinity or the pair is swapped)";
    return r;
  }
  r.depth_m = fx * baseline_m / r.disparity_px;
  r.ok = true;
  return r;
}

Eigen::Isometry3d tag_pose_at_depth(const Eigen::Isometry3d& tag_in_camera, double depth_m) {
  Eigen::Isometry3d out = tag_in_camera;
  const double z = tag_in_camera.translation().z();
  if (z > 0 && depth_m > 0) out.translation() *= depth_m / z;
  return out;
}

}  // namespace bookgrasp
