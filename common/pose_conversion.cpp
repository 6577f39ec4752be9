#include "common/pose_conversion.h"

#include <cmath>

namespace bookgrasp {

bool is_valid_pose(const pose_t& p) {
  double n2 = 0;
  for (double v : p.position)
    if (!std::isfinite(v)) return false;
  for (double v : p.orientation) {
    if (!std::isfinite(v)) return false;
    n2 += v * v;
  }
  return std::abs(std::sqrt(n2) - 1.0) <= 1e-3;
}

Eigen::Isometry3d pose_to_isometry(const pose_t& p) {
  if (!is_valid_pose(p))
    throw PoseError("pose of '" + p.child + "' in '" + p.frame +
                    "' is not a rigid transform (NaN/inf value or quaternion norm not 1)");
  Eigen::Quaterniond q(p.orientation[0], p.orientation[1], p.orientation[2], p.orientation[3]);
  q.normalize();
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = q.toRotationMatrix();
  t.translation() = Eigen::Vector3d(p.position[0], p.position[1], p.position[2]);
  return t;
}

pose_t isometry_to_pose(const Eigen::Isometry3d& t, const std::string& frame, const std::string& child,
                        int64_t utime) {
  pose_t p;
  p.utime = utime;
  p.frame = frame;
  p.child = child;
  const Eigen::Quaterniond q(t.rotation());
  for (int i = 0; i < 3; ++i) p.position[i] = t.translation()[i];
  p.orientation[0] = q.w();
  p.orientation[1] = q.x();
  p.orientation[2] = q.y();
  p.orientation[3] = q.z();
  return p;
}

}  // namespace bookgrasp
