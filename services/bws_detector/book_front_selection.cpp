#include "services/bws_detector/book_front_selection.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <vector>

#include "common/config.h"

namespace bookgrasp::bws {

SelectionParams SelectionParams::from_config(const Config& c) {
  SelectionParams p;
  p.parallel_tolerance_deg = c.get_double("parallel_tolerance_deg", 0.0, 90.0);
  p.perpendicular_tolerance_deg = c.get_double("perpendicular_tolerance_deg", 0.0, 90.0);
  p.min_width_m = c.get_double("min_width_m", 0.0, 10.0);
  p.max_width_m = c.get_double("max_width_m", p.min_width_m, 10.0);
  p.min_height_m = c.get_double("min_height_m", 0.0, 10.0);
  p.max_height_m = c.get_double("max_height_m", p.min_height_m, 10.0);
  p.min_inside_fraction = c.get_double("min_inside_fraction", 0.0, 1.0);
  p.min_pixels = c.get_int("min_pixels", 1, 100000000);
  p.extent_quantile = c.get_double("extent_quantile", 0.0, 0.49);
  p.split_wide_fronts = c.get<bool>("split_wide_fronts");
  p.split_top_jump_px = c.get_int("split_top_jump_px", 1, 1000);
  p.split_depth_step_m = c.get_double("split_depth_step_m", 0.0, 1.0);
  TopGrowthParams& t = p.top_growth;
  t.max_px = c.get_int("top_growth_px", 0, 1000);
  t.disparity_px = c.get_double("top_growth_disparity_px", 0.0, 100.0);
  t.max_gap_px = c.get_int("top_growth_max_gap_px", 0, 1000);
  t.max_hole_px = c.get_int("top_growth_max_hole_px", -1, 1000);
  t.columns = c.get_int("top_growth_columns", 1, 1000);
  t.climbed_only = c.get<bool>("top_growth_climbed_only");
  p.layer_disparity_px = c.get_double("layer_disparity_px", 0.0, 100.0);
  p.layer_min_rows = c.get_int("layer_min_rows", 1, 10000);
  p.layer_min_columns = c.get_int("layer_min_columns", 1, 10000);
  p.layer_min_shift_px = c.get_int("layer_min_shift_px", 0, 10000);
  p.layer_without_front_m = c.get_double("layer_without_front_m", 0.0, 10.0);
  p.edge_fattening_px = c.get_double("edge_fattening_px", 0.0, 100.0);
  p.pi_rule =
      c.get_choice("pi_rule", {"paper", "right_column_top"}) == "paper" ? PiRule::kPaper : PiRule::kRightColumnTop;
  p.front_plane =
      c.get_choice("front_plane", {"region", "rear_board"}) == "region" ? FrontPlane::kRegion : FrontPlane::kRearBoard;
  p.top_crease = TopCreaseParams::from_config(c);
  return p;
}

cv::Point upper_right_corner(const cv::Mat& labels, int label, bool* fallback) {
  if (labels.type() != CV_32S) throw std::invalid_argument("upper_right_corner: labels must be CV_32S");
  int y_min = -1, x_max = -1;
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    for (int x = 0; x < labels.cols; ++x)
      if (l[x] == label) {
        if (y_min < 0) y_min = y;
        x_max = std::max(x_max, x);
      }
  }
  if (y_min < 0) throw std::invalid_argument("upper_right_corner: label " + std::to_string(label) + " not present");
  if (labels.at<int>(y_min, x_max) == label) {
    if (fallback) *fallback = false;
    return {x_max, y_min};
  }
  if (fallback) *fallback = true;
  long best = std::numeric_limits<long>::max();
  cv::Point best_p(-1, -1);
  for (int y = y_min; y < labels.rows; ++y) {  // no region pixel above y_min
    const long dy = y - y_min;
    if (dy * dy > best) break;
    const int* l = labels.ptr<int>(y);
    for (int x = x_max; x >= 0; --x) {  // larger column first: ties keep the larger column
      if (l[x] != label) continue;
      const long dx = x_max - x;
      const long d = dx * dx + dy * dy;
      if (d < best) {
        best = d;
        best_p = {x, y};
      }
    }
  }
  return best_p;
}

cv::Point right_column_top(const cv::Mat& labels, int label) {
  constexpr int kMinColumnPixels = 3;
  if (labels.type() != CV_32S) throw std::invalid_argument("right_column_top: labels must be CV_32S");
  std::vector<int> count(size_t(labels.cols), 0);
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    for (int x = 0; x < labels.cols; ++x) count[size_t(x)] += l[x] == label;
  }
  const int fullest = *std::max_element(count.begin(), count.end());
  if (fullest == 0) throw std::invalid_argument("right_column_top: label " + std::to_string(label) + " not present");
  const int need = std::min(kMinColumnPixels, fullest);
  int x = labels.cols - 1;
  while (count[size_t(x)] < need) --x;
  int top = -1;
  for (int y = 0; y < labels.rows; ++y) {
    if (labels.at<int>(y, x) != label) continue;
    if (top < 0) top = y;
    if (y + 1 < labels.rows && labels.at<int>(y + 1, x) == label) return {x, y};
  }
  return {x, top};
}

cv::Point raise_to_plane_top(const cv::Mat& labels, int label, cv::Point pi, const cv::Mat& points_camera,
                             const Eigen::Vector3d& normal, double offset, const StereoGeometry& g,
                             const TopGrowthParams& t) {
  if (labels.type() != CV_32S || points_camera.type() != CV_32FC3 || points_camera.size() != labels.size())
    throw std::invalid_argument("raise_to_plane_top: CV_32S labels and CV_32FC3 points of one size expected");
  const double fb = g.fx * g.baseline_m;
  std::vector<int> tops, climbed;
  for (int x = pi.x; x > pi.x - t.columns && x >= 0; --x) {
    int top = -1;
    for (int y = 0; y < labels.rows && top < 0; ++y)
      if (labels.at<int>(y, x) == label) top = y;
    if (top < 0) continue;
    // Rows since the last one on the plane: off it, and without depth.
    int off = 0, holes = 0;
    const auto bridged = [&] {
      return t.max_hole_px < 0 ? off + holes <= t.max_gap_px : off <= t.max_gap_px && holes <= t.max_hole_px;
    };
    const int start = top;
    for (int y = start - 1; y >= 0 && start - y <= t.max_px; --y) {
      const cv::Vec3f q = points_camera.at<cv::Vec3f>(y, x);
      if (!std::isfinite(q[2]) || q[2] <= 0.0f) {
        ++holes;
        if (!bridged()) break;
        continue;
      }
      const double denom = normal.dot(Eigen::Vector3d((x - g.cx) / g.fx, (y - g.cy) / g.fy, 1.0));
      if (std::fabs(denom) < 1e-9) break;
      const double z_plane = offset / denom;
      if (!(z_plane > 0.0) || std::fabs(fb / q[2] - fb / z_plane) > t.disparity_px) {
        ++off;
        if (!bridged()) break;
        continue;
      }
      top = y;
      off = holes = 0;
    }
    tops.push_back(top);
    if (start - top > t.max_gap_px) climbed.push_back(top);
  }
  if (t.climbed_only && !climbed.empty()) tops = climbed;
  if (tops.empty()) return pi;
  std::nth_element(tops.begin(), tops.begin() + long(tops.size() / 2), tops.end());
  return {pi.x, std::min(pi.y, tops[tops.size() / 2])};
}

namespace {
/// A stereo point with all three coordinates finite.
bool finite_point(const cv::Vec3f& q) {
  return std::isfinite(q[0]) && std::isfinite(q[1]) && std::isfinite(q[2]);
}
/// q (in the shelf box frame, float or double) inside the box of these half sizes.
template <typename Vec>
bool inside_box(const Vec& q, const Eigen::Vector3d& half_extent) {
  return std::fabs(q.x()) <= half_extent.x() && std::fabs(q.y()) <= half_extent.y() &&
         std::fabs(q.z()) <= half_extent.z();
}
size_t quantile_index(size_t n, double q) {
  return std::min(n - 1, size_t(std::floor(q * double(n - 1) + 0.5)));
}
double quantile(std::vector<double>& v, double q) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  const size_t k = quantile_index(v.size(), q);
  std::nth_element(v.begin(), v.begin() + long(k), v.end());
  return v[k];
}
/// quantile(v, q) and quantile(v, 1 - q) (q <= 0.5): the upper one is selected among the elements
/// above the lower one only (an order statistic is one value whatever the selection did before).
///
/// Exact, without moving `v` around: the values are counted into buckets of equal width between the
/// minimum and the maximum (a monotone map, so equal values share a bucket and a bucket's values all lie
/// between the previous and the next bucket's), and each order statistic is selected among the values
/// of its bucket only. Falls back to nth_element on the whole array for non-finite values.
std::pair<double, double> quantile_pair(std::vector<double>& v, double q) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (v.empty()) return {nan, nan};
  const size_t k0 = quantile_index(v.size(), q), k1 = quantile_index(v.size(), 1.0 - q);
  const size_t n = v.size();
  double lo = v[0], hi = v[0];
  for (size_t i = 1; i < n; ++i) {
    lo = std::min(lo, v[i]);
    hi = std::max(hi, v[i]);
  }
  if (n >= 64 && std::isfinite(lo) && std::isfinite(hi) && std::isfinite(hi - lo)) {
    if (lo == hi) return {lo, lo};
    constexpr int kBuckets = 256;
    const double scale = double(kBuckets) / (hi - lo);
    const auto bucket = [&](double x) { return std::min(kBuckets - 1, int((x - lo) * scale)); };
    size_t count[kBuckets] = {};
    for (size_t i = 0; i < n; ++i) ++count[bucket(v[i])];
    // Buckets holding ranks k0 and k1, and the rank of each bucket's first value.
    int b0 = 0, b1 = 0;
    size_t below0 = 0, below1 = 0, acc = 0;
    for (int b = 0; b < kBuckets; ++b) {
      if (acc <= k0 && k0 < acc + count[b]) {
        b0 = b;
        below0 = acc;
      }
      if (acc <= k1 && k1 < acc + count[b]) {
        b1 = b;
        below1 = acc;
      }
      acc += count[b];
    }
    thread_local std::vector<double> s0, s1;
    s0.clear();
    s1.clear();
    for (size_t i = 0; i < n; ++i) {
      const int b = bucket(v[i]);
      if (b == b0) s0.push_back(v[i]);
      if (b == b1) s1.push_back(v[i]);
    }
    std::nth_element(s0.begin(), s0.begin() + long(k0 - below0), s0.end());
    std::nth_element(s1.begin(), s1.begin() + long(k1 - below1), s1.end());
    return {s0[k0 - below0], s1[k1 - below1]};
  }
  std::nth_element(v.begin(), v.begin() + long(k0), v.end());
  if (k1 > k0) std::nth_element(v.begin() + long(k0) + 1, v.begin() + long(k1), v.end());
  return {v[k0], v[k1]};
}
std::string fmt(double v, int prec = 3) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(prec);
  s << v;
  return s.str();
}
/// Column bands of region `label`: split at empty columns, top-contour jumps and depth steps.
/// `depth` is the per-pixel coordinate along the rear-board normal (NaN = none).
std::vector<std::pair<int, int>> column_bands(const cv::Mat& labels, int label, const cv::Rect& bbox,
                                              const cv::Mat& depth, const SelectionParams& p) {
  std::vector<int> top(size_t(bbox.width), -1);
  std::vector<double> med(size_t(bbox.width), std::numeric_limits<double>::quiet_NaN());
  std::vector<double> col;
  for (int i = 0; i < bbox.width; ++i) {
    const int x = bbox.x + i;
    col.clear();
    for (int y = bbox.y; y < bbox.y + bbox.height; ++y) {
      if (labels.at<int>(y, x) != label) continue;
      if (top[size_t(i)] < 0) top[size_t(i)] = y;
      const float d = depth.at<float>(y, x);
      if (std::isfinite(d)) col.push_back(d);
    }
    if (!col.empty()) med[size_t(i)] = quantile(col, 0.5);
  }
  std::vector<std::pair<int, int>> bands;
  int start = -1;
  for (int i = 0; i < bbox.width; ++i) {
    if (top[size_t(i)] < 0) {
      if (start >= 0) bands.emplace_back(bbox.x + start, bbox.x + i - 1);
      start = -1;
      continue;
    }
    if (start >= 0) {
      const bool jump = std::abs(top[size_t(i)] - top[size_t(i - 1)]) > p.split_top_jump_px;
      const bool step = std::isfinite(med[size_t(i)]) && std::isfinite(med[size_t(i - 1)]) &&
                        std::fabs(med[size_t(i)] - med[size_t(i - 1)]) > p.split_depth_step_m;
      if (jump || step) {
        bands.emplace_back(bbox.x + start, bbox.x + i - 1);
        start = i;
      }
    } else {
      start = i;
    }
  }
  if (start >= 0) bands.emplace_back(bbox.x + start, bbox.x + bbox.width - 1);
  return bands;
}

/// The right-most front on the fronts' layer (SelectionParams::layer_*), see rightmost_front_on_layer.
struct FrontLayer {
  /// Top of the layer's right-most front (its right-most column, topmost layer pixel with one below);
  /// x = -1 if the layer has none.
  cv::Point top{-1, -1};
  /// The layer's pixels as `label`, 0 elsewhere (CV_32S; columns from x_begin only).
  cv::Mat mask;
  /// Offset of the layer's plane (normal . p = offset) through the right-most front's columns.
  double offset = 0.0;
};

/// The fronts' layer: the pixels (columns x_begin.. only) whose disparity is within
/// p.layer_disparity_px of the plane { normal . p = offset } (left camera frame) and whose point lies
/// inside the upper-shelf volume (cam_in_box, half_extent). Its right-most front is the right-most run
/// of p.layer_min_columns columns that each hold >= p.layer_min_rows layer pixels, reach p.min_height_m
/// above the volume's floor (the shelf board's top near its front edge lies in the layer too, but low;
/// a side board can hide a front's lower part), and whose topmost layer pixels differ by at most
/// p.split_top_jump_px from column to column (a front's top is level; what block matching smears onto
/// the plane beside the right-most front falls off column by column).
FrontLayer rightmost_front_on_layer(const cv::Mat& points_camera, const StereoGeometry& g,
                                    const Eigen::Vector3d& normal, double offset, const Eigen::Isometry3d& cam_in_box,
                                    const Eigen::Vector3d& half_extent, int x_begin, int label,
                                    const SelectionParams& p) {
  const double fb = g.fx * g.baseline_m;
  const int rows = points_camera.rows, cols = points_camera.cols;
  thread_local cv::Mat mask;
  mask.create(points_camera.size(), CV_32S);
  mask.setTo(cv::Scalar(0));
  std::vector<int> count(size_t(cols), 0), first_row(size_t(cols), -1);
  std::vector<float> high(size_t(cols), -std::numeric_limits<float>::infinity());
  for (int y = 0; y < rows; ++y) {
    const cv::Vec3f* q = points_camera.ptr<cv::Vec3f>(y);
    int* o = mask.ptr<int>(y);
    for (int x = x_begin; x < cols; ++x) {
      if (!finite_point(q[x]) || q[x][2] <= 0.0f) continue;
      const double dn = normal.dot(Eigen::Vector3d((x - g.cx) / g.fx, (y - g.cy) / g.fy, 1.0));
      if (std::fabs(dn) < 1e-9 || !(offset / dn > 0.0)) continue;
      if (std::fabs(fb / q[x][2] - fb * dn / offset) > p.layer_disparity_px) continue;
      const Eigen::Vector3d qb = cam_in_box * Eigen::Vector3d(q[x][0], q[x][1], q[x][2]);
      if (!inside_box(qb, half_extent)) continue;
      o[x] = label;
      if (count[size_t(x)]++ == 0) first_row[size_t(x)] = y;
      high[size_t(x)] = std::max(high[size_t(x)], float(qb.z()));
    }
  }
  FrontLayer out;
  out.mask = mask;
  int right = -1;
  for (int x = cols - 1, run = 0; x >= x_begin && right < 0; --x) {
    const size_t i = size_t(x);
    const bool filled = count[i] >= p.layer_min_rows && high[i] + half_extent.z() >= p.min_height_m;
    const bool level = run == 0 || std::abs(first_row[i] - first_row[i + 1]) <= p.split_top_jump_px;
    run = filled ? (level ? run + 1 : 1) : 0;
    if (run == p.layer_min_columns) right = x + p.layer_min_columns - 1;
  }
  if (right < 0) return out;
  for (int y = 0; y + 1 < rows && out.top.x < 0; ++y)
    if (mask.at<int>(y, right) == label && mask.at<int>(y + 1, right) == label) out.top = {right, y};
  if (out.top.x < 0) return out;
  std::vector<double> offs;
  for (int y = 0; y < rows; ++y)
    for (int x = std::max(0, right - p.layer_min_columns + 1); x <= right; ++x)
      if (mask.at<int>(y, x) == label) {
        const cv::Vec3f& q = points_camera.at<cv::Vec3f>(y, x);
        offs.push_back(normal.dot(Eigen::Vector3d(q[0], q[1], q[2])));
      }
  out.offset = quantile(offs, 0.5);  // the run's columns hold >= layer_min_rows pixels each
  return out;
}

/// Offset (normal . p = offset, left camera frame, normal = the rear board's) of the plane parallel to
/// the rear board where the valid points inside the upper-shelf volume lie densest: the window of
/// `window_m` along the box's x axis holding the most points (in steps of a third of it), and the
/// median of the points inside it. NaN if no point lies inside the volume.
double densest_layer_offset(const cv::Mat& points_camera, const Eigen::Isometry3d& cam_in_box,
                            const Eigen::Vector3d& half_extent, double window_m) {
  const double step = window_m / 3.0;
  const int bins = int(std::ceil(2.0 * half_extent.x() / step)) + 1;
  std::vector<int> count(size_t(bins), 0);
  std::vector<double> xs;
  for (int y = 0; y < points_camera.rows; ++y) {
    const cv::Vec3f* q = points_camera.ptr<cv::Vec3f>(y);
    for (int x = 0; x < points_camera.cols; ++x) {
      if (!finite_point(q[x]) || q[x][2] <= 0.0f) continue;
      const Eigen::Vector3d b = cam_in_box * Eigen::Vector3d(q[x][0], q[x][1], q[x][2]);
      if (!inside_box(b, half_extent)) continue;
      xs.push_back(b.x());
      ++count[size_t(std::min(bins - 1, int((b.x() + half_extent.x()) / step)))];
    }
  }
  if (xs.empty()) return std::numeric_limits<double>::quiet_NaN();
  int best = 0, best_count = -1;
  for (int i = 0; i + 2 < bins || i == 0; ++i) {
    int n = 0;
    for (int k = i; k < std::min(bins, i + 3); ++k) n += count[size_t(k)];
    if (n > best_count) {
      best_count = n;
      best = i;
    }
  }
  const double lo = -half_extent.x() + best * step, hi = lo + 3.0 * step;
  std::vector<double> in;
  for (double v : xs)
    if (v >= lo && v <= hi) in.push_back(v);
  return quantile(in, 0.5) - cam_in_box.translation().x();
}

/// The end of the selection: PI (out.pi, on the pixels of `label` in `mask`) grows up the front's
/// plane { normal . p = offset } (left camera frame), and P1 is where PI's ray meets that plane; then
/// P1 moves up or down that plane to the height of the top's crease (`up` = the shelf's normal, camera
/// frame; SelectionParams::top_crease).
BookFrontResult p1_on_plane(const cv::Mat& mask, int label, const Eigen::Vector3d& normal, double offset,
                            const Eigen::Vector3d& up, const cv::Mat& points_camera, const StereoGeometry& g,
                            const Eigen::Isometry3d& camera_in_base, const SelectionParams& p, BookFrontResult out) {
  if (p.top_growth.max_px > 0)
    out.pi = raise_to_plane_top(mask, label, out.pi, points_camera, normal, offset, g, p.top_growth);
  // P1's ray: through PI moved edge_fattening_px left and down (StereoBM's border of a near surface
  // in front of a farther one lies that far out; the right-most front's right and top edges are such).
  const Eigen::Vector3d ray((out.pi.x - p.edge_fattening_px - g.cx) / g.fx,
                            (out.pi.y + p.edge_fattening_px - g.cy) / g.fy, 1.0);
  const double denom = normal.dot(ray);
  if (std::fabs(denom) > 0.05 * ray.norm()) {
    out.p1_camera = ray * (offset / denom);
  } else {
    const cv::Vec3f q = points_camera.at<cv::Vec3f>(out.pi);
    if (!std::isfinite(q[2])) {
      out.failure_reason = "PI has no 3D point and its ray is parallel to the front's plane";
      return out;
    }
    out.p1_camera = Eigen::Vector3d(q[0], q[1], q[2]);
  }
  if (p.top_crease.enabled) {
    // The window's columns: those holding the front's pixels below PI (a thin front's neighbour has its own
    // top; the growth can leave PI well above the region).
    const TopCreaseParams& t = p.top_crease;
    thread_local cv::Mat columns;
    columns.create(1, mask.cols, CV_8U);
    columns.setTo(cv::Scalar(0));
    for (int x = std::max(0, out.pi.x - t.right_margin_px - t.columns + 1); x <= out.pi.x && x < mask.cols; ++x)
      for (int y = std::max(0, out.pi.y); y < mask.rows && !columns.at<uchar>(0, x); ++y)
        if (mask.at<int>(y, x) == label) columns.at<uchar>(0, x) = 1;
    const TopCrease c = fit_top_crease(points_camera, g, normal, offset, up, out.pi, up.dot(out.p1_camera), columns, t);
    const Eigen::Vector3d v = up_within_plane(up, normal);
    if (c.found && std::fabs(up.dot(v)) > 1e-6) {
      out.top_crease_shift_m = c.height - up.dot(out.p1_camera);
      out.p1_camera += out.top_crease_shift_m / up.dot(v) * v;
    }
  }
  out.p1_base = camera_in_base * out.p1_camera;
  out.found = true;
  return out;
}
}  // namespace

BookFrontResult select_book_front(const SegmentationResult& seg, const cv::Mat& points_camera, const StereoGeometry& g,
                                  const Eigen::Isometry3d& camera_in_base, const ShelfVolume& shelf,
                                  const SelectionParams& p) {
  if (points_camera.type() != CV_32FC3 || points_camera.size() != seg.labels.size())
    throw std::invalid_argument("select_book_front: points must be CV_32FC3 of the label image's size");
  const size_t K = seg.regions.size();
  // Points of every region in the shelf-box frame.
  const Eigen::Isometry3d cam_in_box = shelf.box_in_base.inverse() * camera_in_base;
  // All regions' points in one array, region by region (first[lab] .. first[lab + 1]), raster order within.
  std::vector<size_t> first(K + 2, 0);
  for (int y = 0; y < seg.labels.rows; ++y) {
    const int* l = seg.labels.ptr<int>(y);
    const cv::Vec3f* q = points_camera.ptr<cv::Vec3f>(y);
    for (int x = 0; x < seg.labels.cols; ++x)
      if (l[x] > 0 && size_t(l[x]) <= K && finite_point(q[x])) ++first[size_t(l[x]) + 1];
  }
  for (size_t i = 1; i < first.size(); ++i) first[i] += first[i - 1];
  const Eigen::Matrix3d R = camera_in_base.linear();
  const Eigen::Vector3d rear_n = shelf.box_in_base.linear().col(0);
  const Eigen::Vector3d shelf_n = shelf.box_in_base.linear().col(2);
  const double cos_par = std::cos(p.parallel_tolerance_deg * M_PI / 180.0);
  const double sin_perp = std::sin(p.perpendicular_tolerance_deg * M_PI / 180.0);
  // Regions oriented like a book front are measured where each pixel's viewing ray meets the region's
  // fitted plane, not at the pixel's own noisy stereo point: a book front is 4-15 px wide, and the depth
  // noise of single pixels (several mm, along oblique rays partly across the shelf) made its extents and
  // its column bands' widths up to twice the book's.
  std::vector<char> on_plane(K + 1, 0);
  for (const PlaneRegion& r : seg.regions) {
    const Eigen::Vector3d n = R * r.normal;
    on_plane[size_t(r.label)] = std::fabs(n.dot(rear_n)) >= cos_par && std::fabs(n.dot(shelf_n)) <= sin_perp;
  }
  const auto measured_point = [&](const PlaneRegion& r, int x, int y, const cv::Vec3f& q) -> Eigen::Vector3d {
    const Eigen::Vector3d raw(q[0], q[1], q[2]);
    if (!on_plane[size_t(r.label)]) return raw;
    const Eigen::Vector3d ray((x - g.cx) / g.fx, (y - g.cy) / g.fy, 1.0);
    const double denom = r.normal.dot(ray);
    if (std::fabs(denom) <= 0.05 * ray.norm()) return raw;
    return ray * (r.offset / denom);
  };
  // The pixels of region r whose measured point lies inside the upper-shelf volume, as r.label in
  // `mask` (CV_32S, 0 elsewhere, or only in r's bounding box when bbox_only): the shelf board's front
  // edge and the rear board, coplanar with the fronts, can merge into a front region but lie outside
  // the volume.
  const auto inside_pixels = [&](const PlaneRegion& r, cv::Mat& mask, bool bbox_only) {
    mask.create(seg.labels.size(), CV_32S);
    (bbox_only ? mask(r.bbox) : mask).setTo(cv::Scalar(0));
    for (int y = r.bbox.y; y < r.bbox.y + r.bbox.height; ++y) {
      const int* l = seg.labels.ptr<int>(y);
      const cv::Vec3f* q = points_camera.ptr<cv::Vec3f>(y);
      int* o = mask.ptr<int>(y);
      for (int x = r.bbox.x; x < r.bbox.x + r.bbox.width; ++x) {
        if (l[x] != r.label || !finite_point(q[x])) continue;
        if (inside_box(cam_in_box * measured_point(r, x, y, q[x]), shelf.half_extent)) o[x] = r.label;
      }
    }
  };
  // The large scratch buffers are per thread and keep their capacity across frames (no fresh pages per
  // frame); each is sized and filled per call as before.
  thread_local std::vector<Eigen::Vector3f> box_pts;
  box_pts.resize(first[K + 1]);
  {
    std::vector<size_t> fill(first.begin(), first.end() - 1);
    for (int y = 0; y < seg.labels.rows; ++y) {
      const int* l = seg.labels.ptr<int>(y);
      const cv::Vec3f* q = points_camera.ptr<cv::Vec3f>(y);
      for (int x = 0; x < seg.labels.cols; ++x) {
        const int lab = l[x];
        if (lab <= 0 || size_t(lab) > K || !finite_point(q[x])) continue;
        box_pts[fill[size_t(lab)]++] =
            (cam_in_box * measured_point(seg.regions[size_t(lab - 1)], x, y, q[x])).cast<float>();
      }
    }
  }

  BookFrontResult out;
  int best = 0;
  double best_y = std::numeric_limits<double>::infinity();
  // Depth along the rear-board normal (box x) of every pixel, for splitting wide regions.
  // Computed when the first wide region needs it.
  thread_local cv::Mat rear_depth_buffer;
  cv::Mat rear_depth;
  const auto make_rear_depth = [&]() {
    if (!rear_depth.empty()) return;
    rear_depth_buffer.create(seg.labels.size(), CV_32F);
    rear_depth = rear_depth_buffer;
    rear_depth.setTo(cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
    for (int y = 0; y < seg.labels.rows; ++y) {
      const cv::Vec3f* q = points_camera.ptr<cv::Vec3f>(y);
      float* d = rear_depth.ptr<float>(y);
      for (int x = 0; x < seg.labels.cols; ++x)
        if (std::isfinite(q[x][2])) d[x] = float((cam_in_box * Eigen::Vector3d(q[x][0], q[x][1], q[x][2])).x());
    }
  };
  std::vector<std::pair<int, int>> band_of(K + 1, {-1, -1});
  thread_local std::vector<double> c[3], b1, b2;  // per region: base coordinates, box y and z of its points
  for (const PlaneRegion& r : seg.regions) {
    RegionVerdict v;
    v.label = r.label;
    v.normal_base = R * r.normal;
    v.offset_base = r.offset + v.normal_base.dot(camera_in_base.translation());
    v.centroid_base = camera_in_base * r.centroid;
    const Eigen::Vector3f* pts = box_pts.data() + first[size_t(r.label)];
    const size_t num_pts = first[size_t(r.label) + 1] - first[size_t(r.label)];
    if (num_pts > 0) {
      size_t inside = 0;
      for (size_t j = 0; j < num_pts; ++j) inside += inside_box(pts[j], shelf.half_extent);
      v.inside_fraction = double(inside) / double(num_pts);
      // A front-like region is measured by its part inside the volume (a shelf board's edge merged with
      // the fronts is not part of a book); other regions by all their points.
      const bool inside_only = on_plane[size_t(r.label)] && inside > 0;
      for (int i = 0; i < 3; ++i) c[i].clear();
      b1.clear();
      b2.clear();
      for (size_t j = 0; j < num_pts; ++j) {
        const Eigen::Vector3f& q = pts[j];
        if (inside_only && !inside_box(q, shelf.half_extent)) continue;
        const Eigen::Vector3d qb = shelf.box_in_base * q.cast<double>();
        for (int i = 0; i < 3; ++i) c[i].push_back(qb(i));
        b1.push_back(q(1));
        b2.push_back(q(2));
      }
      for (int i = 0; i < 3; ++i)
        std::tie(v.extent_min_base(i), v.extent_max_base(i)) = quantile_pair(c[i], p.extent_quantile);
      const auto [w0, w1] = quantile_pair(b1, p.extent_quantile);
      const auto [h0, h1] = quantile_pair(b2, p.extent_quantile);
      v.width_m = w1 - w0;
      v.height_m = h1 - h0;
    }
    const double par = std::fabs(v.normal_base.dot(rear_n));
    const double perp = std::fabs(v.normal_base.dot(shelf_n));
    if (r.pixel_count < p.min_pixels) {
      v.reason = "too small: " + std::to_string(r.pixel_count) + " px < " + std::to_string(p.min_pixels);
    } else if (par < cos_par) {
      v.reason = "not parallel to the rear board: " + fmt(std::acos(std::min(1.0, par)) * 180.0 / M_PI, 1) + " deg > " +
                 fmt(p.parallel_tolerance_deg, 1);
    } else if (perp > sin_perp) {
      v.reason = "not perpendicular to the shelf: off by " + fmt(std::asin(std::min(1.0, perp)) * 180.0 / M_PI, 1) +
                 " deg > " + fmt(p.perpendicular_tolerance_deg, 1);
    } else if (v.inside_fraction < p.min_inside_fraction) {
      v.reason = "outside the upper-shelf volume: " + fmt(v.inside_fraction, 2) + " of points inside < " +
                 fmt(p.min_inside_fraction, 2);
    } else if (v.width_m > p.max_width_m && p.split_wide_fronts) {
      // Several coplanar fronts side by side: split into column bands, keep the right-most band that
      // looks like one book front.
      make_rear_depth();
      thread_local cv::Mat inside;
      inside_pixels(r, inside, true);  // only its bounding box is read
      const std::vector<std::pair<int, int>> bands = column_bands(inside, r.label, r.bbox, rear_depth, p);
      double band_best_y = std::numeric_limits<double>::infinity();
      int passed = 0;
      for (const auto& [x0, x1] : bands) {
        std::vector<double> by, bz;
        double sum_y = 0.0;
        for (int y = r.bbox.y; y < r.bbox.y + r.bbox.height; ++y) {
          const int* l = inside.ptr<int>(y);
          const cv::Vec3f* q = points_camera.ptr<cv::Vec3f>(y);
          for (int x = x0; x <= x1; ++x) {
            if (l[x] != r.label) continue;
            const Eigen::Vector3d qc = measured_point(r, x, y, q[x]);
            const Eigen::Vector3d qb = cam_in_box * qc;
            by.push_back(qb.y());
            bz.push_back(qb.z());
            sum_y += (camera_in_base * qc).y();
          }
        }
        v.bands += (v.bands.empty() ? "[" : "; [") + std::to_string(x0) + ", " + std::to_string(x1) + "]";
        if (int(by.size()) < p.min_pixels) {
          v.bands += " " + std::to_string(by.size()) + " px: too small";
          continue;
        }
        const auto [y0, y1] = quantile_pair(by, p.extent_quantile);
        const auto [z0, z1] = quantile_pair(bz, p.extent_quantile);
        const double w = y1 - y0, h = z1 - z0;
        v.bands += " w " + fmt(w) + " h " + fmt(h);
        if (w < p.min_width_m || h < p.min_height_m || h > p.max_height_m) {
          v.bands += ": not a book front";
          continue;
        }
        // Wider than one book: fronts of one height at one depth, which neither the top contour nor the
        // depth separates; the band's upper-right corner is still the right-most one's.
        v.bands += w > p.max_width_m ? ": ok (several fronts of one height)" : ": ok";
        ++passed;
        const double cy = sum_y / double(by.size());
        if (cy < band_best_y) {
          band_best_y = cy;
          band_of[size_t(r.label)] = {x0, x1};
        }
      }
      if (passed == 0) {
        v.reason = "width " + fmt(v.width_m) + " m > " + fmt(p.max_width_m) + " and none of its " +
                   std::to_string(bands.size()) + " column bands is a book front: " + v.bands;
      } else {
        v.candidate = true;
        if (band_best_y < best_y) {
          best_y = band_best_y;
          best = r.label;
        }
      }
    } else if (v.width_m < p.min_width_m || v.width_m > p.max_width_m) {
      v.reason = "width " + fmt(v.width_m) + " m not in [" + fmt(p.min_width_m) + ", " + fmt(p.max_width_m) + "]";
    } else if (v.height_m < p.min_height_m || v.height_m > p.max_height_m) {
      v.reason = "height " + fmt(v.height_m) + " m not in [" + fmt(p.min_height_m) + ", " + fmt(p.max_height_m) + "]";
    } else {
      v.candidate = true;
      if (v.centroid_base.y() < best_y) {
        best_y = v.centroid_base.y();
        best = r.label;
      }
    }
    out.regions.push_back(std::move(v));
  }
  for (auto& v : out.regions)
    if (v.candidate && v.label != best) v.reason = "candidate, not the right-most";
  // The fronts' layer lies on the plane parallel to the rear board (the cart's normal, not the region's:
  // a small region's normal can be 15 deg off, which tilts a plane across the shelf).
  const Eigen::Vector3d rear_cam = R.transpose() * rear_n;
  const Eigen::Vector3d up_cam = R.transpose() * shelf_n;
  if (best == 0) {
    out.failure_reason = seg.regions.empty() ? "no planar region" : "no region passed the book-front tests";
    if (p.layer_disparity_px <= 0.0 || p.layer_without_front_m <= 0.0) return out;
    const double offset = densest_layer_offset(points_camera, cam_in_box, shelf.half_extent, p.layer_without_front_m);
    if (!std::isfinite(offset)) return out;
    const int label = int(K) + 1;  // the layer's pixels in its mask: no region's label
    const FrontLayer layer =
        rightmost_front_on_layer(points_camera, g, rear_cam, offset, cam_in_box, shelf.half_extent, 0, label, p);
    if (layer.top.x < 0) {
      out.failure_reason += ", and the densest layer has no front";
      return out;
    }
    out.failure_reason.clear();
    out.pi = layer.top;
    out.pi_from_layer = true;
    return p1_on_plane(layer.mask, label, rear_cam, layer.offset, up_cam, points_camera, g, camera_in_base, p,
                       std::move(out));
  }
  const PlaneRegion& r = seg.regions[size_t(best - 1)];
  out.selected_label = best;
  double offset = r.offset;
  cv::Mat band_mask, inside_mask;  // the pixels PI is taken from
  const auto corner_of = [&](const cv::Mat& labels) {
    if (p.pi_rule == PiRule::kPaper) return upper_right_corner(labels, best, &out.pi_fallback);
    out.pi_fallback = false;
    return right_column_top(labels, best);
  };
  if (band_of[size_t(best)].first >= 0) {
    // A band of a wider region: PI of the band's pixels; the plane keeps the region's normal and takes
    // the band's own offset (median of n . p), since neighbouring fronts can stand at other depths.
    out.split = true;
    out.band_x0 = band_of[size_t(best)].first;
    out.band_x1 = band_of[size_t(best)].second;
    thread_local cv::Mat band;
    inside_pixels(r, band, false);
    std::vector<double> offs;
    for (int y = r.bbox.y; y < r.bbox.y + r.bbox.height; ++y) {
      const cv::Vec3f* q = points_camera.ptr<cv::Vec3f>(y);
      int* o = band.ptr<int>(y);
      for (int x = r.bbox.x; x < r.bbox.x + r.bbox.width; ++x) {
        if (o[x] != best) continue;
        if (x < out.band_x0 || x > out.band_x1) {
          o[x] = 0;
          continue;
        }
        offs.push_back(r.normal.dot(Eigen::Vector3d(q[x][0], q[x][1], q[x][2])));
      }
    }
    if (!offs.empty()) offset = quantile(offs, 0.5);
    out.pi = corner_of(band);
    band_mask = band;
  } else {
    // PI of the region's pixels inside the upper-shelf volume (all of them when none is: the region
    // passed the volume test with its raw points).
    thread_local cv::Mat inside;
    inside_pixels(r, inside, false);
    inside_mask = cv::countNonZero(inside) > 0 ? inside : seg.labels;
    out.pi = corner_of(inside_mask);
  }
  cv::Mat grow_mask = out.split ? band_mask : inside_mask;
  Eigen::Vector3d normal = r.normal;  // of the plane PI's front lies in (left camera frame)
  // The selected front's points' median offset along the rear board's normal: the plane parallel to the rear
  // board through the front (FrontPlane::kRearBoard) and the layer's start. NaN when none has a point.
  double rear_offset = std::numeric_limits<double>::quiet_NaN();
  if (p.front_plane == FrontPlane::kRearBoard || p.layer_disparity_px > 0.0) {
    std::vector<double> offs;
    for (int y = r.bbox.y; y < r.bbox.y + r.bbox.height; ++y) {
      const int* m = grow_mask.ptr<int>(y);
      const cv::Vec3f* q = points_camera.ptr<cv::Vec3f>(y);
      for (int x = r.bbox.x; x < r.bbox.x + r.bbox.width; ++x)
        if (m[x] == best && finite_point(q[x]))
          offs.push_back(rear_cam.dot(Eigen::Vector3d(q[x][0], q[x][1], q[x][2])));
    }
    if (!offs.empty()) rear_offset = quantile(offs, 0.5);
  }
  if (p.front_plane == FrontPlane::kRearBoard && std::isfinite(rear_offset)) {
    normal = rear_cam;
    offset = rear_offset;
  }
  if (p.layer_disparity_px > 0.0 && std::isfinite(rear_offset)) {
    // The layer through the selected front's pixels.
    const FrontLayer layer =
        rightmost_front_on_layer(points_camera, g, rear_cam, rear_offset, cam_in_box, shelf.half_extent,
                                 std::max(0, out.pi.x - p.top_growth.columns), best, p);
    if (layer.top.x > out.pi.x + p.layer_min_shift_px) {
      out.pi = layer.top;
      out.pi_from_layer = true;
      grow_mask = layer.mask;
      normal = rear_cam;
      offset = layer.offset;
    }
  }
  return p1_on_plane(grow_mask, best, normal, offset, up_cam, points_camera, g, camera_in_base, p, std::move(out));
}

}  // namespace bookgrasp::bws
