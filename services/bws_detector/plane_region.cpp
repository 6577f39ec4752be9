#include "services/bws_detector/plane_region.h"

#include "services/bws_detector/point_sums.h"

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

namespace {

/// Root-mean-square distance to `plane` of a point set given by its count n, sums s0..s2 and sums of
/// products m(i, j): the operations in the order Eigen evaluated n . (M n) - 2 o n . s + o^2 n on this
/// target (rows 0 and 1 of M n from the left, row 2 from the right), written out so that PointSums
/// need not be turned into matrices and both forms give the same bits.
template <typename M>
double rms_distance_of(double n, double s0, double s1, double s2, const M& m, const Plane& plane) {
  if (n <= 0.0) return 0.0;
  const double n0 = plane.normal[0], n1 = plane.normal[1], n2 = plane.normal[2], o = plane.offset;
  const double r0 = (m(0, 0) * n0 + m(0, 1) * n1) + m(0, 2) * n2;
  const double r1 = (m(1, 0) * n0 + m(1, 1) * n1) + m(1, 2) * n2;
  const double r2 = (m(2, 2) * n2 + m(2, 1) * n1) + m(2, 0) * n0;
  const double q = (r0 * n0 + r1 * n1) + r2 * n2;
  const double l = (s0 * n0 + s1 * n1) + s2 * n2;
  const double sq = q - 2.0 * o * l + o * o * n;
  return std::sqrt(std::max(0.0, sq / n));
}

}  // namespace

double rms_distance(const PointMoments& m, const Plane& plane) {
  return rms_distance_of(m.n, m.sum[0], m.sum[1], m.sum[2], m.sum_outer, plane);
}

double rms_distance(const PointSums& s, const Plane& plane) {
  const double p[3][3] = {{s.xx, s.xy, s.xz}, {s.xy, s.yy, s.yz}, {s.xz, s.yz, s.zz}};
  return rms_distance_of(
      s.n, s.x, s.y, s.z, [&](int i, int j) { return p[i][j]; }, plane);
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

/// Per label: pixel count, bounding box, moment sums (PointSums: PointMoments::add's operations), extent.
struct Acc {
  int pixels = 0;
  int x0 = std::numeric_limits<int>::max(), y0 = std::numeric_limits<int>::max(), x1 = -1, y1 = -1;
  PointSums sums;
  double lo[3] = {kInf, kInf, kInf};
  double hi[3] = {-kInf, -kInf, -kInf};
  int first = -1;
  static constexpr double kInf = std::numeric_limits<double>::infinity();
};

/// Adds the finite points p[x..x1-1] to `a`'s sums (in order) and extent (as cwiseMin / cwiseMax).
inline void add_run(Acc& a, const cv::Vec3f* p, int x, int x1) {
#if defined(__SSE2__)
  // Lanes: the sums as PackedPointSums; the extent in [x, y] and [y, z] pairs. std::min(lo, v) is
  // (v < lo ? v : lo) = _mm_min_pd(v, lo); std::max(hi, v) is (hi < v ? v : hi) = _mm_max_pd(v, hi).
  PackedPointSums s(a.sums);
  __m128d lo_xy = _mm_loadu_pd(a.lo), lo_yz = _mm_loadu_pd(a.lo + 1);
  __m128d hi_xy = _mm_loadu_pd(a.hi), hi_yz = _mm_loadu_pd(a.hi + 1);
  const __m128d one = _mm_set_sd(1.0);
  for (int i = x; i < x1; ++i) {
    __m128d pxy, zz;
    if (!load_finite_point(p[i], &pxy, &zz)) continue;
    const __m128d pyz = _mm_shuffle_pd(pxy, zz, 1);  // [y, z]
    s.add(_mm_unpacklo_pd(one, pxy), pyz);           // [1, x], [y, z]
    lo_xy = _mm_min_pd(pxy, lo_xy);
    hi_xy = _mm_max_pd(pxy, hi_xy);
    lo_yz = _mm_min_pd(pyz, lo_yz);
    hi_yz = _mm_max_pd(pyz, hi_yz);
  }
  s.store(a.sums);
  _mm_storeu_pd(a.lo, lo_xy);
  _mm_storeh_pd(a.lo + 2, lo_yz);
  _mm_storeu_pd(a.hi, hi_xy);
  _mm_storeh_pd(a.hi + 2, hi_yz);
#else
  PointSums s = a.sums;
  for (int i = x; i < x1; ++i) {
    const cv::Vec3f& q = p[i];
    if (!finite3(q)) continue;
    const double v[3] = {q[0], q[1], q[2]};
    s.add(v[0], v[1], v[2]);
    for (int k = 0; k < 3; ++k) {
      a.lo[k] = std::min(a.lo[k], v[k]);  // as cwiseMin / cwiseMax of finite values
      a.hi[k] = std::max(a.hi[k], v[k]);
    }
  }
  a.sums = s;
#endif
}

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
        add_run(a, p, x, x1);
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
    const PointMoments m = a.sums.moments();
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
    r.extent_min = Eigen::Vector3d(a.lo[0], a.lo[1], a.lo[2]);
    r.extent_max = Eigen::Vector3d(a.hi[0], a.hi[1], a.hi[2]);
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
