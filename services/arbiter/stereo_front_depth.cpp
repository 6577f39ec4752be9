#include "services/arbiter/stereo_front_depth.h"

#include <cmath>

namespace bookgrasp {

std::optional<double> front_depth_left_of(const std::vector<FrontPlane>& planes, const Eigen::Vector3d& ps,
                                          const StereoFrontProbe& probe) {
  if (!ps.allFinite()) return std::nullopt;
  const double y_lo = ps.y() - probe.far_left, y_hi = ps.y() - probe.near_left;
  const double y_mid = (y_lo + y_hi) / 2;
  std::optional<double> best;
  int best_pixels = 0;
  for (const FrontPlane& p : planes) {
    if (!p.normal.allFinite() || !std::isfinite(p.offset) || !p.min.allFinite() || !p.max.allFinite()) continue;
    const double n = p.normal.norm();
    if (n < 1e-9 || std::abs(p.normal.z()) / n < std::cos(probe.max_tilt)) continue;
    if (p.max.y() < y_lo || p.min.y() > y_hi) continue;
    if (p.max.x() < probe.min_top) continue;
    const double x_mid = (p.min.x() + p.max.x()) / 2;
    const double z = (p.offset - p.normal.x() * x_mid - p.normal.y() * y_mid) / p.normal.z();
    if (!(z >= probe.min_z && z <= probe.max_z)) continue;
    if (!best || p.pixels > best_pixels) {
      best = z;
      best_pixels = p.pixels;
    }
  }
  return best;
}

}  // namespace bookgrasp
