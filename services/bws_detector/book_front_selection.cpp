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

namespace {
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
  const auto point_ok = [](const cv::Vec3f& q) {
    return std::isfinite(q[0]) && std::isfinite(q[1]) && std::isfinite(q[2]);
  };
  for (int y = 0; y < seg.labels.rows; ++y) {
    const int* l = seg.labels.ptr<int>(y);
    const cv::Vec3f* q = points_camera.ptr<cv::Vec3f>(y);
    for (int x = 0; x < seg.labels.cols; ++x)
      if (l[x] > 0 && size_t(l[x]) <= K && point_ok(q[x])) ++first[size_t(l[x]) + 1];
  }
  for (size_t i = 1; i < first.size(); ++i) first[i] += first[i - 1];
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
        if (lab <= 0 || size_t(lab) > K || !point_ok(q[x])) continue;
        box_pts[fill[size_t(lab)]++] = (cam_in_box * Eigen::Vector3d(q[x][0], q[x][1], q[x][2])).cast<float>();
      }
    }
  }
  const Eigen::Matrix3d R = camera_in_base.linear();
  const Eigen::Vector3d rear_n = shelf.box_in_base.linear().col(0);
  const Eigen::Vector3d shelf_n = shelf.box_in_base.linear().col(2);
  const double cos_par = std::cos(p.parallel_tolerance_deg * M_PI / 180.0);
  const double sin_perp = std::sin(p.perpendicular_tolerance_deg * M_PI / 180.0);

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
      for (int i = 0; i < 3; ++i) c[i].resize(num_pts);
      b1.resize(num_pts);
      b2.resize(num_pts);
      int inside = 0;
      for (size_t j = 0; j < num_pts; ++j) {
        const Eigen::Vector3f& q = pts[j];
        const Eigen::Vector3d qb = shelf.box_in_base * q.cast<double>();
        for (int i = 0; i < 3; ++i) c[i][j] = qb(i);
        b1[j] = q(1);
        b2[j] = q(2);
        if (std::fabs(q.x()) <= shelf.half_extent.x() && std::fabs(q.y()) <= shelf.half_extent.y() &&
            std::fabs(q.z()) <= shelf.half_extent.z())
          ++inside;
      }
      v.inside_fraction = double(inside) / double(num_pts);
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
      const std::vector<std::pair<int, int>> bands = column_bands(seg.labels, r.label, r.bbox, rear_depth, p);
      double band_best_y = std::numeric_limits<double>::infinity();
      int passed = 0;
      for (const auto& [x0, x1] : bands) {
        std::vector<double> by, bz;
        double sum_y = 0.0;
        for (int y = r.bbox.y; y < r.bbox.y + r.bbox.height; ++y) {
          const int* l = seg.labels.ptr<int>(y);
          const cv::Vec3f* q = points_camera.ptr<cv::Vec3f>(y);
          for (int x = x0; x <= x1; ++x) {
            if (l[x] != r.label || !std::isfinite(q[x][2])) continue;
            const Eigen::Vector3d qc(q[x][0], q[x][1], q[x][2]);
            const Eigen::Vector3d qb = cam_in_box * qc;
            by.push_back(qb.y());
            bz.push_back(qb.z());
            sum_y += (camera_in_base * qc).y();
          }
        }
        if (int(by.size()) < p.min_pixels) continue;
        const auto [y0, y1] = quantile_pair(by, p.extent_quantile);
        const auto [z0, z1] = quantile_pair(bz, p.extent_quantile);
        const double w = y1 - y0, h = z1 - z0;
        if (w < p.min_width_m || w > p.max_width_m || h < p.min_height_m || h > p.max_height_m) continue;
        ++passed;
        const double cy = sum_y / double(by.size());
        if (cy < band_best_y) {
          band_best_y = cy;
          band_of[size_t(r.label)] = {x0, x1};
        }
      }
      if (passed == 0) {
        v.reason = "width " + fmt(v.width_m) + " m > " + fmt(p.max_width_m) + " and none of its " +
                   std::to_string(bands.size()) + " column bands is a book front";
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
  if (best == 0) {
    out.failure_reason = seg.regions.empty() ? "no planar region" : "no region passed the book-front tests";
    return out;
  }
  const PlaneRegion& r = seg.regions[size_t(best - 1)];
  out.selected_label = best;
  double offset = r.offset;
  if (band_of[size_t(best)].first >= 0) {
    // A band of a wider region: PI of the band's pixels; the plane keeps the region's normal and takes
    // the band's own offset (median of n . p), since neighbouring fronts can stand at other depths.
    out.split = true;
    out.band_x0 = band_of[size_t(best)].first;
    out.band_x1 = band_of[size_t(best)].second;
    thread_local cv::Mat band;
    band.create(seg.labels.size(), CV_32S);
    band.setTo(cv::Scalar(0));
    std::vector<double> offs;
    for (int y = r.bbox.y; y < r.bbox.y + r.bbox.height; ++y) {
      const int* l = seg.labels.ptr<int>(y);
      const cv::Vec3f* q = points_camera.ptr<cv::Vec3f>(y);
      int* o = band.ptr<int>(y);
      for (int x = out.band_x0; x <= out.band_x1; ++x) {
        if (l[x] != best) continue;
        o[x] = best;
        if (std::isfinite(q[x][2])) offs.push_back(r.normal.dot(Eigen::Vector3d(q[x][0], q[x][1], q[x][2])));
      }
    }
    if (!offs.empty()) offset = quantile(offs, 0.5);
    out.pi = upper_right_corner(band, best, &out.pi_fallback);
  } else {
    out.pi = upper_right_corner(seg.labels, best, &out.pi_fallback);
  }
  const Eigen::Vector3d ray((out.pi.x - g.cx) / g.fx, (out.pi.y - g.cy) / g.fy, 1.0);
  const double denom = r.normal.dot(ray);
  if (std::fabs(denom) > 0.05 * ray.norm()) {
    out.p1_camera = ray * (offset / denom);
  } else {
    const cv::Vec3f q = points_camera.at<cv::Vec3f>(out.pi);
    if (!std::isfinite(q[2])) {
      out.failure_reason = "PI has no 3D point and its ray is parallel to the region's plane";
      return out;
    }
    out.p1_camera = Eigen::Vector3d(q[0], q[1], q[2]);
  }
  out.p1_base = camera_in_base * out.p1_camera;
  out.found = true;
  return out;
}

}  // namespace bookgrasp::bws
