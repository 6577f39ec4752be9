#include "common/pose_conversion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace bookgrasp {
namespace {

TEST(PoseConversion, RoundTrip) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(-1.1, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  t.translation() = Eigen::Vector3d(0.5, -0.2, 1.25);
  const pose_t p = isometry_to_pose(t, "base", "cart", 77);
  EXPECT_EQ(p.frame, "base");
  EXPECT_EQ(p.child, "cart");
  EXPECT_EQ(p.utime, 77);
  const Eigen::Isometry3d back = pose_to_isometry(p);
  EXPECT_TRUE(back.isApprox(t, 1e-12));
  // A known point: rotation about z by 90 degrees maps x to y.
  Eigen::Isometry3d r = Eigen::Isometry3d::Identity();
  r.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const pose_t q = isometry_to_pose(r, "a", "b", 0);
  EXPECT_NEAR(q.orientation[0], std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(q.orientation[3], std::sqrt(0.5), 1e-12);
}

TEST(PoseConversion, RejectsNanAndBadQuaternions) {
  pose_t p = isometry_to_pose(Eigen::Isometry3d::Identity(), "base", "x", 0);
  EXPECT_TRUE(is_valid_pose(p));
  p.position[1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(is_valid_pose(p));
  EXPECT_THROW(pose_to_isometry(p), PoseError);
  p = isometry_to_pose(Eigen::Isometry3d::Identity(), "base", "x", 0);
  p.orientation[0] = 0;
  EXPECT_THROW(pose_to_isometry(p), PoseError);
  p.orientation[0] = 1.0005;  // nearly unit: normalised, accepted
  EXPECT_NO_THROW(pose_to_isometry(p));
}

}  // namespace
}  // namespace bookgrasp
