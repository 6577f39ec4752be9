#include "services/snapshot/truth_overlay.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "common/pose_conversion.h"

namespace bookgrasp::snapshot {
namespace {

bool project(const sim_render::PinholeCamera& cam, const Eigen::Vector3d& p, cv::Point2d* px) {
  if (cam.to_camera(p).z() <= 1e-3) return false;
  const Eigen::Vector2d uv = cam.project(p);
  *px = cv::Point2d(uv.x(), uv.y());
  return true;
}

/// cv drawing takes integer points: draw with 4 bits of sub-pixel precision.
cv::Point fixed(const cv::Point2d& p) { return cv::Point(cvRound(p.x * 16.0), cvRound(p.y * 16.0)); }

void line(cv::Mat& img, const cv::Point2d& a, const cv::Point2d& b, const cv::Scalar& c, int t = 1) {
  cv::line(img, fixed(a), fixed(b), c, t, cv::LINE_AA, 4);
}

void label(cv::Mat& img, const std::string& text, cv::Point at, const cv::Scalar& c) {
  cv::putText(img, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
  cv::putText(img, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.4, c, 1, cv::LINE_AA);
}

void draw_marker(cv::Mat& img, const sim_render::PinholeCamera& cam, const pose_t& pose, double size,
                 const std::string& name) {
  if (!is_valid_pose(pose) || size <= 0) return;
  const Eigen::Isometry3d t = pose_to_isometry(pose);
  const double h = 0.5 * size;
  const Eigen::Vector3d local[4] = {{-h, h, 0}, {h, h, 0}, {h, -h, 0}, {-h, -h, 0}};
  cv::Point2d px[4];
  for (int i = 0; i < 4; ++i)
    if (!project(cam, t * local[i], &px[i])) return;
  const cv::Scalar cyan(0, 230, 255);
  for (int i = 0; i < 4; ++i) line(img, px[i], px[(i + 1) % 4], cyan, 1);
  label(img, name, cv::Point(static_cast<int>(px[0].x), static_cast<int>(px[0].y) - 4), cyan);
}

}  // namespace

cv::Mat draw_ground_truth(const cv::Mat& rgb, const ground_truth_t& truth, const sim_render::PinholeCamera& camera,
                          double cart_marker_size_m, double holder_marker_size_m) {
  cv::Mat img = rgb.clone();
  const cv::Scalar green(40, 255, 40), red(255, 40, 40), yellow(255, 255, 0), white(255, 255, 255);
  for (const book_truth_t& b : truth.books) {
    // Front face: corners with bit 0 clear (front), bit 1 = left, bit 2 = top.
    const int face[4] = {4, 6, 2, 0};  // top-right, top-left, bottom-left, bottom-right
    cv::Point2d px[4];
    bool ok = true;
    for (int i = 0; i < 4; ++i) {
      const double* c = b.corners_base[face[i]];
      ok = ok && project(camera, Eigen::Vector3d(c[0], c[1], c[2]), &px[i]);
    }
    if (!ok) continue;
    const cv::Scalar colour = b.rightmost ? red : green;
    for (int i = 0; i < 4; ++i) {
      line(img, px[i], px[(i + 1) % 4], colour, 1);
      cv::circle(img, fixed(px[i]), 2 * 16, colour, 1, cv::LINE_AA, 4);
    }
    label(img, std::to_string(b.id), cv::Point(static_cast<int>(px[1].x), static_cast<int>(px[1].y) - 4), colour);
    if (b.rightmost) {
      cv::Point2d p1;
      if (project(camera, Eigen::Vector3d(b.p1_base[0], b.p1_base[1], b.p1_base[2]), &p1)) {
        cv::circle(img, fixed(p1), 7 * 16, red, 2, cv::LINE_AA, 4);
        label(img, "P1", cv::Point(static_cast<int>(p1.x) + 9, static_cast<int>(p1.y) - 6), red);
      }
    }
  }
  cv::Point2d se;
  if (project(camera, Eigen::Vector3d(truth.stripe_end_base[0], truth.stripe_end_base[1], truth.stripe_end_base[2]),
              &se)) {
    line(img, se + cv::Point2d(-7, -7), se + cv::Point2d(7, 7), yellow, 2);
    line(img, se + cv::Point2d(-7, 7), se + cv::Point2d(7, -7), yellow, 2);
    label(img, "stripe end", cv::Point(static_cast<int>(se.x) + 9, static_cast<int>(se.y) + 14), yellow);
  }
  draw_marker(img, camera, truth.cart_marker, cart_marker_size_m, "cart marker");
  draw_marker(img, camera, truth.holder_marker, holder_marker_size_m, "holder marker");
  char text[160];
  std::snprintf(text, sizeof(text), "%s seed %lld: %d books; green = front faces, red = right-most + P1",
                truth.scene.c_str(), static_cast<long long>(truth.seed), truth.num_books);
  label(img, text, cv::Point(6, 14), white);
  return img;
}

cv::Mat colorize_depth(const cv::Mat& depth) {
  CV_Assert(depth.type() == CV_32FC1);
  std::vector<float> valid;
  valid.reserve(depth.total());
  for (int r = 0; r < depth.rows; ++r) {
    const float* p = depth.ptr<float>(r);
    for (int c = 0; c < depth.cols; ++c)
      if (std::isfinite(p[c])) valid.push_back(p[c]);
  }
  double lo = 0.0, hi = 1.0;
  if (!valid.empty()) {
    std::sort(valid.begin(), valid.end());
    lo = valid[valid.size() / 100];
    hi = valid[valid.size() - 1 - valid.size() / 100];
    if (hi <= lo) hi = lo + 1e-3;
  }
  cv::Mat grey(depth.size(), CV_8UC1);
  cv::Mat invalid(depth.size(), CV_8UC1, cv::Scalar(0));
  for (int r = 0; r < depth.rows; ++r) {
    const float* p = depth.ptr<float>(r);
    for (int c = 0; c < depth.cols; ++c) {
      if (!std::isfinite(p[c])) {
        invalid.at<uchar>(r, c) = 255;
        grey.at<uchar>(r, c) = 0;
        continue;
      }
      const double t = std::clamp((p[c] - lo) / (hi - lo), 0.0, 1.0);
      grey.at<uchar>(r, c) = static_cast<uchar>(std::lround(255.0 * (1.0 - t)));  // near = high = red
    }
  }
  cv::Mat bgr;
  cv::applyColorMap(grey, bgr, cv::COLORMAP_TURBO);
  bgr.setTo(cv::Scalar(0, 0, 0), invalid);
  // Colour bar on the right with the range.
  const int bar_w = 16, x0 = bgr.cols - bar_w - 50, y0 = 30, bar_h = std::max(60, bgr.rows / 2);
  for (int i = 0; i < bar_h; ++i) {
    cv::Mat one(1, 1, CV_8UC1, cv::Scalar(255 - 255 * i / (bar_h - 1)));
    cv::Mat col;
    cv::applyColorMap(one, col, cv::COLORMAP_TURBO);
    cv::line(bgr, cv::Point(x0, y0 + i), cv::Point(x0 + bar_w, y0 + i), cv::Scalar(col.at<cv::Vec3b>(0, 0)), 1);
  }
  char text[64];
  std::snprintf(text, sizeof(text), "%.3f m", lo);
  cv::putText(bgr, text, cv::Point(x0 - 10, y0 - 8), cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
  std::snprintf(text, sizeof(text), "%.3f m", hi);
  cv::putText(bgr, text, cv::Point(x0 - 10, y0 + bar_h + 14), cv::FONT_HERSHEY_SIMPLEX, 0.4,
              cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  cv::putText(bgr, "depth z (left camera)", cv::Point(6, 14), cv::FONT_HERSHEY_SIMPLEX, 0.4,
              cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

}  // namespace bookgrasp::snapshot
