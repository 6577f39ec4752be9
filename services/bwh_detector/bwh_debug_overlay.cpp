#include "services/bwh_detector/bwh_debug_overlay.h"

#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "common/image_caption.h"
#include "common/image_conversion.h"

namespace bookgrasp {

cv::Mat draw_bwh_overlay(const cv::Mat& image, const BookDetection& d, int rank_from_right, const std::string& title) {
  cv::Mat img = to_rgb_copy(image);
  if (d.stripe.found) cv::line(img, d.stripe.line_start, d.stripe.line_end, cv::Scalar(255, 0, 255), 1, cv::LINE_AA);
  const int selected = rank_from_right >= 0 && rank_from_right < static_cast<int>(d.ranking.size())
                           ? d.ranking[static_cast<size_t>(rank_from_right)]
                           : -1;
  for (const BookCandidate& c : d.candidates) {
    const bool chosen = c.id == selected;
    const cv::Scalar colour = chosen       ? cv::Scalar(255, 40, 40)
                              : c.accepted ? cv::Scalar(40, 220, 40)
                                           : cv::Scalar(170, 170, 170);
    cv::rectangle(img, c.bbox, colour, chosen ? 2 : 1);
    if (!c.accepted) continue;
    cv::drawMarker(img, c.corner_r, colour, cv::MARKER_CROSS, 14, chosen ? 2 : 1, cv::LINE_AA);
    // The slope: a line from R along the upper edge towards the book's left corner.
    const double len = std::max(20.0, c.width_px);
    const cv::Point2d dir(-std::cos(c.slope_rad), -std::sin(c.slope_rad));
    cv::line(img, c.corner_r, c.corner_r + len * dir, colour, 1, cv::LINE_AA);
    cv::putText(img, std::to_string(c.id), c.bbox.tl() + cv::Point(3, 14), cv::FONT_HERSHEY_PLAIN, 1.0, colour);
  }
  char buf[256];
  int accepted = 0;
  for (const BookCandidate& c : d.candidates) accepted += c.accepted;
  std::snprintf(buf, sizeof buf, "%s: %zu candidates, %d books (green), rank %d red", title.c_str(),
                d.candidates.size(), accepted, rank_from_right);
  const int next = draw_caption(&img, 0, buf, cv::Scalar(255, 255, 255));
  if (selected >= 0) {
    const BookCandidate& b = d.candidates[static_cast<size_t>(selected)];
    std::snprintf(buf, sizeof buf, "R (%.1f, %.1f) px, slope %.2f deg, width %.1f px%s", b.corner_r.x, b.corner_r.y,
                  b.slope_rad * 180.0 / CV_PI, b.width_px, b.refined ? "" : " (outline, not refined)");
    draw_caption(&img, next, buf, cv::Scalar(255, 80, 80));
  } else {
    draw_caption(&img, next, "no book: " + (d.found ? "rank beyond the books found" : d.failure_reason),
                 cv::Scalar(255, 80, 80));
  }
  return img;
}

}  // namespace bookgrasp
