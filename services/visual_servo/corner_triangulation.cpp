#include "services/visual_servo/corner_triangulation.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "common/text_format.h"

namespace bookgrasp {

namespace {
/// The least-squares point of the rays of `views`; false if they are (nearly) parallel.
bool nearest_point(const std::vector<CornerSighting>& views, const CameraIntrinsics& k, Eigen::Vector3d* point) {
  // sum_i (I - d_i d_i^T)(p - c_i) = 0 over the rays c_i + t d_i.
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const CornerSighting& s : views) {
    const Eigen::Vector3d ray_cam((s.pixel.x() - k.cx) / k.fx, (s.pixel.y() - k.cy) / k.fy, 1.0);
    const Eigen::Vector3d d = (s.camera_in_base.linear() * ray_cam).normalized();
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
  // way) are dropped one at a time, the worst first, while enough views over enough baseline remain.
  std::vector<CornerSighting> views = sightings;
  for (;;) {
    TriangulatedCorner out;
    if (!nearest_point(views, k, &out.point)) return fail("the viewing rays of R are parallel");
    std::vector<double> err(views.size());
    double sq = 0;
    for (size_t i = 0; i < views.size(); ++i) {
      const Eigen::Vector3d pc = views[i].camera_in_base.inverse() * out.point;
      if (!(pc.z() > 0)) return fail("the triangulated R lies behind a camera");
      const Eigen::Vector2d px(k.fx * pc.x() / pc.z() + k.cx, k.fy * pc.y() / pc.z() + k.cy);
      err[i] = (px - views[i].pixel).norm();
      sq += err[i] * err[i];
    }
    out.rms_px = std::sqrt(sq / static_cast<double>(views.size()));
    out.baseline_m = baseline_of(views);
    out.sightings = static_cast<int>(views.size());
    if (out.rms_px <= params.max_rms_px) return out;
    std::vector<CornerSighting> fewer = views;
    fewer.erase(fewer.begin() + (std::max_element(err.begin(), err.end()) - err.begin()));
    if (static_cast<int>(fewer.size()) < need || baseline_of(fewer) < params.min_baseline_m)
      return fail(format_text("R does not stay one point: reprojection RMS %.2f px > %.2f px over the %zu views left",
                              out.rms_px, params.max_rms_px, views.size()));
    views = std::move(fewer);
  }
}

}  // namespace bookgrasp
