#include "services/bswh_detector/stripe_debug_overlay.h"

#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "common/image_caption.h"
#include "common/image_conversion.h"

namespace bookgrasp {

cv::Mat draw_bswh_overlay(const cv::Mat& image, const StripeDetection& d, const std::string& title) {
  cv::Mat img = to_rgb_copy(image);
  char buf[256];
  if (d.found) {
    // The band's two borders half a thickness either side of the centre line, then the line itself.
    const cv::Point2d along = d.line_end - d.line_start;
    const double n = std::hypot(along.x, along.y);
    const cv::Point2d normal = n > 0 ? cv::Point2d(-along.y / n, along.x / n) : cv::Point2d(0, 1);
    const cv::Point2d half = 0.5 * d.thickness_px * normal;
    cv::line(img, d.line_start + half, d.line_end + half, cv::Scalar(255, 160, 255), 1, cv::LINE_AA);
    cv::line(img, d.line_start - half, d.line_end - half, cv::Scalar(255, 160, 255), 1, cv::LINE_AA);
    cv::line(img, d.line_start, d.line_end, cv::Scalar(255, 0, 255), 2, cv::LINE_AA);
  }
  if (d.end_found) cv::drawMarker(img, d.end, cv::Scalar(255, 40, 40), cv::MARKER_CROSS, 16, 2, cv::LINE_AA);
  std::snprintf(buf, sizeof buf, "%s: stripe %s, end %s", title.c_str(), d.found ? "found" : "not found",
                d.end_found ? "found" : "not found");
  const int next = draw_caption(&img, 0, buf, cv::Scalar(255, 255, 255));
  if (d.end_found) {
    std::snprintf(buf, sizeof buf, "end (%.1f, %.1f) px, angle %.2f deg, thickness %.1f px, edge rows %d", d.end.x,
                  d.end.y, d.angle_rad * 180.0 / CV_PI, d.thickness_px, d.end_edge_support);
    draw_caption(&img, next, buf, cv::Scalar(255, 80, 80));
  } else {
    draw_caption(&img, next, d.failure_reason, cv::Scalar(255, 80, 80));
  }
  return img;
}

}  // namespace bookgrasp
