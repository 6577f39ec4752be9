#include "services/bws_detector/plane_region.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace bookgrasp::bws {

Plane fit_plane(const PointMoments& m) {
  Plane plane;
  if (m.n < 3.0) return plane;
  const Eigen::Vector3d mean = m.sum / m.n;
  const Eigen::Matrix3d cov = m.sum_outer / m.n - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov);
  const Eigen::Vector3d ev = solver.eigenvalues();
  // Degenerate (collinear or a single point): the two largest spreads must both be non-zero.
  if (!(ev(1) > 1e-12 * std::max(1.0, ev(2)))) return plane;
  Eigen::Vector3d n = solver.eigenvectors().col(0).normalized();
  if (n.dot(mean) > 0.0) n = -n;
  plane.normal = n;
  plane.offset = n.dot(mean);
  plane.valid = true;
  return plane;
}

double rms_distance(const PointMoments& m, const Plane& plane) {
  if (m.n <= 0.0) return 0.0;
  const Eigen::Vector3d& n = plane.normal;
  const double sq = n.dot(m.sum_outer * n) - 2.0 * plane.offset * n.dot(m.sum) + plane.offset * plane.offset * m.n;
  return std::sqrt(std::max(0.0, sq / m.n));
}

cv::Mat image_space_points(const cv::Mat& image) {
  if (image.type() != CV_32F) throw std::invalid_argument("image_space_points: image must be CV_32F");
  cv::Mat pts(image.size(), CV_32FC3);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int y = 0; y < image.rows; ++y) {
    const float* in = image.ptr<float>(y);
    cv::Vec3f* out = pts.ptr<cv::Vec3f>(y);
    for (int x = 0; x < image.cols; ++x) {
      const float v = in[x];
      out[x] = (std::isfinite(v) && v > 0.f) ? cv::Vec3f(float(x), float(y), v) : cv::Vec3f(nan, nan, nan);
    }
  }
  return pts;
}

namespace {

/// One past the last column of the run of `l[x]`'s value that starts at x (the row has W labels).
inline int run_end(const int* l, int x, int W) {
  const int v = l[x];
  int x1 = x + 1;
#if defined(__SSE2__)
  const __m128i vv = _mm_set1_epi32(v);
  for (; x1 + 4 <= W; x1 += 4) {
    const unsigned m =
        unsigned(_mm_movemask_epi8(_mm_cmpeq_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(l + x1)), vv)));
    if (m != 0xffffu) return x1 + __builtin_ctz(~m) / 4;
  }
#endif
  while (x1 < W && l[x1] == v) ++x1;
  return x1;
}

/// Moment sums as PointMoments::add makes them (same products, same order), the six distinct products.
struct Acc {
  int pixels = 0;
  int x0 = std::numeric_limits<int>::max(), y0 = std::numeric_limits<int>::max(), x1 = -1, y1 = -1;
  double n = 0.0, sx = 0.0, sy = 0.0, sz = 0.0, xx = 0.0, xy = 0.0, xz = 0.0, yy = 0.0, yz = 0.0, zz = 0.0;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
  int first = -1;
};

SegmentationResult describe(const cv::Mat& labels, const cv::Mat& points, int min_pixels, bool in_place) {
  if (labels.type() != CV_32S) throw std::invalid_argument("describe_regions: labels must be CV_32S");
  if (points.type() != CV_32FC3 || points.size() != labels.size())
    throw std::invalid_argument("describe_regions: points must be CV_32FC3 of the labels' size");
  // Renumber in raster order of first pixel.
  int max_label = 0;
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    for (int x = 0; x < labels.cols; ++x) max_label = std::max(max_label, l[x]);
  }
  // Per-thread buffers that keep their capacity across calls (no fresh pages per frame).
  thread_local std::vector<Acc> acc;
  thread_local std::vector<int> order, remap;
  acc.assign(size_t(max_label) + 1, Acc());
  // Run by run (maximal horizontal pieces of one label): the pixel count and the bounding box once per
  // run, the sums and the extent pixel by pixel into local copies (the same additions in the same order).
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const cv::Vec3f* p = points.ptr<cv::Vec3f>(y);
    for (int x = 0; x < labels.cols;) {
      const int lab = l[x];
      const int x1 = run_end(l, x, labels.cols);
      if (lab > 0) {
        Acc& a = acc[size_t(lab)];
        if (a.first < 0) a.first = y * labels.cols + x;
        a.pixels += x1 - x;
        a.x0 = std::min(a.x0, x);
        a.x1 = std::max(a.x1, x1 - 1);
        a.y0 = std::min(a.y0, y);
        a.y1 = std::max(a.y1, y);
        double n = a.n, sx = a.sx, sy = a.sy, sz = a.sz, xx = a.xx, xy = a.xy, xz = a.xz, yy = a.yy, yz = a.yz,
               zz = a.zz;
        double lo0 = a.lo[0], lo1 = a.lo[1], lo2 = a.lo[2], hi0 = a.hi[0], hi1 = a.hi[1], hi2 = a.hi[2];
        for (int i = x; i < x1; ++i) {
          const cv::Vec3f& q = p[i];
          if (!(std::isfinite(q[0]) && std::isfinite(q[1]) && std::isfinite(q[2]))) continue;
          const double v0 = q[0], v1 = q[1], v2 = q[2];
          n += 1.0;
          sx += v0;
          sy += v1;
          sz += v2;
          xx += v0 * v0;
          xy += v0 * v1;
          xz += v0 * v2;
          yy += v1 * v1;
          yz += v1 * v2;
          zz += v2 * v2;
          lo0 = std::min(lo0, v0);  // as cwiseMin / cwiseMax of finite values
          lo1 = std::min(lo1, v1);
          lo2 = std::min(lo2, v2);
          hi0 = std::max(hi0, v0);
          hi1 = std::max(hi1, v1);
          hi2 = std::max(hi2, v2);
        }
        a.n = n;
        a.sx = sx;
        a.sy = sy;
        a.sz = sz;
        a.xx = xx;
        a.xy = xy;
        a.xz = xz;
        a.yy = yy;
        a.yz = yz;
        a.zz = zz;
        a.lo = Eigen::Vector3d(lo0, lo1, lo2);
        a.hi = Eigen::Vector3d(hi0, hi1, hi2);
      }
      x = x1;
    }
  }
  order.clear();
  for (int lab = 1; lab <= max_label; ++lab)
    if (acc[size_t(lab)].pixels > 0) order.push_back(lab);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return acc[size_t(a)].first < acc[size_t(b)].first; });

  SegmentationResult out;
  remap.assign(size_t(max_label) + 1, 0);
  for (int lab : order) {
    const Acc& a = acc[size_t(lab)];
    if (a.pixels < min_pixels) continue;
    PointMoments m;
    m.n = a.n;
    m.sum = Eigen::Vector3d(a.sx, a.sy, a.sz);
    m.sum_outer << a.xx, a.xy, a.xz, a.xy, a.yy, a.yz, a.xz, a.yz, a.zz;
    const Plane plane = fit_plane(m);
    if (!plane.valid) continue;
    PlaneRegion r;
    r.label = int(out.regions.size()) + 1;
    r.pixel_count = a.pixels;
    r.point_count = int(m.n);
    r.bbox = cv::Rect(a.x0, a.y0, a.x1 - a.x0 + 1, a.y1 - a.y0 + 1);
    r.normal = plane.normal;
    r.offset = plane.offset;
    r.centroid = m.sum / m.n;
    r.rms_residual = rms_distance(m, plane);
    r.extent_min = a.lo;
    r.extent_max = a.hi;
    remap[size_t(lab)] = r.label;
    out.regions.push_back(r);
  }
  out.labels = in_place ? labels : cv::Mat(labels.size(), CV_32S);
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    int* o = out.labels.ptr<int>(y);
    for (int x = 0; x < labels.cols;) {  // run by run (in place: a run is read before it is written)
      const int lab = l[x];
      const int x1 = run_end(l, x, labels.cols);
      std::fill(o + x, o + x1, lab > 0 ? remap[size_t(lab)] : 0);
      x = x1;
    }
  }
  return out;
}

}  // namespace

SegmentationResult describe_regions(const cv::Mat& labels, const cv::Mat& points, int min_pixels) {
  return describe(labels, points, min_pixels, false);
}

SegmentationResult describe_regions_in_place(cv::Mat& labels, const cv::Mat& points, int min_pixels) {
  return describe(labels, points, min_pixels, true);
}

}  // namespace bookgrasp::bws
