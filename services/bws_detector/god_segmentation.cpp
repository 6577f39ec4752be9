#include "services/bws_detector/god_segmentation.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include <Eigen/Eigenvalues>

#include "common/config.h"
#include "services/bws_detector/point_sums.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__SSE2__) && defined(__GNUC__)
// The voting and the bins also have AVX2 forms, compiled for that instruction set with the `target`
// attribute and chosen at run time (`has_avx2`): the build itself targets baseline x86-64.
#include <immintrin.h>
#define BOOKGRASP_GOD_AVX2 1
#define GOD_TARGET_AVX2 __attribute__((target("avx2")))
#endif

namespace bookgrasp::bws {

namespace {

/// Direction of (dx, dy) in degrees, (0, 360]; dx, dy not both zero.
/// atan on [0, 1] by a degree-9 odd polynomial (max error ~1e-5 rad).
inline float direction_deg(float dx, float dy) {
  const float ax = std::fabs(dx), ay = std::fabs(dy);
  const float mn = std::min(ax, ay), mx = std::max(ax, ay);
  const float t = mn / mx;
  const float s = t * t;
  float a = t * (0.9998660f + s * (-0.3302995f + s * (0.1801410f + s * (-0.0851330f + s * 0.0208351f))));
  a *= 57.295779513f;  // degrees, [0, 45]
  if (ay > ax) a = 90.f - a;
  if (dx < 0.f) a = 180.f - a;
  if (dy < 0.f) a = -a;
  if (a <= 0.f) a += 360.f;
  return a;
}

inline bool valid_value(float v) {
  return std::isfinite(v) && v > 0.f;
}

struct UnionFind {
  std::vector<int> parent;
  UnionFind() = default;
  explicit UnionFind(size_t n) { reset(n); }
  /// Singletons 0..n-1 (keeps the vector's capacity).
  void reset(size_t n) {
    parent.resize(n);
    std::iota(parent.begin(), parent.end(), 0);
  }
  int find(int a) {
    while (parent[size_t(a)] != a) {
      parent[size_t(a)] = parent[size_t(parent[size_t(a)])];
      a = parent[size_t(a)];
    }
    return a;
  }
  /// Joins the sets; the smaller root index becomes the root (deterministic).
  int unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a == b) return a;
    if (b < a) std::swap(a, b);
    parent[size_t(b)] = a;
    return a;
  }
};

/// Adds the merge-space points (x, y, v[x]) of the valid pixels x0..x1 of row y to `s` (PointSums::add, in order).
inline void add_image_run(PointSums& s, const float* v, int x0, int x1, int y) {
#if defined(__SSE2__)
  PackedPointSums p(s);
  for (int x = x0; x <= x1; ++x)
    if (valid_value(v[x])) p.add(_mm_set_pd(double(x), 1.0), _mm_set_pd(double(v[x]), double(y)));
  p.store(s);
#else
  for (int x = x0; x <= x1; ++x)
    if (valid_value(v[x])) s.add(double(x), double(y), double(v[x]));
#endif
}

/// add_image_run with the coordinate sums added per run: n, x, y, xx, xy and yy of pixel coordinates are
/// integers, and a double adds integers below 2^53 without rounding, in any order. So when every such
/// sum of the image stays below 2^53 (`exact_coordinate_sums`), their run totals give the bits of the
/// pixel-by-pixel sums; only the sums with the value (z, xz, yz, zz) are added pixel by pixel, in order,
/// with the scalar code's operations.
inline void add_image_run_exact(PointSums& s, const float* v, int x0, int x1, int y) {
  int64_t n = 0, sx = 0, sxx = 0;
#if defined(__SSE2__)
  __m128d z_xz = _mm_set_pd(s.xz, s.z), yz_zz = _mm_loadu_pd(&s.yz);
  const __m128d vy = _mm_set_sd(double(y));
  for (int x = x0; x <= x1; ++x) {
    if (!valid_value(v[x])) continue;
    ++n;
    sx += x;
    sxx += int64_t(x) * x;
    const __m128d z2 = _mm_set1_pd(double(v[x]));                         // [z, z]
    z_xz = _mm_add_pd(z_xz, _mm_mul_pd(_mm_set_pd(double(x), 1.0), z2));  // [1*z, x*z]
    yz_zz = _mm_add_pd(yz_zz, _mm_mul_pd(_mm_unpacklo_pd(vy, z2), z2));   // [y*z, z*z]
  }
  _mm_storel_pd(&s.z, z_xz);
  _mm_storeh_pd(&s.xz, z_xz);
  _mm_storeu_pd(&s.yz, yz_zz);
#else
  const double py = double(y);
  for (int x = x0; x <= x1; ++x) {
    if (!valid_value(v[x])) continue;
    ++n;
    sx += x;
    sxx += int64_t(x) * x;
    const double pz = double(v[x]);
    s.z += pz;
    s.xz += double(x) * pz;
    s.yz += py * pz;
    s.zz += pz * pz;
  }
#endif
  s.n += double(n);
  s.x += double(sx);
  s.y += double(int64_t(y) * n);
  s.xx += double(sxx);
  s.xy += double(int64_t(y) * sx);
  s.yy += double(int64_t(y) * y * n);
}

/// True when every coordinate sum add_image_run_exact makes (of at most W * H pixels, coordinates below
/// max(W, H)) stays below 2^53.
inline bool exact_coordinate_sums(int W, int H) {
  const double m = double(std::max(W, H));
  return double(W) * double(H) * m * m < 9007199254740992.0;  // 2^53
}

/// Eigen's closed-form 3x3 symmetric eigensolver (SelfAdjointEigenSolver::computeDirect) cut to what the
/// merge's plane uses: the eigenvalues, and on request the eigenvector of the smallest one. The same steps
/// through Eigen's own computeRoots and extract_kernel, so the same bits; the eigenvectors of the two
/// larger eigenvalues are not made unless the smallest one's comes from them.
class DirectEigen {
 public:
  /// Eigenvalues of `mat` (its lower triangle), ascending, as computeDirect gives them.
  explicit DirectEigen(const Eigen::Matrix3d& mat) {
    const double shift = mat.trace() / 3.0;
    scaled_ = mat.template selfadjointView<Eigen::Lower>();
    scaled_.diagonal().array() -= shift;
    const double scale = scaled_.cwiseAbs().maxCoeff();
    if (scale > 0) scaled_ /= scale;
    Direct::computeRoots(scaled_, scaled_values_);
    eigenvalues = scaled_values_ * scale;
    eigenvalues.array() += shift;
  }
  /// computeDirect's eigenvectors().col(0).
  Eigen::Vector3d smallest_eigenvector() const {
    const Eigen::Vector3d& ev = scaled_values_;
    const double eps = Eigen::NumTraits<double>::epsilon();
    if ((ev(2) - ev(0)) <= eps) return Eigen::Vector3d::UnitX();
    double d0 = ev(2) - ev(1);
    const double d1 = ev(1) - ev(0);
    Eigen::Matrix3d tmp = scaled_;
    Eigen::Vector3d col_k, col_l;
    if (!(d0 > d1)) {  // k = 0: column 0 is the first kernel
      tmp.diagonal().array() -= ev(0);
      Direct::extract_kernel(tmp, col_k, col_l);
      return col_k;
    }
    d0 = d1;  // k = 2, l = 0: column 0 is the second one
    tmp.diagonal().array() -= ev(2);
    Direct::extract_kernel(tmp, col_k, col_l);
    if (d0 <= 2 * eps * d1) {
      col_l -= col_k.dot(col_l) * col_l;
      col_l.normalize();
    } else {
      tmp = scaled_;
      tmp.diagonal().array() -= ev(0);
      Eigen::Vector3d dummy;
      Direct::extract_kernel(tmp, col_l, dummy);
    }
    return col_l;
  }
  /// Ascending eigenvalues.
  Eigen::Vector3d eigenvalues;

 private:
  using Direct =
      Eigen::internal::direct_selfadjoint_eigenvalues<Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>, 3, false>;
  Eigen::Matrix3d scaled_;
  Eigen::Vector3d scaled_values_;
};

/// The merge's plane of a segment: fit_plane(s.moments()) with the covariance's eigenvectors from
/// Eigen's closed-form 3x3 solver (analytic eigenvalues, eigenvectors from cross products of rows)
/// instead of its iterative one: ~5x cheaper; the normal can differ from fit_plane's in the last bits.
/// Near-degenerate sets (second eigenvalue near the degeneracy threshold) and ill-conditioned ones
/// (two smallest eigenvalues close, where the closed form loses accuracy) use fit_plane itself.
/// Only the merge and growth use it; the output regions are described with fit_plane.
Plane fit_plane_closed_form(const PointSums& s) {
  Plane plane;
  if (s.n < 3.0) return plane;
  const Eigen::Vector3d mean = Eigen::Vector3d(s.x, s.y, s.z) / s.n;
  Eigen::Matrix3d so;
  so << s.xx, s.xy, s.xz, s.xy, s.yy, s.yz, s.xz, s.yz, s.zz;
  const Eigen::Matrix3d cov = so / s.n - mean * mean.transpose();
  const DirectEigen solver(cov);
  const Eigen::Vector3d& ev = solver.eigenvalues;
  const double scale = std::max(1.0, ev(2));
  if (!ev.allFinite() || !(ev(1) > 1e-9 * scale) || !(ev(1) - ev(0) > 1e-6 * ev(2))) return fit_plane(s.moments());
  Eigen::Vector3d n = solver.smallest_eigenvector().normalized();
  if (!n.allFinite()) return fit_plane(s.moments());
  if (n.dot(mean) > 0.0) n = -n;
  plane.normal = n;
  plane.offset = n.dot(mean);
  plane.valid = true;
  return plane;
}

/// One stable counting-sort pass of edges (lo << 32 | hi, 1 <= lo, hi <= count) from `in` to `out` by lo
/// (`by_lo`) or by hi. `start` is scratch.
void counting_pass(const std::vector<uint64_t>& in, std::vector<uint64_t>& out, int count, bool by_lo,
                   std::vector<int>& start) {
  const int shift = by_lo ? 32 : 0;
  start.assign(size_t(count) + 2, 0);
  for (const uint64_t e : in) ++start[size_t((e >> shift) & 0xffffffffu) + 1];
  for (size_t i = 1; i < start.size(); ++i) start[i] += start[i - 1];
  out.resize(in.size());
  for (const uint64_t e : in) out[size_t(start[size_t((e >> shift) & 0xffffffffu)]++)] = e;
}

/// Sorts edges (lo << 32 | hi, 1 <= lo, hi <= count) by (lo, hi) and removes repeated ones, in O(E + count)
/// by two counting-sort passes (hi, then lo). The sorted order makes the merge candidates come out sorted
/// by (a, b), which their radix sort by distance keeps (sort_candidates).
void sort_unique_edges(std::vector<uint64_t>& edges, int count, std::vector<uint64_t>& tmp, std::vector<int>& start) {
  counting_pass(edges, tmp, count, false, start);
  counting_pass(tmp, edges, count, true, start);
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
}

/// A merge candidate: distance d >= +0 (its IEEE bits, which order as d does for non-negative doubles) and
/// the pair (a << 32 | b, a < b). Sorted by (d_bits, ab) = by (d, a, b).
struct Candidate {
  uint64_t d_bits;
  uint64_t ab;
};

/// Sorts candidates that are sorted by `ab` into (d_bits, ab) order: a stable LSD radix sort on d_bits in
/// 11-bit digits, skipping the digits every candidate shares. `tmp` and `hist` are scratch.
void sort_candidates(std::vector<Candidate>& c, std::vector<Candidate>& tmp, std::vector<uint32_t>& hist) {
  constexpr int kBits = 11, kDigits = 6;
  constexpr size_t kBuckets = size_t(1) << kBits;
  constexpr uint64_t kMask = kBuckets - 1;
  const size_t n = c.size();
  if (n < 2) return;
  hist.assign(kBuckets * kDigits, 0);
  for (const Candidate& e : c)
    for (int k = 0; k < kDigits; ++k) ++hist[size_t(k) * kBuckets + size_t((e.d_bits >> (k * kBits)) & kMask)];
  tmp.resize(n);
  for (int k = 0; k < kDigits; ++k) {
    uint32_t* h = hist.data() + size_t(k) * kBuckets;
    const int shift = k * kBits;
    if (h[(c[0].d_bits >> shift) & kMask] == n) continue;  // one digit value: the pass would not move anything
    uint32_t sum = 0;
    for (size_t i = 0; i < kBuckets; ++i) {
      const uint32_t v = h[i];
      h[i] = sum;
      sum += v;
    }
    for (const Candidate& e : c) tmp[h[(e.d_bits >> shift) & kMask]++] = e;
    c.swap(tmp);
  }
}

#if defined(BOOKGRASP_GOD_AVX2)
/// True when the CPU runs AVX2 (checked once).
bool has_avx2() {
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2;
}

/// valid_value of eight floats as a lane mask (0 < v < inf).
GOD_TARGET_AVX2 inline __m256 valid8(__m256 v, __m256 zero, __m256 inf) {
  return _mm256_and_ps(_mm256_cmp_ps(v, zero, _CMP_GT_OQ), _mm256_cmp_ps(v, inf, _CMP_LT_OQ));
}

/// god_bins_of_image's four-pixel SSE2 step on eight pixels (AVX, the same single-precision operations
/// per lane; the AVX2 target has no fused multiply-add, so the same bits) for the columns x, x + 8, ...
/// of one row while x + 8 <= x_end. Returns the first column not done.
GOD_TARGET_AVX2 int god_bins_row_avx2(const float* up, const float* mid, const float* dn, uint8_t* b, int x, int x_end,
                                      int s, float flat, float jump, float w, int B) {
  const __m256 zero = _mm256_setzero_ps(), inf = _mm256_set1_ps(std::numeric_limits<float>::infinity());
  const __m256 vflat = _mm256_set1_ps(flat), vjump = _mm256_set1_ps(jump), vw = _mm256_set1_ps(w);
  const __m256 sign = _mm256_set1_ps(-0.f), half = _mm256_set1_ps(0.5f);
  const __m256i vB = _mm256_set1_epi32(B), vBm1 = _mm256_set1_epi32(B - 1), v255 = _mm256_set1_epi32(255);
  for (; x + 8 <= x_end; x += 8) {
    const __m256 c = _mm256_loadu_ps(mid + x), r = _mm256_loadu_ps(mid + x + s), l = _mm256_loadu_ps(mid + x - s);
    const __m256 d = _mm256_loadu_ps(dn + x), u = _mm256_loadu_ps(up + x);
    const __m256 ok = _mm256_and_ps(_mm256_and_ps(_mm256_and_ps(valid8(c, zero, inf), valid8(r, zero, inf)),
                                                  _mm256_and_ps(valid8(l, zero, inf), valid8(d, zero, inf))),
                                    valid8(u, zero, inf));
    const __m256 dx = _mm256_sub_ps(r, l), dy = _mm256_sub_ps(d, u);
    const __m256 m = _mm256_sqrt_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)));
    const __m256 votes = _mm256_and_ps(ok, _mm256_cmp_ps(m, vjump, _CMP_LE_OQ));
    if (_mm256_movemask_ps(votes) == 0) continue;  // the row was set to 255
    const __m256 is_flat = _mm256_cmp_ps(m, vflat, _CMP_LE_OQ);
    // direction_deg
    const __m256 ax = _mm256_andnot_ps(sign, dx), ay = _mm256_andnot_ps(sign, dy);
    const __m256 t = _mm256_div_ps(_mm256_min_ps(ay, ax), _mm256_max_ps(ay, ax));  // min(ax, ay) / max(ax, ay)
    const __m256 s2 = _mm256_mul_ps(t, t);
    __m256 p = _mm256_mul_ps(s2, _mm256_set1_ps(0.0208351f));
    p = _mm256_mul_ps(s2, _mm256_add_ps(_mm256_set1_ps(-0.0851330f), p));
    p = _mm256_mul_ps(s2, _mm256_add_ps(_mm256_set1_ps(0.1801410f), p));
    p = _mm256_mul_ps(s2, _mm256_add_ps(_mm256_set1_ps(-0.3302995f), p));
    __m256 a = _mm256_mul_ps(t, _mm256_add_ps(_mm256_set1_ps(0.9998660f), p));
    a = _mm256_mul_ps(a, _mm256_set1_ps(57.295779513f));
    a = _mm256_blendv_ps(a, _mm256_sub_ps(_mm256_set1_ps(90.f), a), _mm256_cmp_ps(ay, ax, _CMP_GT_OQ));
    a = _mm256_blendv_ps(a, _mm256_sub_ps(_mm256_set1_ps(180.f), a), _mm256_cmp_ps(dx, zero, _CMP_LT_OQ));
    a = _mm256_blendv_ps(a, _mm256_xor_ps(a, sign), _mm256_cmp_ps(dy, zero, _CMP_LT_OQ));
    a = _mm256_blendv_ps(a, _mm256_add_ps(a, _mm256_set1_ps(360.f)), _mm256_cmp_ps(a, zero, _CMP_LE_OQ));
    __m256i k = _mm256_cvttps_epi32(_mm256_add_ps(_mm256_div_ps(a, vw), half));
    k = _mm256_sub_epi32(k, _mm256_and_si256(_mm256_cmpgt_epi32(k, vBm1), vB));  // k >= B: k -= B
    k = _mm256_blendv_epi8(k, vB, _mm256_castps_si256(is_flat));
    k = _mm256_blendv_epi8(v255, k, _mm256_castps_si256(votes));
    // Bytes: the packs work within each 128-bit half, so pixels 0-3 and 4-7 end in the halves' low words.
    k = _mm256_packus_epi16(_mm256_packs_epi32(k, k), _mm256_packs_epi32(k, k));
    const int32_t lo = _mm_cvtsi128_si32(_mm256_castsi256_si128(k)),
                  hi = _mm_cvtsi128_si32(_mm256_extracti128_si256(k, 1));
    std::memcpy(b + x, &lo, 4);
    std::memcpy(b + x + 4, &hi, 4);
  }
  return x;
}
#endif

/// god_bins(compute_god_features(image, s, flat), B, jump) without the two float images (same arithmetic,
/// and no arctangent for jump pixels, which do not vote).
void god_bins_of_image(const cv::Mat& image, int s, double flat_mgod_max, int B, double jump_mgod_min, cv::Mat& bins) {
  bins.create(image.size(), CV_8U);
  bins.setTo(cv::Scalar(255));
  const float flat = float(flat_mgod_max), jump = float(jump_mgod_min), w = 360.f / float(B);
  for (int y = s; y < image.rows - s; ++y) {
    const float* up = image.ptr<float>(y - s);
    const float* mid = image.ptr<float>(y);
    const float* dn = image.ptr<float>(y + s);
    uint8_t* b = bins.ptr<uint8_t>(y);
    int x = s;
#if defined(BOOKGRASP_GOD_AVX2)
    if (has_avx2()) x = god_bins_row_avx2(up, mid, dn, b, x, image.cols - s, s, flat, jump, w, B);
#endif
#if defined(__SSE2__)
    // Four pixels at a time, the scalar loop's operations in the same order (IEEE single precision
    // either way, no fused multiply-add on this target), branches as masks.
    const __m128 zero = _mm_setzero_ps(), inf = _mm_set1_ps(std::numeric_limits<float>::infinity());
    const __m128 vflat = _mm_set1_ps(flat), vjump = _mm_set1_ps(jump), vw = _mm_set1_ps(w);
    const __m128 sign = _mm_set1_ps(-0.f), half = _mm_set1_ps(0.5f);
    const __m128i vB = _mm_set1_epi32(B), vBm1 = _mm_set1_epi32(B - 1);
    const auto valid4 = [&](__m128 v) { return _mm_and_ps(_mm_cmpgt_ps(v, zero), _mm_cmplt_ps(v, inf)); };
    for (; x + 4 <= image.cols - s; x += 4) {
      const __m128 c = _mm_loadu_ps(mid + x), r = _mm_loadu_ps(mid + x + s), l = _mm_loadu_ps(mid + x - s);
      const __m128 d = _mm_loadu_ps(dn + x), u = _mm_loadu_ps(up + x);
      const __m128 ok =
          _mm_and_ps(_mm_and_ps(_mm_and_ps(valid4(c), valid4(r)), _mm_and_ps(valid4(l), valid4(d))), valid4(u));
      const __m128 dx = _mm_sub_ps(r, l), dy = _mm_sub_ps(d, u);
      const __m128 m = _mm_sqrt_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)));
      const __m128 votes = _mm_and_ps(ok, _mm_cmple_ps(m, vjump));
      const int vmask = _mm_movemask_ps(votes);
      if (vmask == 0) continue;
      const __m128 is_flat = _mm_cmple_ps(m, vflat);
      // direction_deg
      const __m128 ax = _mm_andnot_ps(sign, dx), ay = _mm_andnot_ps(sign, dy);
      const __m128 ay_gt = _mm_cmpgt_ps(ay, ax);
      const __m128 mn = _mm_or_ps(_mm_and_ps(_mm_cmplt_ps(ay, ax), ay), _mm_andnot_ps(_mm_cmplt_ps(ay, ax), ax));
      const __m128 mx = _mm_or_ps(_mm_and_ps(_mm_cmplt_ps(ax, ay), ay), _mm_andnot_ps(_mm_cmplt_ps(ax, ay), ax));
      const __m128 t = _mm_div_ps(mn, mx);
      const __m128 s2 = _mm_mul_ps(t, t);
      __m128 p = _mm_mul_ps(s2, _mm_set1_ps(0.0208351f));
      p = _mm_mul_ps(s2, _mm_add_ps(_mm_set1_ps(-0.0851330f), p));
      p = _mm_mul_ps(s2, _mm_add_ps(_mm_set1_ps(0.1801410f), p));
      p = _mm_mul_ps(s2, _mm_add_ps(_mm_set1_ps(-0.3302995f), p));
      __m128 a = _mm_mul_ps(t, _mm_add_ps(_mm_set1_ps(0.9998660f), p));
      a = _mm_mul_ps(a, _mm_set1_ps(57.295779513f));
      const auto pick = [](__m128 mask, __m128 yes, __m128 no) {
        return _mm_or_ps(_mm_and_ps(mask, yes), _mm_andnot_ps(mask, no));
      };
      a = pick(ay_gt, _mm_sub_ps(_mm_set1_ps(90.f), a), a);
      a = pick(_mm_cmplt_ps(dx, zero), _mm_sub_ps(_mm_set1_ps(180.f), a), a);
      a = pick(_mm_cmplt_ps(dy, zero), _mm_xor_ps(a, sign), a);
      a = pick(_mm_cmple_ps(a, zero), _mm_add_ps(a, _mm_set1_ps(360.f)), a);
      __m128i k = _mm_cvttps_epi32(_mm_add_ps(_mm_div_ps(a, vw), half));
      k = _mm_sub_epi32(k, _mm_and_si128(_mm_cmpgt_epi32(k, vBm1), vB));  // k >= B: k -= B
      k = _mm_or_si128(_mm_and_si128(_mm_castps_si128(is_flat), vB), _mm_andnot_si128(_mm_castps_si128(is_flat), k));
      // 255 where the pixel does not vote; the four bytes stored at once (0 <= k <= B <= 254).
      k = _mm_or_si128(_mm_and_si128(_mm_castps_si128(votes), k),
                       _mm_andnot_si128(_mm_castps_si128(votes), _mm_set1_epi32(255)));
      k = _mm_packs_epi32(k, k);
      const int32_t k4 = _mm_cvtsi128_si32(_mm_packus_epi16(k, k));
      std::memcpy(b + x, &k4, 4);
    }
#endif
    for (; x < image.cols - s; ++x) {
      const float r = mid[x + s], l = mid[x - s], d = dn[x], u = up[x];
      if (!(valid_value(mid[x]) && valid_value(r) && valid_value(l) && valid_value(d) && valid_value(u))) continue;
      const float dx = r - l, dy = d - u;
      const float m = std::sqrt(dx * dx + dy * dy);
      if (!(m <= jump)) continue;
      if (m <= flat) {
        b[x] = uint8_t(B);
      } else {
        int k = int(direction_deg(dx, dy) / w + 0.5f);
        if (k >= B) k -= B;
        b[x] = uint8_t(k);
      }
    }
  }
}

}  // namespace

GodParams GodParams::from_config(const Config& c) {
  GodParams p;
  p.gradient_step = c.get_int("gradient_step", 1, 16);
  p.smoothing_radius_px = c.get_int("smoothing_radius_px", 0, 16);
  p.smoothing_max_difference = c.get_double("smoothing_max_difference", 0.0, 1e9);
  p.direction_bins = c.get_int("direction_bins", 2, 254);
  p.flat_mgod_max = c.get_double("flat_mgod_max", 0.0, 1e6);
  p.window_size = c.get_int("window_size", 1, 101);
  p.jump_mgod_min = c.get_double("jump_mgod_min", 0.0, 1e9);
  p.jump_min_curvature = c.get_double("jump_min_curvature", 0.0, 1e9);
  p.merge_distance = c.get_double("merge_distance", 0.0, 1e9);
  p.merge_space =
      c.get_choice("merge_space", {"image", "points"}) == "image" ? MergeSpace::kImage : MergeSpace::kPoints;
  p.merge_max_angle_deg = c.get_double("merge_max_angle_deg", 0.0, 90.0);
  p.merge_angle_min_px = c.get_int("merge_angle_min_px", 3, 100000000);
  p.adjacency_radius_px = c.get_int("adjacency_radius_px", 1, 16);
  p.boundary_growth_px = c.get_int("boundary_growth_px", 0, 64);
  p.boundary_growth_distance = c.get_double("boundary_growth_distance", 0.0, 1e9);
  p.min_region_px = c.get_int("min_region_px", 1, 10000000);
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    throw ConfigError(c.source() + ": " + c.path_of("window_size") + ": " + e.what());
  }
  return p;
}

void GodParams::validate() const {
  if (gradient_step < 1) throw std::invalid_argument("gradient_step must be >= 1");
  if (smoothing_radius_px < 0) throw std::invalid_argument("smoothing_radius_px must be >= 0");
  if (!(smoothing_max_difference >= 0.0)) throw std::invalid_argument("smoothing_max_difference must be >= 0");
  if (direction_bins < 2 || direction_bins > 254) throw std::invalid_argument("direction_bins must be in [2, 254]");
  if (window_size < 1 || window_size % 2 == 0) throw std::invalid_argument("window_size must be odd and >= 1");
  if (!(flat_mgod_max >= 0.0)) throw std::invalid_argument("flat_mgod_max must be >= 0");
  if (!(jump_mgod_min > flat_mgod_max)) throw std::invalid_argument("jump_mgod_min must be > flat_mgod_max");
  if (!(jump_min_curvature >= 0.0)) throw std::invalid_argument("jump_min_curvature must be >= 0");
  if (!(merge_distance >= 0.0)) throw std::invalid_argument("merge_distance must be >= 0");
  if (adjacency_radius_px < 1) throw std::invalid_argument("adjacency_radius_px must be >= 1");
  if (boundary_growth_px < 0) throw std::invalid_argument("boundary_growth_px must be >= 0");
  if (min_region_px < 1) throw std::invalid_argument("min_region_px must be >= 1");
}

namespace {

/// Adds to sum[x], count[x] the values v[x] (x in [0, n)) that are valid and within max_difference of
/// centre[x]. NaN compares false, so an invalid v or centre adds nothing. SSE2 four at a time (the same
/// float operations per element as the scalar tail, so the result does not depend on the path).
inline void add_close_values(const float* __restrict v, const float* __restrict centre, int n, float max_difference,
                             float* __restrict sum, float* __restrict count) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  int x = 0;
#if defined(__SSE2__)
  const __m128 zero = _mm_setzero_ps(), inf = _mm_set1_ps(kInf), one = _mm_set1_ps(1.f);
  const __m128 dmax = _mm_set1_ps(max_difference), abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
  for (; x + 4 <= n; x += 4) {
    const __m128 value = _mm_loadu_ps(v + x);
    const __m128 diff = _mm_and_ps(_mm_sub_ps(value, _mm_loadu_ps(centre + x)), abs_mask);
    const __m128 use =
        _mm_and_ps(_mm_and_ps(_mm_cmpgt_ps(value, zero), _mm_cmplt_ps(value, inf)), _mm_cmple_ps(diff, dmax));
    _mm_storeu_ps(sum + x, _mm_add_ps(_mm_loadu_ps(sum + x), _mm_and_ps(use, value)));
    _mm_storeu_ps(count + x, _mm_add_ps(_mm_loadu_ps(count + x), _mm_and_ps(use, one)));
  }
#endif
  for (; x < n; ++x) {
    const float value = v[x];
    if (value > 0.f && value < kInf && std::fabs(value - centre[x]) <= max_difference) {
      sum[x] += value;
      count[x] += 1.f;
    }
  }
}

/// out[x] = sum[x] / count[x] where centre[x] is valid (count >= 1: the centre itself), else centre[x].
inline void finish_means(const float* __restrict centre, const float* __restrict sum, const float* __restrict count,
                         int n, float* __restrict out) {
  int x = 0;
#if defined(__SSE2__)
  const __m128 zero = _mm_setzero_ps(), inf = _mm_set1_ps(std::numeric_limits<float>::infinity());
  for (; x + 4 <= n; x += 4) {
    const __m128 c = _mm_loadu_ps(centre + x);
    const __m128 valid = _mm_and_ps(_mm_cmpgt_ps(c, zero), _mm_cmplt_ps(c, inf));
    const __m128 mean = _mm_div_ps(_mm_loadu_ps(sum + x), _mm_loadu_ps(count + x));
    _mm_storeu_ps(out + x, _mm_or_ps(_mm_and_ps(valid, mean), _mm_andnot_ps(valid, c)));
  }
#endif
  for (; x < n; ++x) out[x] = valid_value(centre[x]) ? sum[x] / count[x] : centre[x];
}

/// The two passes of smooth_valid_values: along rows (each pixel with the pixels within r columns of
/// it), then along columns (within r rows), each a row at a time into per-column sums.
void smooth_rows_then_columns(const cv::Mat& in, int r, float max_difference, cv::Mat& rows, cv::Mat& out,
                              std::vector<float>& sum, std::vector<float>& count) {
  const int W = in.cols, H = in.rows;
  rows.create(in.size(), CV_32F);
  out.create(in.size(), CV_32F);
  sum.resize(size_t(W));
  count.resize(size_t(W));
  for (int y = 0; y < H; ++y) {
    const float* src = in.ptr<float>(y);
    std::fill(sum.begin(), sum.end(), 0.f);
    std::fill(count.begin(), count.end(), 0.f);
    for (int k = -r; k <= r; ++k) {
      const int x0 = std::max(0, -k), x1 = std::min(W, W - k);  // x + k within the row
      if (x1 > x0)
        add_close_values(src + x0 + k, src + x0, x1 - x0, max_difference, &sum[size_t(x0)], &count[size_t(x0)]);
    }
    finish_means(src, sum.data(), count.data(), W, rows.ptr<float>(y));
  }
  for (int y = 0; y < H; ++y) {
    const float* centre = rows.ptr<float>(y);
    std::fill(sum.begin(), sum.end(), 0.f);
    std::fill(count.begin(), count.end(), 0.f);
    for (int k = std::max(0, y - r); k <= std::min(H - 1, y + r); ++k)
      add_close_values(rows.ptr<float>(k), centre, W, max_difference, sum.data(), count.data());
    finish_means(centre, sum.data(), count.data(), W, out.ptr<float>(y));
  }
}

/// smooth_valid_values into `out` (r >= 1), with the intermediate buffers of this thread.
void smooth_valid_values_into(const cv::Mat& image, int radius, double max_difference, cv::Mat& out) {
  thread_local cv::Mat rows;
  thread_local std::vector<float> sum, count;
  smooth_rows_then_columns(image, radius, float(max_difference), rows, out, sum, count);
}

}  // namespace

cv::Mat smooth_valid_values(const cv::Mat& image, int radius, double max_difference) {
  if (image.type() != CV_32F) throw std::invalid_argument("smooth_valid_values: image must be CV_32F");
  if (radius < 0) throw std::invalid_argument("smooth_valid_values: radius must be >= 0");
  if (!(max_difference >= 0.0)) throw std::invalid_argument("smooth_valid_values: max_difference must be >= 0");
  if (radius == 0) return image.clone();
  cv::Mat out;
  smooth_valid_values_into(image, radius, max_difference, out);
  return out;
}

GodFeatures compute_god_features(const cv::Mat& image, int s, double flat_mgod_max) {
  if (image.type() != CV_32F) throw std::invalid_argument("compute_god_features: image must be CV_32F");
  if (s < 1) throw std::invalid_argument("compute_god_features: gradient_step must be >= 1");
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float flat = float(flat_mgod_max);
  GodFeatures f;
  f.dgod.create(image.size(), CV_32F);
  f.mgod.create(image.size(), CV_32F);
  f.dgod.setTo(nan);
  f.mgod.setTo(nan);
  for (int y = s; y < image.rows - s; ++y) {
    const float* up = image.ptr<float>(y - s);
    const float* mid = image.ptr<float>(y);
    const float* dn = image.ptr<float>(y + s);
    float* dg = f.dgod.ptr<float>(y);
    float* mg = f.mgod.ptr<float>(y);
    for (int x = s; x < image.cols - s; ++x) {
      const float r = mid[x + s], l = mid[x - s], d = dn[x], u = up[x];
      if (!(valid_value(mid[x]) && valid_value(r) && valid_value(l) && valid_value(d) && valid_value(u))) continue;
      const float dx = r - l, dy = d - u;
      const float m = std::sqrt(dx * dx + dy * dy);
      mg[x] = m;
      dg[x] = (m <= flat) ? 0.f : direction_deg(dx, dy);
    }
  }
  return f;
}

cv::Mat god_bins(const GodFeatures& f, int B, double jump_mgod_min) {
  if (B < 2 || B > 254) throw std::invalid_argument("god_bins: direction_bins must be in [2, 254]");
  cv::Mat bins(f.dgod.size(), CV_8U);
  const float w = 360.f / float(B);
  const float jump = float(jump_mgod_min);
  for (int y = 0; y < bins.rows; ++y) {
    const float* dg = f.dgod.ptr<float>(y);
    const float* mg = f.mgod.ptr<float>(y);
    uint8_t* b = bins.ptr<uint8_t>(y);
    for (int x = 0; x < bins.cols; ++x) {
      const float a = dg[x];
      if (!std::isfinite(a) || !(mg[x] <= jump)) {
        b[x] = 255;
      } else if (a == 0.f) {
        b[x] = uint8_t(B);
      } else {
        int k = int(a / w + 0.5f);
        if (k >= B) k -= B;
        b[x] = uint8_t(k);
      }
    }
  }
  return bins;
}

void keep_steep_planes(const cv::Mat& image, int s, int B, double jump_mgod_min, double max_curvature, cv::Mat& bins) {
  if (image.type() != CV_32F || bins.type() != CV_8U || bins.size() != image.size())
    throw std::invalid_argument("keep_steep_planes: CV_32F image and CV_8U bins of the same size expected");
  if (s < 1 || B < 2 || B > 254) throw std::invalid_argument("keep_steep_planes: bad gradient step or bin count");
  const float w = 360.f / float(B), jump = float(jump_mgod_min), c = float(max_curvature);
  for (int y = s; y < image.rows - s; ++y) {
    const float* up = image.ptr<float>(y - s);
    const float* mid = image.ptr<float>(y);
    const float* dn = image.ptr<float>(y + s);
    uint8_t* b = bins.ptr<uint8_t>(y);
    for (int x = s; x < image.cols - s; ++x) {
      if (b[x] != 255) continue;
      const float m0 = mid[x], r = mid[x + s], l = mid[x - s], d = dn[x], u = up[x];
      if (!(valid_value(m0) && valid_value(r) && valid_value(l) && valid_value(d) && valid_value(u))) continue;
      const float dx = r - l, dy = d - u;
      if (!(std::sqrt(dx * dx + dy * dy) > jump)) continue;
      if (std::abs(r - 2.f * m0 + l) > c || std::abs(d - 2.f * m0 + u) > c) continue;
      int k = int(direction_deg(dx, dy) / w + 0.5f);
      if (k >= B) k -= B;
      b[x] = uint8_t(k);
    }
  }
}

namespace {

/// Histogram lanes are counted in 16 bits (n * n <= 101 * 101 votes), padded to whole vectors of 8, or
/// in 8 bits (windows up to 15 x 15: n * n <= 225 votes), padded to whole vectors of 16.
using Count = uint16_t;
using Count8 = uint8_t;

#if defined(__SSE2__)
inline void hist_add(Count* h, const Count* c, int K) {
  for (int k = 0; k < K; k += 8) {
    const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i*>(h + k));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(h + k),
                     _mm_add_epi16(a, _mm_loadu_si128(reinterpret_cast<const __m128i*>(c + k))));
  }
}
inline void hist_sub(Count* h, const Count* c, int K) {
  for (int k = 0; k < K; k += 8) {
    const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i*>(h + k));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(h + k),
                     _mm_sub_epi16(a, _mm_loadu_si128(reinterpret_cast<const __m128i*>(c + k))));
  }
}
/// Index of the largest count, the lowest index on ties. Lanes past the real bins hold 0 and the
/// pixel's own bin has at least its own vote, so they never win. Counts < 32768: signed max is exact.
inline int hist_argmax(const Count* h, int K) {
  __m128i mx = _mm_loadu_si128(reinterpret_cast<const __m128i*>(h));
  for (int k = 8; k < K; k += 8) mx = _mm_max_epi16(mx, _mm_loadu_si128(reinterpret_cast<const __m128i*>(h + k)));
  mx = _mm_max_epi16(mx, _mm_shuffle_epi32(mx, _MM_SHUFFLE(1, 0, 3, 2)));
  mx = _mm_max_epi16(mx, _mm_shuffle_epi32(mx, _MM_SHUFFLE(2, 3, 0, 1)));
  mx =
      _mm_max_epi16(mx, _mm_shufflelo_epi16(_mm_shufflehi_epi16(mx, _MM_SHUFFLE(2, 3, 0, 1)), _MM_SHUFFLE(2, 3, 0, 1)));
  for (int k = 0; k < K; k += 8) {
    const int m = _mm_movemask_epi8(_mm_cmpeq_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(h + k)), mx));
    if (m) return k + __builtin_ctz(unsigned(m)) / 2;
  }
  return 0;
}
/// The voting with 8-bit counts (windows up to 15 x 15: n * n <= 225 votes), 16 pixels at a time: the
/// column histograms are stored per bin (`colp`: num_bins planes of `stride` bytes, column x at x + r,
/// zero columns around), updated by vector compares of a whole row of bins; the window count of bin k
/// for 16 pixels is the sum of the 2r + 1 shifted loads of plane k; the argmax runs over the bins with a
/// strict comparison (largest count, the lowest bin on ties, as hist_argmax). Non-voting pixels get 255.
template <int kR>
void vote_clusters_planar_r(const cv::Mat& bins, int num_bins, cv::Mat& out, std::vector<uint8_t>& colp) {
  constexpr int r = kR;
  const int W = bins.cols, H = bins.rows;
  const size_t stride = size_t(W + 2 * r + 32) & ~size_t(15);
  colp.assign(size_t(num_bins) * stride, 0);
  uint8_t* const planes = colp.data();  // (a local: byte stores may alias the vector's members)
  // Counts are at most 225: compared as signed bytes after flipping the sign bit.
  const __m128i bias = _mm_set1_epi8(char(-128)), none = _mm_set1_epi8(char(-1));
  // 16 bins of row y from column x (255 past the row's end).
  const auto load_bins = [&](const uint8_t* b, int x) {
    if (x + 16 <= W) return _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + x));
    alignas(16) uint8_t tmp[16];
    std::fill(tmp, tmp + 16, uint8_t(255));
    std::copy(b + x, b + W, tmp);
    return _mm_load_si128(reinterpret_cast<const __m128i*>(tmp));
  };
  // Column histograms += the bins of row `in`, -= those of row `out_row` (either may be -1: none).
  const auto col_update = [&](int in, int out_row) {
    const uint8_t* bi = in >= 0 ? bins.ptr<uint8_t>(in) : nullptr;
    const uint8_t* bo = out_row >= 0 ? bins.ptr<uint8_t>(out_row) : nullptr;
    for (int x = 0; x < W; x += 16) {
      const __m128i vi = bi ? load_bins(bi, x) : none, vo = bo ? load_bins(bo, x) : none;
      // No pixel of either row votes here (all 255, e.g. no disparity): no column histogram changes.
      if (_mm_movemask_epi8(_mm_cmpeq_epi8(_mm_and_si128(vi, vo), none)) == 0xffff) continue;
      __m128i kk = _mm_setzero_si128();
      for (int k = 0; k < num_bins; ++k, kk = _mm_sub_epi8(kk, none)) {  // kk: k in every lane
        __m128i* c = reinterpret_cast<__m128i*>(planes + size_t(k) * stride + size_t(x + r));
        // cmpeq gives -1 where the bin is k: subtracting it counts the pixel, adding it removes it.
        const __m128i v = _mm_sub_epi8(_mm_loadu_si128(c), _mm_cmpeq_epi8(vi, kk));
        _mm_storeu_si128(c, _mm_add_epi8(v, _mm_cmpeq_epi8(vo, kk)));
      }
    }
  };
  // Stores 16 results at column x of row o (only the row's pixels).
  const auto store_out = [&](uint8_t* o, int x, __m128i res) {
    if (x + 16 <= W) {
      _mm_storeu_si128(reinterpret_cast<__m128i*>(o + x), res);
    } else {
      alignas(16) uint8_t tmp[16];
      _mm_store_si128(reinterpret_cast<__m128i*>(tmp), res);
      std::copy(tmp, tmp + (W - x), o + x);
    }
  };
  for (int y = 0; y <= std::min(r, H - 1); ++y) col_update(y, -1);
  out.create(bins.size(), CV_8U);
  for (int y = 0; y < H; ++y) {
    if (y > 0) col_update(y + r < H ? y + r : -1, y - r - 1);
    const uint8_t* b = bins.ptr<uint8_t>(y);
    uint8_t* o = out.ptr<uint8_t>(y);
    for (int x = 0; x < W; x += 16) {
      const __m128i vb = load_bins(b, x);
      // Voting pixels have a bin < num_bins (<= 255): bins are unsigned, compared after flipping the sign bit.
      const __m128i votes = _mm_cmplt_epi8(_mm_xor_si128(vb, bias), _mm_xor_si128(_mm_set1_epi8(char(num_bins)), bias));
      if (_mm_movemask_epi8(votes) == 0) {  // none of the 16 pixels votes: all stay 255, no window counts needed
        store_out(o, x, none);
        continue;
      }
      // Window count of bin k for pixels x..x+15: columns x - r .. x + 15 + r (plane offsets x .. x + 2r).
      const auto window = [&](int k) {
        const uint8_t* c = planes + size_t(k) * stride + size_t(x);
        __m128i sum = _mm_loadu_si128(reinterpret_cast<const __m128i*>(c));
        for (int j = 1; j <= 2 * r; ++j)
          sum = _mm_add_epi8(sum, _mm_loadu_si128(reinterpret_cast<const __m128i*>(c + j)));
        return _mm_xor_si128(sum, bias);
      };
      __m128i best = window(0), arg = _mm_setzero_si128(), kk = _mm_setzero_si128();
      for (int k = 1; k < num_bins; ++k) {
        kk = _mm_sub_epi8(kk, none);  // k in every lane
        const __m128i sb = window(k);
        const __m128i gt = _mm_cmpgt_epi8(sb, best);
        best = _mm_or_si128(_mm_and_si128(gt, sb), _mm_andnot_si128(gt, best));
        arg = _mm_or_si128(_mm_and_si128(gt, kk), _mm_andnot_si128(gt, arg));
      }
      store_out(o, x, _mm_or_si128(_mm_and_si128(votes, arg), _mm_andnot_si128(votes, none)));
    }
  }
}

#if defined(BOOKGRASP_GOD_AVX2)
/// 32 bins of a row from column x (255 past the row's W pixels).
GOD_TARGET_AVX2 inline __m256i load_bins32(const uint8_t* b, int x, int W) {
  if (x + 32 <= W) return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(b + x));
  alignas(32) uint8_t tmp[32];
  std::fill(tmp, tmp + 32, uint8_t(255));
  std::copy(b + x, b + W, tmp);
  return _mm256_load_si256(reinterpret_cast<const __m256i*>(tmp));
}

/// Stores the 32 results `res` at column x of the row `o` (only the row's W pixels).
GOD_TARGET_AVX2 inline void store_out32(uint8_t* o, int x, int W, __m256i res) {
  if (x + 32 <= W) {
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(o + x), res);
    return;
  }
  alignas(32) uint8_t tmp[32];
  _mm256_store_si256(reinterpret_cast<__m256i*>(tmp), res);
  std::copy(tmp, tmp + (W - x), o + x);
}

/// vote_clusters_planar_r's column update on 32 lanes: the column histograms (planes of `stride` bytes,
/// column x at x + r) += the bins of row `in`, -= those of row `out_row` (either may be null: none).
GOD_TARGET_AVX2 inline void col_update32(uint8_t* planes, size_t stride, int r, int num_bins, int W, const uint8_t* in,
                                         const uint8_t* out_row) {
  const __m256i none = _mm256_set1_epi8(char(-1));
  for (int x = 0; x < W; x += 32) {
    const __m256i vi = in ? load_bins32(in, x, W) : none, vo = out_row ? load_bins32(out_row, x, W) : none;
    if (_mm256_movemask_epi8(_mm256_cmpeq_epi8(_mm256_and_si256(vi, vo), none)) == -1) continue;
    __m256i kk = _mm256_setzero_si256();
    for (int k = 0; k < num_bins; ++k, kk = _mm256_sub_epi8(kk, none)) {  // kk: k in every lane
      __m256i* c = reinterpret_cast<__m256i*>(planes + size_t(k) * stride + size_t(x + r));
      const __m256i v = _mm256_sub_epi8(_mm256_loadu_si256(c), _mm256_cmpeq_epi8(vi, kk));
      _mm256_storeu_si256(c, _mm256_add_epi8(v, _mm256_cmpeq_epi8(vo, kk)));
    }
  }
}

/// vote_clusters_planar_r on 32 pixels at a time (AVX2): the same byte operations on twice the lanes,
/// so the same clusters. The planes get a wider padding (32-byte loads up to column W - 1 + 2r + 31).
template <int kR>
GOD_TARGET_AVX2 void vote_clusters_planar_avx2_r(const cv::Mat& bins, int num_bins, cv::Mat& out,
                                                 std::vector<uint8_t>& colp) {
  constexpr int r = kR;
  const int W = bins.cols, H = bins.rows;
  const size_t stride = size_t(W + 2 * r + 64) & ~size_t(31);
  colp.assign(size_t(num_bins) * stride, 0);
  uint8_t* const planes = colp.data();
  const __m256i bias = _mm256_set1_epi8(char(-128)), none = _mm256_set1_epi8(char(-1));
  const __m256i limit = _mm256_xor_si256(_mm256_set1_epi8(char(num_bins)), bias);
  for (int y = 0; y <= std::min(r, H - 1); ++y)
    col_update32(planes, stride, r, num_bins, W, bins.ptr<uint8_t>(y), nullptr);
  out.create(bins.size(), CV_8U);
  for (int y = 0; y < H; ++y) {
    if (y > 0)
      col_update32(planes, stride, r, num_bins, W, y + r < H ? bins.ptr<uint8_t>(y + r) : nullptr,
                   y - r - 1 >= 0 ? bins.ptr<uint8_t>(y - r - 1) : nullptr);
    const uint8_t* b = bins.ptr<uint8_t>(y);
    uint8_t* o = out.ptr<uint8_t>(y);
    for (int x = 0; x < W; x += 32) {
      const __m256i votes = _mm256_cmpgt_epi8(limit, _mm256_xor_si256(load_bins32(b, x, W), bias));
      if (_mm256_movemask_epi8(votes) == 0) {
        store_out32(o, x, W, none);
        continue;
      }
      __m256i best = _mm256_setzero_si256(), arg = _mm256_setzero_si256(), kk = _mm256_setzero_si256();
      for (int k = 0; k < num_bins; ++k, kk = _mm256_sub_epi8(kk, none)) {
        const uint8_t* c = planes + size_t(k) * stride + size_t(x);
        __m256i sum = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(c));
        for (int j = 1; j <= 2 * r; ++j)
          sum = _mm256_add_epi8(sum, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(c + j)));
        sum = _mm256_xor_si256(sum, bias);
        if (k == 0) {
          best = sum;
          continue;
        }
        const __m256i gt = _mm256_cmpgt_epi8(sum, best);
        best = _mm256_blendv_epi8(best, sum, gt);
        arg = _mm256_blendv_epi8(arg, kk, gt);
      }
      store_out32(o, x, W, _mm256_blendv_epi8(none, arg, votes));
    }
  }
}
#endif

/// Calls fn(std::integral_constant<int, R>{}) for the window's half size r (0..7; larger r: 7), so a kernel
/// templated on R is instantiated once per size.
template <typename Fn>
void with_half_size(int r, Fn&& fn) {
  switch (r) {
    case 0:
      return fn(std::integral_constant<int, 0>{});
    case 1:
      return fn(std::integral_constant<int, 1>{});
    case 2:
      return fn(std::integral_constant<int, 2>{});
    case 3:
      return fn(std::integral_constant<int, 3>{});
    case 4:
      return fn(std::integral_constant<int, 4>{});
    case 5:
      return fn(std::integral_constant<int, 5>{});
    case 6:
      return fn(std::integral_constant<int, 6>{});
    default:
      return fn(std::integral_constant<int, 7>{});
  }
}

/// vote_clusters_planar_r for the window's half size r (0..7).
void vote_clusters_planar(const cv::Mat& bins, int num_bins, int r, cv::Mat& out, std::vector<uint8_t>& colp) {
#if defined(BOOKGRASP_GOD_AVX2)
  if (has_avx2())
    return with_half_size(r,
                          [&](auto R) { vote_clusters_planar_avx2_r<decltype(R)::value>(bins, num_bins, out, colp); });
#endif
  with_half_size(r, [&](auto R) { vote_clusters_planar_r<decltype(R)::value>(bins, num_bins, out, colp); });
}
#else
template <typename C>
inline void hist_add(C* h, const C* c, int K) {
  for (int k = 0; k < K; ++k) h[k] = C(h[k] + c[k]);
}
template <typename C>
inline void hist_sub(C* h, const C* c, int K) {
  for (int k = 0; k < K; ++k) h[k] = C(h[k] - c[k]);
}
template <typename C>
inline int hist_argmax(const C* h, int K) {
  int best = 0;
  for (int k = 1; k < K; ++k)
    if (h[k] > h[best]) best = k;
  return best;
}
#endif

}  // namespace

namespace {

/// The voting on per-pixel histograms of C counts: a window histogram slid along each row over the
/// column histograms (`col`: K lanes per column).
template <typename C>
void vote_clusters_histograms(const cv::Mat& bins, int num_bins, int r, cv::Mat& out, std::vector<C>& col) {
  const int W = bins.cols, H = bins.rows;
  constexpr int L = 16 / int(sizeof(C));     // lanes per vector
  const int K = (num_bins + L - 1) / L * L;  // whole vectors
  using Count = C;
  col.assign(size_t(W) * size_t(K), 0);
  auto col_update = [&](int y, int delta) {
    const uint8_t* b = bins.ptr<uint8_t>(y);
    for (int x = 0; x < W; ++x)
      if (b[x] < num_bins) col[size_t(x) * size_t(K) + b[x]] = Count(col[size_t(x) * size_t(K) + b[x]] + delta);
  };
  for (int y = 0; y <= std::min(r, H - 1); ++y) col_update(y, +1);
  out.create(bins.size(), CV_8U);
  out.setTo(cv::Scalar(255));
  Count hist_buf[256 + 16];  // K <= 256
  Count* const hist = hist_buf;
  for (int y = 0; y < H; ++y) {
    if (y > 0) {
      if (y + r < H) col_update(y + r, +1);
      if (y - r - 1 >= 0) col_update(y - r - 1, -1);
    }
    const uint8_t* b = bins.ptr<uint8_t>(y);
    uint8_t* o = out.ptr<uint8_t>(y);
    std::fill(hist, hist + K, Count(0));
    for (int x = 0; x <= std::min(r, W - 1); ++x) hist_add(hist, &col[size_t(x) * size_t(K)], K);
    for (int x = 0; x < W; ++x) {
      if (b[x] < num_bins) o[x] = uint8_t(hist_argmax(hist, K));
      if (x + r + 1 < W) hist_add(hist, &col[size_t(x + r + 1) * size_t(K)], K);
      if (x - r >= 0) hist_sub(hist, &col[size_t(x - r) * size_t(K)], K);
    }
  }
}

/// vote_clusters into `out` (its buffer reused when it has the size and type), with the column
/// histograms in `col` (capacity reused).
/// (Counts in C: uint16_t always, uint8_t for windows up to 15 x 15.)
template <typename C>
void vote_clusters_into(const cv::Mat& bins, int num_bins, int n, cv::Mat& out, std::vector<C>& col) {
  if (bins.type() != CV_8U) throw std::invalid_argument("vote_clusters: bins must be CV_8U");
  if (n < 1 || n % 2 == 0) throw std::invalid_argument("vote_clusters: window_size must be odd");
  if (num_bins < 1 || num_bins > 255) throw std::invalid_argument("vote_clusters: num_bins must be in [1, 255]");
  if (sizeof(C) == 1 && n > 15) throw std::invalid_argument("vote_clusters: 8-bit counts need window_size <= 15");
#if defined(__SSE2__)
  if constexpr (sizeof(C) == 1) {
    vote_clusters_planar(bins, num_bins, n / 2, out, col);
  } else {
    vote_clusters_histograms(bins, num_bins, n / 2, out, col);
  }
#else
  vote_clusters_histograms(bins, num_bins, n / 2, out, col);
#endif
}

/// Appends base + x for the pixels x0 <= x < x1 of the row `v` with a valid value, in order: four
/// values tested at once (0 < v < inf, i.e. valid_value), the valid ones listed from the mask's bits.
inline void push_valid_pixels(const float* v, int x0, int x1, int base, std::vector<int>& out) {
  int x = x0;
#if defined(__SSE2__)
  const __m128 zero = _mm_setzero_ps(), inf = _mm_set1_ps(std::numeric_limits<float>::infinity());
  for (; x + 4 <= x1; x += 4) {
    const __m128 q = _mm_loadu_ps(v + x);
    for (unsigned m = unsigned(_mm_movemask_ps(_mm_and_ps(_mm_cmpgt_ps(q, zero), _mm_cmplt_ps(q, inf)))); m != 0;
         m &= m - 1)
      out.push_back(base + x + __builtin_ctz(m));
  }
#endif
  for (; x < x1; ++x)
    if (valid_value(v[x])) out.push_back(base + x);
}

/// A maximal horizontal run of one initial segment in a row: columns x0..x1 of segment `label`.
struct Run {
  int x0, x1, label;
};

/// Runs of the initial segments, in raster order: `runs[row_start[y]] .. runs[row_start[y + 1] - 1]`
/// are the runs of row y (row_start has H + 1 entries).
struct RunImage {
  std::vector<Run> runs;
  std::vector<size_t> row_start;
  /// Per run: kCoveredAbove / kCoveredBelow when a run of its segment in the row above / below spans
  /// all its columns (and maybe more).
  std::vector<uint8_t> cover;
};

/// RunImage::cover bits.
constexpr uint8_t kCoveredAbove = 1, kCoveredBelow = 2;

/// Last column of the run of `c[x]`'s value that starts at x (the row has W pixels).
inline int run_end(const uint8_t* c, int x, int W) {
  const uint8_t v = c[x];
  int x1 = x + 1;
#if defined(__SSE2__)
  const __m128i vv = _mm_set1_epi8(char(v));
  for (; x1 + 16 <= W; x1 += 16) {
    const unsigned m =
        unsigned(_mm_movemask_epi8(_mm_cmpeq_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(c + x1)), vv)));
    if (m != 0xffffu) return x1 + __builtin_ctz(~m) - 1;
  }
#endif
  while (x1 < W && c[x1] == v) ++x1;
  return x1 - 1;
}

/// 4-connected components of equal values of `cls` (CV_8U, 255 = background) as runs: the runs of each
/// row, joined to the runs of the row above that share a column and the value (union-find on runs),
/// labelled 1..count in raster order of the components' first pixels (= of their first runs).
/// `uf` and `values` are scratch (capacity reused).
void connected_runs(const cv::Mat& cls, RunImage& ri, int* count, UnionFind& uf, std::vector<uint8_t>& values) {
  if (cls.type() != CV_8U) throw std::invalid_argument("connected_regions: input must be CV_8U");
  const int W = cls.cols, H = cls.rows;
  std::vector<Run>& runs = ri.runs;
  runs.clear();
  values.clear();
  ri.cover.clear();
  uf.parent.clear();
  ri.row_start.resize(size_t(H) + 1);
  for (int y = 0; y < H; ++y) {
    const size_t i0 = runs.size();
    ri.row_start[size_t(y)] = i0;
    const uint8_t* c = cls.ptr<uint8_t>(y);
    for (int x = 0; x < W;) {
      const int x1 = run_end(c, x, W);
      if (c[x] != 255) {
        const int id = int(runs.size());
        runs.push_back({x, x1, id});
        values.push_back(c[x]);
        ri.cover.push_back(0);
        uf.parent.push_back(id);
      }
      x = x1 + 1;
    }
    if (y == 0) continue;
    // Runs of the row above that share a column (4-neighbours); both lists are sorted by column.
    size_t j = ri.row_start[size_t(y) - 1];
    for (size_t i = i0; i < runs.size(); ++i) {
      while (j < i0 && runs[j].x1 < runs[i].x0) ++j;
      for (size_t k = j; k < i0 && runs[k].x0 <= runs[i].x1; ++k)
        if (values[k] == values[i]) {
          uf.unite(int(k), int(i));
          if (runs[k].x0 <= runs[i].x0 && runs[k].x1 >= runs[i].x1) ri.cover[i] |= kCoveredAbove;
          if (runs[i].x0 <= runs[k].x0 && runs[i].x1 >= runs[k].x1) ri.cover[k] |= kCoveredBelow;
        }
    }
  }
  ri.row_start[size_t(H)] = runs.size();
  // Compact numbering in raster order of first occurrence. A run's parent is an earlier run of its
  // set (unite makes the smaller root the root, path halving points to a grandparent), so in index order
  // a root opens the next label and any other run takes its parent's, already final.
  const int* parent = uf.parent.data();
  int k = 0;
  for (size_t i = 0; i < runs.size(); ++i) {
    const size_t p = size_t(parent[i]);
    runs[i].label = p == i ? ++k : runs[p].label;
  }
  if (count) *count = k;
}

/// Writes the label image of `ri` (CV_32S, `size`; 0 outside the runs): a run's pixels get
/// `id[run.label]`, or run.label itself when `id` is null.
void paint_runs(const RunImage& ri, cv::Size size, const int* id, cv::Mat& lab) {
  lab.create(size, CV_32S);
  const int W = size.width;
  for (int y = 0; y < size.height; ++y) {
    int* l = lab.ptr<int>(y);
    // Pixels x0..x1 get v, four at a time: a store may run past x1 (not past the row), into pixels
    // that a later piece of the row overwrites.
    const auto fill = [&](int x0, int x1, int v) {
      int x = x0;
#if defined(__SSE2__)
      const __m128i vv = _mm_set1_epi32(v);
      for (; x <= x1 && x + 4 <= W; x += 4) _mm_storeu_si128(reinterpret_cast<__m128i*>(l + x), vv);
#endif
      for (; x <= x1; ++x) l[x] = v;
    };
    int x = 0;
    for (size_t i = ri.row_start[size_t(y)]; i < ri.row_start[size_t(y) + 1]; ++i) {
      const Run& r = ri.runs[i];
      fill(x, r.x0 - 1, 0);
      fill(r.x0, r.x1, id ? id[r.label] : r.label);
      x = r.x1 + 1;
    }
    fill(x, W - 1, 0);
  }
}

}  // namespace

cv::Mat vote_clusters(const cv::Mat& bins, int num_bins, int n) {
  cv::Mat out;
  std::vector<Count> col;
  vote_clusters_into(bins, num_bins, n, out, col);
  return out;
}

cv::Mat connected_regions(const cv::Mat& cls, int* count) {
  RunImage ri;
  UnionFind uf;
  std::vector<uint8_t> values;
  connected_runs(cls, ri, count, uf, values);
  cv::Mat lab;
  paint_runs(ri, cls.size(), nullptr, lab);
  return lab;
}

namespace {

/// Scratch buffers of segment_god that live across frames (one per thread), so that a frame of the
/// usual size reuses the previous frame's memory instead of faulting in fresh pages. Only capacity
/// carries over: every buffer is sized and initialised per call as before.
struct GodWorkspace {
  cv::Mat bins, clusters, labels, smoothed;
  std::vector<Count> col;
  std::vector<Count8> col8;
  UnionFind cc_uf, uf;
  std::vector<uint8_t> run_values;
  std::vector<PointSums> mom, omom;
  RunImage ri;
  std::vector<uint64_t> edges, recent, edge_tmp, root_edges;
  std::vector<uint32_t> open_runs;
  std::vector<int> edge_start;
  std::vector<Plane> planes, oplanes;
  std::vector<uint8_t> fitted;
  std::vector<Candidate> cand, cand_tmp;
  std::vector<uint32_t> cand_hist;
  std::vector<char> touched;
  std::vector<int> id_of_initial, id_of_root, root_of_id, todo, next_todo;
  std::vector<std::pair<int, int>> grown;
};

/// An image buffer of the workspace for this call: dropped first if the caller still holds it (a
/// returned label image), so a result is never overwritten by a later frame.
cv::Mat& own(cv::Mat& m) {
  if (m.u && m.u->refcount > 1) m.release();
  return m;
}

}  // namespace

SegmentationResult segment_god(const cv::Mat& image, const cv::Mat& points, const GodParams& params, GodDebug* debug) {
  params.validate();
  if (image.type() != CV_32F || image.empty())
    throw std::invalid_argument("segment_god: image must be a non-empty CV_32F depth or disparity image");
  if (!points.empty() && (points.type() != CV_32FC3 || points.size() != image.size()))
    throw std::invalid_argument("segment_god: points must be empty or CV_32FC3 of the image's size");
  if (params.merge_space == MergeSpace::kPoints && points.empty())
    throw std::invalid_argument("segment_god: merge_space 'points' needs the points image");

  thread_local GodWorkspace ws;
  GodDebug local;
  GodDebug& dbg = debug ? *debug : local;
  // Images: the debug output's own (fresh) images, else the workspace's.
  cv::Mat& bins = debug ? dbg.bins : own(ws.bins);
  cv::Mat& clusters = debug ? dbg.clusters : own(ws.clusters);
  cv::Mat& init_labels = debug ? dbg.initial_labels : own(ws.labels);  // without debug: the merged labels' buffer
  // The gradients' input: the image, or its edge-preserving mean (the planes use the image itself).
  if (params.smoothing_radius_px > 0)
    smooth_valid_values_into(image, params.smoothing_radius_px, params.smoothing_max_difference, ws.smoothed);
  const cv::Mat& gradient_input = params.smoothing_radius_px > 0 ? ws.smoothed : image;
  if (debug) {
    dbg.features = compute_god_features(gradient_input, params.gradient_step, params.flat_mgod_max);
    dbg.bins = god_bins(dbg.features, params.direction_bins, params.jump_mgod_min);
    dbg.clusters.release();
    dbg.initial_labels.release();
  } else {
    // Same bins without the DGoD/MGoD images (only the debug output needs them).
    god_bins_of_image(gradient_input, params.gradient_step, params.flat_mgod_max, params.direction_bins,
                      params.jump_mgod_min, bins);
  }
  if (params.jump_min_curvature > 0)
    keep_steep_planes(gradient_input, params.gradient_step, params.direction_bins, params.jump_mgod_min,
                      params.jump_min_curvature, bins);
  if (params.window_size <= 15)
    vote_clusters_into(bins, params.direction_bins + 1, params.window_size, clusters, ws.col8);
  else
    vote_clusters_into(bins, params.direction_bins + 1, params.window_size, clusters, ws.col);
  // Initial segments as runs (the label image of the initial segments is painted for the debug output
  // only: the moments, the adjacency and the merged labels all work on the runs).
  int count = 0;
  RunImage& ri = ws.ri;
  connected_runs(clusters, ri, &count, ws.cc_uf, ws.run_values);
  if (debug) paint_runs(ri, clusters.size(), nullptr, init_labels);
  dbg.initial_count = count;
  const int W = image.cols, H = image.rows;
  const std::vector<Run>& runs = ri.runs;
  const std::vector<size_t>& row_start = ri.row_start;

  // Merge-space point of a pixel: (x, y, value) in image space (no (x, y, value) image is built), else
  // the caller's point. The output planes are fitted to the caller's points, or to (x, y, value).
  const bool image_space = params.merge_space == MergeSpace::kImage;
  const bool same = points.empty() || !image_space;  // output points == merge points
  const auto merge_point = [&](int x, int y, Eigen::Vector3d* v) {
    if (image_space) {
      const float d = image.ptr<float>(y)[x];
      if (!valid_value(d)) return false;
      *v = Eigen::Vector3d(double(x), double(y), double(d));
      return true;
    }
    const cv::Vec3f& q = points.ptr<cv::Vec3f>(y)[x];
    if (!finite3(q)) return false;
    *v = Eigen::Vector3d(q[0], q[1], q[2]);
    return true;
  };

  // Moments of every initial segment in merge space and in the output points' space (raster order,
  // the same sums PointMoments::add would make). When the two spaces are one, one array serves both.
  std::vector<PointSums>& mom = ws.mom;
  mom.assign(size_t(count) + 1, PointSums());
  if (!same) ws.omom.assign(size_t(count) + 1, PointSums());
  std::vector<PointSums>& omom = same ? mom : ws.omom;
  // Run by run: a run's pixels are consecutive in its segment's raster order, so its sums are added
  // pixel by pixel into a local copy (the same additions in the same order, kept in registers).
  const bool exact = exact_coordinate_sums(W, H);
  for (int y = 0; y < H; ++y) {
    const float* v = image.ptr<float>(y);
    const cv::Vec3f* q = points.empty() ? nullptr : points.ptr<cv::Vec3f>(y);
    for (size_t i = row_start[size_t(y)]; i < row_start[size_t(y) + 1]; ++i) {
      const Run& r = runs[i];
      if (image_space && exact)
        add_image_run_exact(mom[size_t(r.label)], v, r.x0, r.x1, y);
      else if (image_space)
        add_image_run(mom[size_t(r.label)], v, r.x0, r.x1, y);
      else
        add_point_run(mom[size_t(r.label)], q, r.x0, r.x1);
      if (!same) add_point_run(omom[size_t(r.label)], q, r.x0, r.x1);
    }
  }

  // Adjacency: two initial segments are adjacent when two of their pixels are within the Chebyshev
  // radius R. Found on runs (maximal horizontal pieces of one label): a run and the later runs of its
  // row that start within R of its end, and the runs of the next R rows that overlap its columns
  // widened by R. An edge is not pushed again while it is in a small direct-mapped cache of recent
  // edges (most repeats come from the next rows); the rest of the repeats go in sort_unique_edges.
  // Implied pairs are skipped: a run u of row y covered by a run u' of its segment in row y + 1
  // (kCoveredBelow: u' spans u's columns) pairs with no run of rows y + 1..y + R that u' does not reach
  // at one row less (u' is as near to it in columns), and likewise for a run k of row y + dy covered
  // by a run of its segment in row y + dy - 1 (kCoveredAbove). By induction on dy every skipped pair is
  // found at a smaller row distance, down to the pairs within one row, which are never skipped: the
  // edge set is the same.
  const int R = params.adjacency_radius_px;
  std::vector<uint64_t>& edges = ws.edges;
  edges.resize(std::max(edges.capacity(), size_t(count) * 4 + 64));
  constexpr int kCacheBits = 11;
  std::vector<uint64_t>& recent = ws.recent;
  recent.assign(size_t(1) << kCacheBits, 0);  // 0 never is an edge (labels >= 1)
  // Without branches on the data (their outcomes are close to random here): the edge is always
  // written and counted only if it is new to the cache and not a pair of one segment.
  uint64_t* out = edges.data();
  uint64_t* out_end = out + edges.size();
  uint64_t* const cache = recent.data();
  const auto push = [&](int a, int b, bool implied) {
    const uint64_t lo = uint64_t(std::min(a, b)), hi = uint64_t(std::max(a, b));
    const uint64_t e = (lo << 32) | hi;
    uint64_t& slot = cache[size_t((e * 0x9E3779B97F4A7C15ull) >> (64 - kCacheBits))];
    const uint64_t old = slot;
    const bool fresh = (old != e) & (a != b) & !implied;
    *out = e;
    out += fresh;
    slot = fresh ? e : old;
    if (out == out_end) {
      const size_t n = edges.size();
      edges.resize(2 * n);
      out = edges.data() + n;
      out_end = edges.data() + edges.size();
    }
  };
  const Run* const rn = runs.data();
  const uint8_t* const cover = ri.cover.data();
  std::vector<uint32_t>& open = ws.open_runs;  // the row's runs not covered below (listed without branches)
  open.resize(size_t(W) + 1);
  for (int y = 0; y < H; ++y) {
    const size_t i0 = row_start[size_t(y)], i1 = row_start[size_t(y) + 1];
    size_t num_open = 0;
    for (size_t i = i0; i < i1; ++i) {
      open[num_open] = uint32_t(i);
      num_open += !(cover[i] & kCoveredBelow);
    }
    for (size_t i = i0; i < i1; ++i)
      for (size_t k = i + 1; k < i1 && rn[k].x0 - rn[i].x1 <= R; ++k) push(rn[i].label, rn[k].label, false);
    for (int dy = 1; dy <= R && y + dy < H; ++dy) {
      size_t j = row_start[size_t(y + dy)];
      const size_t j1 = row_start[size_t(y + dy) + 1];
      for (size_t oi = 0; oi < num_open; ++oi) {
        const Run u = rn[open[oi]];
        while (j < j1 && rn[j].x1 < u.x0 - R) ++j;  // u.x0 grows with i: j only moves forward
        for (size_t k = j; k < j1 && rn[k].x0 <= u.x1 + R; ++k) push(u.label, rn[k].label, cover[k] & kCoveredAbove);
      }
    }
  }
  const size_t num_edges = size_t(out - edges.data());
  edges.resize(num_edges);
  std::vector<uint64_t>& edge_tmp = ws.edge_tmp;
  std::vector<int>& edge_start = ws.edge_start;
  sort_unique_edges(edges, count, edge_tmp, edge_start);

  // Iterative merging: each round merges the closest admissible pairs, each region at most once,
  // then refits; until a round merges nothing.
  UnionFind& uf = ws.uf;
  uf.reset(size_t(count) + 1);
  std::vector<Plane>& planes = ws.planes;
  planes.assign(size_t(count) + 1, Plane());
  std::vector<Plane>& oplanes = ws.oplanes;
  oplanes.assign(same ? 0 : size_t(count) + 1, Plane());
  // Fitted lazily (most initial segments are never the larger region of a pair or gated).
  std::vector<uint8_t>& fitted = ws.fitted;
  fitted.assign(size_t(count) + 1, 0);  // bit 0: planes[i] current, bit 1: oplanes[i] current
  const auto plane = [&](int i) -> const Plane& {
    if (!(fitted[size_t(i)] & 1)) {
      planes[size_t(i)] = fit_plane_closed_form(mom[size_t(i)]);
      fitted[size_t(i)] |= 1;
    }
    return planes[size_t(i)];
  };
  const auto oplane = [&](int i) -> const Plane& {
    if (same) return plane(i);
    if (!(fitted[size_t(i)] & 2)) {
      oplanes[size_t(i)] = fit_plane_closed_form(omom[size_t(i)]);
      fitted[size_t(i)] |= 2;
    }
    return oplanes[size_t(i)];
  };
  const double cos_gate = std::cos(params.merge_max_angle_deg * M_PI / 180.0);
  const double gate_n = double(params.merge_angle_min_px);
  const double T = params.merge_distance;
  std::vector<Candidate>& cand = ws.cand;
  std::vector<char>& touched = ws.touched;
  touched.assign(size_t(count) + 1, 0);
  std::vector<uint64_t>& root_edges = ws.root_edges;
  root_edges.clear();
  root_edges.reserve(edges.size());
  dbg.merges = 0;
  dbg.merge_rounds = 0;
  for (;;) {
    cand.clear();
    root_edges.clear();
    for (uint64_t e : edges) {
      int a = uf.find(int(e >> 32)), b = uf.find(int(e & 0xffffffffu));
      if (a == b) continue;
      if (b < a) std::swap(a, b);
      root_edges.push_back((uint64_t(a) << 32) | uint64_t(b));
    }
    sort_unique_edges(root_edges, count, edge_tmp, edge_start);
    edges.swap(root_edges);  // adjacency between current roots only
    // Distance of the smaller region's points to the larger region's plane, with the orientation gate;
    // a negative value means "may not merge".
    auto merge_cost = [&](int a, int b) {
      const bool a_large = mom[size_t(a)].n >= mom[size_t(b)].n;
      const int L = a_large ? a : b, S = a_large ? b : a;
      if (mom[size_t(S)].n <= 0.0 || !plane(L).valid) return -1.0;
      const double d = rms_distance(mom[size_t(S)], plane(L));
      if (!(d < T)) return -1.0;
      if (omom[size_t(a)].n >= gate_n && omom[size_t(b)].n >= gate_n && oplane(a).valid && oplane(b).valid &&
          std::fabs(oplane(a).normal.dot(oplane(b).normal)) < cos_gate)
        return -1.0;
      return d;
    };
    for (uint64_t e : edges) {
      const int a = int(e >> 32), b = int(e & 0xffffffffu);
      const double d = merge_cost(a, b);
      if (d >= 0.0) {
        uint64_t bits;
        std::memcpy(&bits, &d, sizeof bits);
        cand.push_back({bits, e});  // e = a << 32 | b
      }
    }
    if (cand.empty()) break;
    ++dbg.merge_rounds;
    sort_candidates(cand, ws.cand_tmp, ws.cand_hist);
    // Closest pairs first; a pair whose regions changed in this round is re-checked with the current
    // planes (so a region can grow several times per round, keeping the rounds few).
    int merged_this_round = 0;
    // The candidates come in distance order, so their segments are all over the moment arrays (larger
    // than the core's L2 cache): the segments of a candidate a few places ahead are prefetched.
    constexpr size_t kAhead = 8;
    for (size_t ci = 0; ci < cand.size(); ++ci) {
      if (ci + kAhead < cand.size()) {
        const uint64_t ab = cand[ci + kAhead].ab;
        for (const size_t i : {size_t(ab >> 32), size_t(ab & 0xffffffffu)}) {
          __builtin_prefetch(&uf.parent[i]);
          __builtin_prefetch(&mom[i].n);
          __builtin_prefetch(&mom[i].zz);
          if (!same) {
            __builtin_prefetch(&omom[i].n);
            __builtin_prefetch(&omom[i].zz);
          }
        }
      }
      const Candidate& c = cand[ci];
      const int a0 = int(c.ab >> 32), b0 = int(c.ab & 0xffffffffu);
      const int a = uf.find(a0), b = uf.find(b0);
      if (a == b) continue;
      if ((a != a0 || b != b0 || touched[size_t(a)] || touched[size_t(b)]) && merge_cost(a, b) < 0.0) continue;
      const int root = uf.unite(a, b);
      const int other = root == a ? b : a;
      mom[size_t(root)].add(mom[size_t(other)]);
      if (!same) omom[size_t(root)].add(omom[size_t(other)]);
      fitted[size_t(root)] = 0;
      touched[size_t(root)] = 1;
      ++dbg.merges;
      ++merged_this_round;
    }
    std::fill(touched.begin(), touched.end(), 0);
    if (merged_this_round == 0) break;
  }

  // Merged labels, numbered 1..K in raster order of their first pixel. A root is the smallest initial
  // label of its set, i.e. the set's first initial segment in raster order, so this numbering keeps the
  // order of the roots (the growth's tie-break) and describe_regions gets K instead of `count` slots.
  // A segment's first pixel is its first run, so the ids are assigned run by run and painted from the
  // runs. Without debug output the label image is the workspace's buffer.
  cv::Mat labels = debug ? cv::Mat(image.size(), CV_32S) : init_labels;
  std::vector<int>&id_of_initial = ws.id_of_initial, &id_of_root = ws.id_of_root, &root_of_id = ws.root_of_id;
  id_of_initial.assign(size_t(count) + 1, 0);
  id_of_root.assign(size_t(count) + 1, 0);
  root_of_id.assign(1, 0);
  for (const Run& r : runs) {
    int& id = id_of_initial[size_t(r.label)];
    if (id != 0) continue;
    const int root = uf.find(r.label);
    int& rid = id_of_root[size_t(root)];
    if (rid == 0) {
      rid = int(root_of_id.size());
      root_of_id.push_back(root);
    }
    id = rid;
  }
  paint_runs(ri, image.size(), id_of_initial.data(), labels);

  // Boundary growth: unlabeled pixels with a valid point join the 8-neighbour region whose plane is
  // nearest, if within boundary_growth_distance (ties: the smaller label). Each step reads the labels
  // of the previous one. A pixel can only change in a step if a neighbour grew in the step before, so
  // after the first step (every unlabeled pixel) only the neighbours of the grown pixels are examined.
  if (params.boundary_growth_px > 0) {
    std::vector<int>&todo = ws.todo, &next_todo = ws.next_todo;
    std::vector<std::pair<int, int>>& grown = ws.grown;  // (pixel index, label)
    todo.clear();
    int* lab = labels.ptr<int>(0);  // continuous (created above)
    Eigen::Vector3d v;
    // The unlabeled pixels are the gaps between the runs: visited in raster order, as a scan of the image.
    for (int y = 0; y < H; ++y) {
      int x = 0;
      for (size_t i = row_start[size_t(y)];; ++i) {
        const bool last = i == row_start[size_t(y) + 1];
        const int gap_end = last ? W : runs[i].x0;
        if (image_space) {
          push_valid_pixels(image.ptr<float>(y), x, gap_end, y * W, todo);
          x = gap_end;
        }
        for (; x < gap_end; ++x)
          if (merge_point(x, y, &v)) todo.push_back(y * W + x);
        if (last) break;
        x = runs[i].x1 + 1;
      }
    }
    for (int g = 0; g < params.boundary_growth_px && !todo.empty(); ++g) {
      grown.clear();
      for (const int idx : todo) {
        const int y = idx / W, x = idx - y * W;
        if (!merge_point(x, y, &v)) continue;
        int best = 0;
        double best_d = params.boundary_growth_distance;
        for (int dy = -1; dy <= 1; ++dy) {
          const int yy = y + dy;
          if (yy < 0 || yy >= H) continue;
          const int* ln = lab + yy * W;
          for (int dx = -1; dx <= 1; ++dx) {
            const int xx = x + dx;
            if (xx < 0 || xx >= W) continue;
            const int b = ln[xx];
            if (b <= 0 || b == best) continue;
            const Plane& pl = plane(root_of_id[size_t(b)]);
            if (!pl.valid) continue;
            const double d = std::fabs(pl.normal.dot(v) - pl.offset);
            if (d < best_d || (d == best_d && best != 0 && b < best)) {
              best_d = d;
              best = b;
            }
          }
        }
        if (best) grown.emplace_back(idx, best);
      }
      if (grown.empty()) break;
      for (const auto& [idx, b] : grown) lab[idx] = b;
      // Next step's pixels: unlabeled neighbours of this step's grown pixels, each once (-1 while queued).
      next_todo.clear();
      for (const auto& gi : grown) {
        const int y = gi.first / W, x = gi.first - y * W;
        for (int yy = std::max(0, y - 1); yy <= std::min(H - 1, y + 1); ++yy)
          for (int xx = std::max(0, x - 1); xx <= std::min(W - 1, x + 1); ++xx)
            if (lab[yy * W + xx] == 0) {
              lab[yy * W + xx] = -1;
              next_todo.push_back(yy * W + xx);
            }
      }
      for (const int idx : next_todo) lab[idx] = 0;
      todo.swap(next_todo);
    }
  }

  return describe_regions_in_place(labels, points.empty() ? image_space_points(image) : points, params.min_region_px);
}

}  // namespace bookgrasp::bws
