#include "common/grasp_frame.h"

#include <stdexcept>

namespace bookgrasp {

Eigen::Isometry3d grasp_frame_in_base(const Eigen::Vector3d& into_shelf, const Eigen::Vector3d& origin,
                                      const Eigen::Vector3d& up) {
  if (!into_shelf.allFinite() || !origin.allFinite() || !up.allFinite())
    throw std::invalid_argument("grasp frame: directions and origin must be finite");
  const Eigen::Vector3d x = up.normalized();
  Eigen::Vector3d z = into_shelf - into_shelf.dot(x) * x;
  if (z.norm() < 1e-6 * into_shelf.norm() || into_shelf.norm() < 1e-9)
    throw std::invalid_argument("grasp frame: the into-shelf direction is parallel to up");
  z.normalize();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear().col(0) = x;
  t.linear().col(1) = y;
  t.linear().col(2) = z;
  t.translation() = origin;
  return t;
}

}  // namespace bookgrasp
