#pragma once
/// @file
/// Moment sums of a point set in ten doubles, added point by point exactly as PointMoments::add does
/// (same products, same order), and an SSE2 form of the same additions (same bits). Internal to
/// bws_core: the GoD moments and describe_regions share it.

#include <cmath>

#include <opencv2/core.hpp>

#include "services/bws_detector/plane_region.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace bookgrasp::bws {

/// Sums of a point set in double: count, sums, the six distinct products (80 bytes).
struct PointSums {
  /// Count, sums of the coordinates, sums of their products.
  double n = 0.0, x = 0.0, y = 0.0, z = 0.0, xx = 0.0, xy = 0.0, xz = 0.0, yy = 0.0, yz = 0.0, zz = 0.0;
  /// Adds one point (PointMoments::add's operations).
  void add(double px, double py, double pz) {
    n += 1.0;
    x += px;
    y += py;
    z += pz;
    xx += px * px;
    xy += px * py;
    xz += px * pz;
    yy += py * py;
    yz += py * pz;
    zz += pz * pz;
  }
  /// Adds every point of another set (PointMoments::add(const PointMoments&)'s operations).
  void add(const PointSums& o) {
    n += o.n;
    x += o.x;
    y += o.y;
    z += o.z;
    xx += o.xx;
    xy += o.xy;
    xz += o.xz;
    yy += o.yy;
    yz += o.yz;
    zz += o.zz;
  }
  /// The same sums as PointMoments.
  PointMoments moments() const {
    PointMoments m;
    m.n = n;
    m.sum = Eigen::Vector3d(x, y, z);
    m.sum_outer << xx, xy, xz, xy, yy, yz, xz, yz, zz;
    return m;
  }
};

static_assert(sizeof(PointSums) == 10 * sizeof(double), "PointSums: ten contiguous doubles");

/// rms_distance(s.moments(), plane) without the matrices (same bits).
double rms_distance(const PointSums& s, const Plane& plane);

/// True when the three coordinates of `q` are finite.
inline bool finite3(const cv::Vec3f& q) {
  return std::isfinite(q[0]) && std::isfinite(q[1]) && std::isfinite(q[2]);
}

#if defined(__SSE2__)
/// PointSums::add of (px, py, pz) on five pairs of lanes [n, x] [y, z] [xx, xy] [xz, yy] [yz, zz]: every
/// lane makes the scalar code's operation (IEEE double, no fused multiply-add), so the sums are the same bits.
struct PackedPointSums {
  /// The five pairs of lanes.
  __m128d nx, yz, xx_xy, xz_yy, yz_zz;
  /// Loads `s`.
  explicit PackedPointSums(const PointSums& s)
      : nx(_mm_loadu_pd(&s.n)),
        yz(_mm_loadu_pd(&s.y)),
        xx_xy(_mm_loadu_pd(&s.xx)),
        xz_yy(_mm_loadu_pd(&s.xz)),
        yz_zz(_mm_loadu_pd(&s.yz)) {}
  /// Stores into `s`.
  void store(PointSums& s) const {
    _mm_storeu_pd(&s.n, nx);
    _mm_storeu_pd(&s.y, yz);
    _mm_storeu_pd(&s.xx, xx_xy);
    _mm_storeu_pd(&s.xz, xz_yy);
    _mm_storeu_pd(&s.yz, yz_zz);
  }
  /// Adds the point: one_x = [1, px], pyz = [py, pz].
  void add(__m128d one_x, __m128d pyz) {
    const __m128d px2 = _mm_unpackhi_pd(one_x, one_x);  // [px, px]
    const __m128d pxy = _mm_shuffle_pd(one_x, pyz, 1);  // [px, py]
    const __m128d pzy = _mm_shuffle_pd(pyz, pyz, 1);    // [pz, py]
    const __m128d pz2 = _mm_unpackhi_pd(pyz, pyz);      // [pz, pz]
    nx = _mm_add_pd(nx, one_x);
    yz = _mm_add_pd(yz, pyz);
    xx_xy = _mm_add_pd(xx_xy, _mm_mul_pd(px2, pxy));  // [px*px, px*py]
    xz_yy = _mm_add_pd(xz_yy, _mm_mul_pd(pxy, pzy));  // [px*pz, py*py]
    yz_zz = _mm_add_pd(yz_zz, _mm_mul_pd(pyz, pz2));  // [py*pz, pz*pz]
  }
};

/// Loads the point `q` as doubles [x, y] and [z, z]; false (and nothing loaded) if a coordinate is not
/// finite (exponent bits all ones: the same test as finite3). Reads exactly the 12 bytes of `q`.
inline bool load_finite_point(const cv::Vec3f& q, __m128d* xy, __m128d* zz) {
  const __m128 fxy = _mm_loadl_pi(_mm_setzero_ps(), reinterpret_cast<const __m64*>(&q[0]));  // [x, y, 0, 0]
  const __m128 fz = _mm_load_ss(&q[2]);                                                      // [z, 0, 0, 0]
  const __m128i exp_mask = _mm_set1_epi32(0x7f800000);
  const __m128i e = _mm_and_si128(_mm_castps_si128(_mm_movelh_ps(fxy, fz)), exp_mask);  // [x, y, z, 0]
  if (_mm_movemask_epi8(_mm_cmpeq_epi32(e, exp_mask)) != 0) return false;
  *xy = _mm_cvtps_pd(fxy);
  const __m128d z = _mm_cvtss_sd(_mm_setzero_pd(), fz);
  *zz = _mm_unpacklo_pd(z, z);
  return true;
}
#endif

/// Adds the finite points q[x0..x1] to `s` (PointSums::add, in order).
inline void add_point_run(PointSums& s, const cv::Vec3f* q, int x0, int x1) {
#if defined(__SSE2__)
  PackedPointSums p(s);
  const __m128d one = _mm_set_sd(1.0);
  for (int x = x0; x <= x1; ++x) {
    __m128d xy, zz;
    if (!load_finite_point(q[x], &xy, &zz)) continue;
    p.add(_mm_unpacklo_pd(one, xy), _mm_shuffle_pd(xy, zz, 1));  // [1, x], [y, z]
  }
  p.store(s);
#else
  for (int x = x0; x <= x1; ++x)
    if (finite3(q[x])) s.add(q[x][0], q[x][1], q[x][2]);
#endif
}

}  // namespace bookgrasp::bws
