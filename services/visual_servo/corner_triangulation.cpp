#include "services/visual_servo/corner_triangulation.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "common/text_format.h"

namespace bookgrasp {

namespace {
/// The unit viewing ray of a sighting's pixel, in base.
Eigen::Vector3d ray_in_base(const CornerSighting& s, const CameraIntrinsics& k) {
  const Eigen::Vector3d ray_cam((s.pixel.x() - k.cx) / k.fx, (s.pixel.y() - k.cy) / k.fy, 1.0);
  return (s.camera_in_base.linear() * ray_cam).normalized();
}

/// The least-squares point of the rays of `views`; false if they are (nearly) parallel.
bool nearest_point(const std::vector<CornerSighting>& views, const CameraIntrinsics& k, Eigen::Vector3d* point) {
  // sum_i (I - d_i d_i^T)(p - c_i) = 0 over the rays c_i + t d_i.
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const CornerSighting& s : views) {
    const Eigen::Vector3d d = ray_in_base(s, k);
    const Eigen::Matrix3d proj = Eigen::Matrix3d::Identity() - d * d.transpose();
    a += proj;
    b += proj * s.camera_in_base.translation();
  }
  // The rays' spread shows in a's smallest eigenvalue (0 for parallel rays).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(a);
  if (!(eig.eigenvalues()(0) > 1e-9 * static_cast<double>(views.size()))) return false;
  *point = a.ldlt().solve(b);
  return point->allFinite();
}

/// A view's error for a point: the angle between its ray and the direction to the point, times fx (the
/// reprojection error for small angles; large for a point behind the camera).
double view_error_px(const CornerSighting& v, const Eigen::Vector3d& point, const CameraIntrinsics& k) {
  const Eigen::Vector3d ray = ray_in_base(v, k), to_point = point - v.camera_in_base.translation();
  return k.fx * std::atan2(ray.cross(to_point).norm(), ray.dot(to_point));
}

double baseline_of(const std::vector<CornerSighting>& views) {
  double baseline = 0;
  for (size_t i = 0; i < views.size(); ++i)
    for (size_t j = i + 1; j < views.size(); ++j)
      baseline =
          std::max(baseline, (views[i].camera_in_base.translation() - views[j].camera_in_base.translation()).norm());
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
  if (baseline_of(sightings) < params.min_baseline_m)
    return fail(format_text("the camera moved %.1f mm while seeing R, need %.1f mm", baseline_of(sightings) * 1e3,
                            params.min_baseline_m * 1e3));
  // Views whose R was another point (the detector took a shadow edge or another book for the corner on the
  // way) must not pull the point: the largest set of views that agree with the point of some pair of them
  // (RANSAC over every pair; a few dozen views), then the least-squares point of that set.
  // At most kMaxViews views, evenly over the task (the pair search is quadratic; a 20 s servo at 10 Hz has 200).
  constexpr size_t kMaxViews = 40;
  std::vector<CornerSighting> subsampled;
  if (sightings.size() > kMaxViews) {
    for (size_t i = 0; i < kMaxViews; ++i)
      subsampled.push_back(sightings[i * (sightings.size() - 1) / (kMaxViews - 1)]);
  }
  const std::vector<CornerSighting>& views = subsampled.empty() ? sightings : subsampled;
  Eigen::Vector3d all;  // every view together: rays that cannot be triangulated at all
  if (!nearest_point(views, k, &all)) return fail("the viewing rays of R are parallel");
  bool in_front = false;  // some pair's point lies in front of its cameras
  const double inlier_px = 2 * params.max_rms_px;
  std::vector<CornerSighting> best;
  double best_sum = 0;
  for (size_t i = 0; i < views.size(); ++i)
    for (size_t j = i + 1; j < views.size(); ++j) {
      if ((views[i].camera_in_base.translation() - views[j].camera_in_base.translation()).norm() <
          params.min_baseline_m / 2)
        continue;
      Eigen::Vector3d p;
      if (!nearest_point({views[i], views[j]}, k, &p)) continue;
      in_front |= (views[i].camera_in_base.inverse() * p).z() > 0 && (views[j].camera_in_base.inverse() * p).z() > 0;
      std::vector<CornerSighting> agree;
      double sum = 0;
      for (const CornerSighting& v : views)
        if (const double e = view_error_px(v, p, k); e <= inlier_px) {
          agree.push_back(v);
          sum += e;
        }
      if (agree.size() > best.size() || (agree.size() == best.size() && sum < best_sum)) {
        best = std::move(agree);
        best_sum = sum;
      }
    }
  if (!in_front) return fail("the triangulated R lies behind the cameras");
  if (static_cast<int>(best.size()) < need)
    return fail(format_text("R does not stay one point: at most %zu of the %zu views agree within %.1f px, need %d",
                            best.size(), views.size(), inlier_px, need));
  TriangulatedCorner out;
  if (!nearest_point(best, k, &out.point)) return fail("the viewing rays of R are parallel");
  out.baseline_m = baseline_of(best);
  out.sightings = static_cast<int>(best.size());
  double sq = 0;
  for (const CornerSighting& v : best) {
    if (!((v.camera_in_base.inverse() * out.point).z() > 0)) return fail("the triangulated R lies behind a camera");
    sq += std::pow(view_error_px(v, out.point, k), 2);
  }
  out.rms_px = std::sqrt(sq / static_cast<double>(best.size()));
  if (out.baseline_m < params.min_baseline_m)
    return fail(format_text("the %d views of R that agree span %.1f mm, need %.1f mm", out.sightings,
                            out.baseline_m * 1e3, params.min_baseline_m * 1e3));
  if (out.rms_px > params.max_rms_px)
    return fail(format_text("R does not stay one point: RMS %.2f px > %.2f px over the %d views that agree", out.rms_px,
                            params.max_rms_px, out.sightings));
  return out;
}

}  // namespace bookgrasp
