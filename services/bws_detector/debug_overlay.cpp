#include "services/bws_detector/debug_overlay.h"

#include <cstdio>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "common/image_caption.h"
#include "common/image_conversion.h"

namespace bookgrasp::bws {

cv::Mat draw_bws_overlay(const cv::Mat& left, const BwsOutput& r, const std::string& title) {
  cv::Mat img = to_rgb_copy(left);
  const cv::Mat& lab = r.segmentation.labels;
  if (lab.empty() || lab.size() != img.size()) return img;
  const size_t K = r.segmentation.regions.size();
  // 0 = none, 1 = dropped, 2 = candidate, 3 = selected.
  std::vector<uint8_t> kind(K + 1, 0);
  for (const RegionVerdict& v : r.selection.regions)
    if (v.label > 0 && size_t(v.label) <= K) kind[size_t(v.label)] = v.candidate ? 2 : 1;
  if (r.selection.selected_label > 0 && size_t(r.selection.selected_label) <= K)
    kind[size_t(r.selection.selected_label)] = 3;
  const cv::Vec3b tint[4] = {{0, 0, 0}, {160, 160, 200}, {40, 220, 40}, {255, 40, 40}};
  const float alpha[4] = {0.f, 0.25f, 0.45f, 0.6f};
  for (int y = 0; y < img.rows; ++y) {
    const int* l = lab.ptr<int>(y);
    const int* ld = y + 1 < img.rows ? lab.ptr<int>(y + 1) : nullptr;
    cv::Vec3b* p = img.ptr<cv::Vec3b>(y);
    for (int x = 0; x < img.cols; ++x) {
      const int a = l[x];
      if (a <= 0 || size_t(a) > K) continue;
      const uint8_t k = kind[size_t(a)];
      const bool border = (x + 1 < img.cols && l[x + 1] != a) || (ld && ld[x] != a) || (x > 0 && l[x - 1] != a) ||
                          (y > 0 && lab.ptr<int>(y - 1)[x] != a);
      const float w = border ? 0.9f : alpha[k];
      for (int c = 0; c < 3; ++c) p[x][c] = cv::saturate_cast<uint8_t>((1.f - w) * p[x][c] + w * tint[k][c]);
    }
  }
  char buf[256];
  int line = 0;
  const auto text = [&](const std::string& s, const cv::Scalar& colour) { line = draw_caption(&img, line, s, colour); };
  int candidates = 0;
  for (const RegionVerdict& v : r.selection.regions) candidates += v.candidate;
  std::snprintf(buf, sizeof buf, "%s: %zu regions, %d candidates (green), selected red", title.c_str(), K, candidates);
  text(buf, cv::Scalar(255, 255, 255));
  if (r.selection.found) {
    const cv::Point pi = r.selection.pi;
    cv::drawMarker(img, pi, cv::Scalar(255, 255, 0), cv::MARKER_CROSS, 14, 2);
    std::snprintf(buf, sizeof buf, "P1 base [%.3f %.3f %.3f] m, grasp [%.3f %.3f %.3f] m%s", r.selection.p1_base.x(),
                  r.selection.p1_base.y(), r.selection.p1_base.z(), r.p1_grasp.x(), r.p1_grasp.y(), r.p1_grasp.z(),
                  r.selection.pi_fallback     ? " (PI fallback)"
                  : r.selection.pi_from_layer ? " (PI on the front layer)"
                                              : "");
    text(buf, cv::Scalar(255, 255, 0));
  } else {
    text("no book: " + r.selection.failure_reason, cv::Scalar(255, 80, 80));
  }
  return img;
}

}  // namespace bookgrasp::bws
