#include "services/bws_detector/top_crease.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "common/config.h"

namespace bookgrasp::bws {

TopCreaseParams TopCreaseParams::from_config(const Config& c) {
  TopCreaseParams p;
  p.enabled = c.get<bool>("top_crease");
  p.columns = c.get_int("top_crease_columns", 1, 1000);
  p.right_margin_px = c.get_int("top_crease_right_margin_px", 0, 1000);
  p.rows_above = c.get_int("top_crease_rows_above", 0, 1000);
  p.rows_below = c.get_int("top_crease_rows_below", 0, 1000);
  p.search_down_m = c.get_double("top_crease_search_down_m", 0.0, 1.0);
  p.search_up_m = c.get_double("top_crease_search_up_m", 0.0, 1.0);
  p.step_m = c.get_double("top_crease_step_m", 1e-5, 0.1);
  p.residual_cap_px = c.get_double("top_crease_residual_cap_px", 1e-3, 100.0);
  p.min_pixels_each_side = c.get_int("top_crease_min_pixels_each_side", 1, 100000);
  p.right_columns = c.get_int("top_crease_right_columns", 1, 1000);
  p.max_right_difference_m = c.get_double("top_crease_max_right_difference_m", 0.0, 1.0);
  return p;
}

namespace {
/// One window pixel: its measured disparity, the front's disparity on its ray, and where the ray meets
/// the front's plane and the direction of the ray along `up` (unnormalised ray, z = 1).
struct WindowPixel {
  double disparity;
  double front_disparity;
  double front_height;  // up . p where the ray meets the front's plane
  double up_per_depth;  // up . ray
  int right_part;       // 1 in the right-most columns fitted apart (TopCreaseParams::right_columns), 0 left of them
};
}  // namespace

Eigen::Vector3d up_within_plane(const Eigen::Vector3d& up, const Eigen::Vector3d& normal) {
  return up - up.dot(normal) * normal;
}

TopCrease fit_top_crease(const cv::Mat& points_camera, const StereoGeometry& g, const Eigen::Vector3d& normal,
                         double offset, const Eigen::Vector3d& up, cv::Point pi, double start_height,
                         const cv::Mat& columns_mask, const TopCreaseParams& p) {
  if (points_camera.type() != CV_32FC3) throw std::invalid_argument("fit_top_crease: points must be CV_32FC3");
  TopCrease out;
  const double fb = g.fx * g.baseline_m;
  const auto ray_of = [&](double x, double y) { return Eigen::Vector3d((x - g.cx) / g.fx, (y - g.cy) / g.fy, 1.0); };
  // The rows the searched heights project to in PI's column (the front's top edge moves along it): the point
  // on the front's plane at height h straight above or below PI's point q, projected.
  const Eigen::Vector3d pi_ray = ray_of(pi.x, pi.y);
  const double pi_dn = normal.dot(pi_ray);
  const Eigen::Vector3d q = pi_ray * (offset / pi_dn);
  Eigen::Vector3d v = up_within_plane(up, normal);
  const bool projects = std::fabs(pi_dn) >= 1e-9 && v.norm() >= 1e-9;
  v /= up.dot(v);  // so that up . (q + s v) = up . q + s
  const auto row_at_height = [&](double h) {
    if (!projects) return double(pi.y);
    const Eigen::Vector3d a = q + (h - up.dot(q)) * v;
    return a.z() > 1e-6 ? g.fy * a.y() / a.z() + g.cy : double(pi.y);
  };
  const double h_lo = start_height - p.search_down_m, h_hi = start_height + p.search_up_m;
  const double r_top = row_at_height(h_hi), r_bottom = row_at_height(h_lo);
  // Clamped before the conversion: a ray almost parallel to the front's plane projects far out.
  const double rows = points_camera.rows;
  const int y0 = std::max(0, int(std::floor(std::clamp(std::min(r_top, r_bottom), -1.0, rows))) - p.rows_above);
  const int y1 = std::min(points_camera.rows - 1,
                          int(std::ceil(std::clamp(std::max(r_top, r_bottom), -1.0, rows))) + p.rows_below);
  const int x1 = std::min(points_camera.cols - 1, pi.x - p.right_margin_px);
  const int x0 = std::max(0, x1 - p.columns + 1);
  // The window's columns of the front; the check fits its right-most p.right_columns apart from the rest.
  std::vector<int> used;
  for (int x = x0; x <= x1; ++x)
    if (columns_mask.empty() || columns_mask.at<uchar>(0, x)) used.push_back(x);
  const int split_x =
      used.size() >= 2 ? used[used.size() - size_t(std::clamp(p.right_columns, 1, int(used.size()) - 1))] : x1 + 1;
  std::vector<WindowPixel> px;
  for (int y = y0; y <= y1; ++y) {
    const cv::Vec3f* q = points_camera.ptr<cv::Vec3f>(y);
    for (int x = x0; x <= x1; ++x) {
      if (!columns_mask.empty() && !columns_mask.at<uchar>(0, x)) continue;
      if (!std::isfinite(q[x][2]) || q[x][2] <= 0.0f) continue;
      const Eigen::Vector3d r = ray_of(x, y);
      const double dn = normal.dot(r);
      if (std::fabs(dn) < 1e-9 || !(offset / dn > 0.0)) continue;
      const double depth = offset / dn;  // r.z = 1: the front's z on this ray
      px.push_back({fb / q[x][2], fb / depth, depth * up.dot(r), up.dot(r), x >= split_x ? 1 : 0});
    }
  }
  const double cap2 = p.residual_cap_px * p.residual_cap_px;
  double best_cost = std::numeric_limits<double>::infinity();
  double best_part_cost[2] = {best_cost, best_cost};
  const int steps = int(std::floor((h_hi - h_lo) / p.step_m + 1e-9));
  for (int i = 0; i <= steps; ++i) {
    const double h = h_lo + i * p.step_m;
    double cost = 0.0, part_cost[2] = {0.0, 0.0};
    int front = 0, top = 0;
    for (const WindowPixel& w : px) {
      double e2 = cap2;
      bool on_front = false;
      if (w.front_height <= h) {
        on_front = true;
        const double e = w.disparity - w.front_disparity;
        e2 = std::min(cap2, e * e);
      } else if (w.up_per_depth * h > 0.0) {
        // Above the edge: the ray meets the top face { up . p = h } at depth h / (up . ray).
        const double e = w.disparity - fb * w.up_per_depth / h;
        e2 = std::min(cap2, e * e);
      }
      cost += e2;
      part_cost[w.right_part] += e2;
      if (e2 < cap2) ++(on_front ? front : top);
    }
    if (cost < best_cost) {
      best_cost = cost;
      out.height = h;
      out.front_pixels = front;
      out.top_pixels = top;
    }
    for (int k = 0; k < 2; ++k)
      if (part_cost[k] < best_part_cost[k]) {
        best_part_cost[k] = part_cost[k];
        (k ? out.right_height : out.left_height) = h;
      }
  }
  out.found = std::isfinite(best_cost) && out.front_pixels >= p.min_pixels_each_side &&
              out.top_pixels >= p.min_pixels_each_side &&
              (p.max_right_difference_m <= 0.0 || used.size() < 2 ||
               std::fabs(out.left_height - out.right_height) <= p.max_right_difference_m);
  return out;
}

}  // namespace bookgrasp::bws
