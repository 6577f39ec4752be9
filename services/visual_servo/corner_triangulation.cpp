#include "services/visual_servo/corner_triangulation.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "common/text_format.h"

namespace bookgrasp {

namespace {
/// A view as a ray in base: the camera centre, the unit direction of R's pixel and the optical axis.
struct Ray {
  Eigen::Vector3d centre;
  Eigen::Vector3d dir;
  Eigen::Vector3d axis;
};

Ray ray_of(const CornerSighting& s, const CameraIntrinsics& k) {
  const Eigen::Vector3d ray_cam((s.pixel.x() - k.cx) / k.fx, (s.pixel.y() - k.cy) / k.fy, 1.0);
  return {s.camera_in_base.translation(), (s.camera_in_base.linear() * ray_cam).normalized(),
          s.camera_in_base.linear().col(2)};
}

/// The least-squares point of the rays `idx` of `rays`; false if they are (nearly) parallel.
bool nearest_point(const std::vector<Ray>& rays, const std::vector<size_t>& idx, Eigen::Vector3d* point) {
  // sum_i (I - d_i d_i^T)(p - c_i) = 0 over the rays c_i + t d_i.
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (size_t i : idx) {
    const Eigen::Matrix3d proj = Eigen::Matrix3d::Identity() - rays[i].dir * rays[i].dir.transpose();
    a += proj;
    b += proj * rays[i].centre;
  }
  // The rays' spread shows in a's smallest eigenvalue (0 for parallel rays).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(a);
  if (!(eig.eigenvalues()(0) > 1e-9 * static_cast<double>(idx.size()))) return false;
  *point = a.ldlt().solve(b);
  return point->allFinite();
}

/// A view's error for a point: the angle between its ray and the direction to the point, times fx (the
/// reprojection error for small angles; large for a point behind the camera).
double view_error_px(const Ray& r, const Eigen::Vector3d& point, const CameraIntrinsics& k) {
  const Eigen::Vector3d to_point = point - r.centre;
  return k.fx * std::atan2(r.dir.cross(to_point).norm(), r.dir.dot(to_point));
}

/// Whether `point` lies in front of the view's camera (positive depth along its optical axis).
bool in_front_of(const Ray& r, const Eigen::Vector3d& point) {
  return r.axis.dot(point - r.centre) > 0;
}

/// The largest distance between two of the rays' centres (all rays, or those of `idx`).
double baseline_of(const std::vector<Ray>& rays, const std::vector<size_t>& idx) {
  double baseline = 0;
  for (size_t i = 0; i < idx.size(); ++i)
    for (size_t j = i + 1; j < idx.size(); ++j)
      baseline = std::max(baseline, (rays[idx[i]].centre - rays[idx[j]].centre).norm());
  return baseline;
}
}  // namespace

std::optional<TriangulatedCorner> triangulate_corner(const std::vector<CornerSighting>& sightings,
                                                     const CameraIntrinsics& k, const CornerTriangulationParams& params,
                                                     std::string* why) {
  auto fail = [&](const std::string& reason) -> std::optional<TriangulatedCorner> {
    if (why) *why = reason;
    return std::nullopt;
  };
  const int need = std::max(2, params.min_sightings);
  if (static_cast<int>(sightings.size()) < need)
    return fail(format_text("%zu sightings of R, need %d", sightings.size(), need));
  std::vector<Ray> rays;
  std::vector<size_t> all;
  for (const CornerSighting& s : sightings) {
    all.push_back(rays.size());
    rays.push_back(ray_of(s, k));
  }
  if (const double b = baseline_of(rays, all); b < params.min_baseline_m)
    return fail(
        format_text("the camera moved %.1f mm while seeing R, need %.1f mm", b * 1e3, params.min_baseline_m * 1e3));
  // At most kMaxViews views, evenly over the task (the pair search below is quadratic; a 20 s servo at 10 Hz has
  // 200).
  constexpr size_t kMaxViews = 40;
  const size_t n = std::min(rays.size(), kMaxViews);
  std::vector<size_t> views(n);
  for (size_t i = 0; i < n; ++i) views[i] = n < rays.size() ? i * (rays.size() - 1) / (n - 1) : i;
  Eigen::Vector3d every;  // every view together: rays that cannot be triangulated at all
  if (!nearest_point(rays, views, &every)) return fail("the viewing rays of R are parallel");
  // Views whose R was another point (the detector took a shadow edge or another book for the corner on the
  // way) must not pull the point: the largest set of views that agree with the point of some pair of them
  // (RANSAC over every pair), then the least-squares point of that set.
  bool in_front = false;  // some pair's point lies in front of its cameras
  const double inlier_px = 2 * params.max_rms_px;
  size_t best_count = 0;
  double best_sum = 0;
  Eigen::Vector3d best_point = Eigen::Vector3d::Zero();
  for (size_t a = 0; a < n; ++a)
    for (size_t b = a + 1; b < n; ++b) {
      const Ray &ra = rays[views[a]], &rb = rays[views[b]];
      if ((ra.centre - rb.centre).norm() < params.min_baseline_m / 2) continue;
      Eigen::Vector3d p;
      if (!nearest_point(rays, {views[a], views[b]}, &p)) continue;
      in_front |= in_front_of(ra, p) && in_front_of(rb, p);
      size_t count = 0;
      double sum = 0;
      for (size_t v : views)
        if (const double e = view_error_px(rays[v], p, k); e <= inlier_px) {
          ++count;
          sum += e;
        }
      if (count > best_count || (count == best_count && sum < best_sum)) {
        best_count = count;
        best_sum = sum;
        best_point = p;
      }
    }
  if (!in_front) return fail("the triangulated R lies behind the cameras");
  if (static_cast<int>(best_count) < need)
    return fail(format_text("R does not stay one point: at most %zu of the %zu views agree within %.1f px, need %d",
                            best_count, n, inlier_px, need));
  std::vector<size_t> best;
  for (size_t v : views)
    if (view_error_px(rays[v], best_point, k) <= inlier_px) best.push_back(v);
  TriangulatedCorner out;
  if (!nearest_point(rays, best, &out.point)) return fail("the viewing rays of R are parallel");
  out.baseline_m = baseline_of(rays, best);
  out.sightings = static_cast<int>(best.size());
  double sq = 0;
  for (size_t i : best) {
    if (!in_front_of(rays[i], out.point)) return fail("the triangulated R lies behind a camera");
    sq += std::pow(view_error_px(rays[i], out.point, k), 2);
  }
  out.rms_px = std::sqrt(sq / static_cast<double>(best.size()));
  if (out.baseline_m < params.min_baseline_m)
    return fail(format_text("the %d views of R that agree span %.1f mm, need %.1f mm", out.sightings,
                            out.baseline_m * 1e3, params.min_baseline_m * 1e3));
  if (out.rms_px > params.max_rms_px)
    return fail(format_text("R does not stay one point: RMS %.2f px > %.2f px over the %d views that agree", out.rms_px,
                            params.max_rms_px, out.sightings));
  for (size_t i = 0; i < rays.size(); ++i)
    if (in_front_of(rays[i], out.point) && view_error_px(rays[i], out.point, k) <= inlier_px) out.agreeing.push_back(i);
  return out;
}

}  // namespace bookgrasp
