#include "common/grasp_frame.h"

#include <gtest/gtest.h>

namespace bookgrasp {
namespace {

TEST(GraspFrame, RobotFacingTheCartAlongBaseX) {
  // The cart straight ahead: into the shelf = base +x. Then X up = base z, Y right = base -y.
  const Eigen::Isometry3d g = grasp_frame_in_base(Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0.6, 0, 0.1));
  EXPECT_TRUE(g.linear().col(0).isApprox(Eigen::Vector3d(0, 0, 1)));
  EXPECT_TRUE(g.linear().col(1).isApprox(Eigen::Vector3d(0, -1, 0)));
  EXPECT_TRUE(g.linear().col(2).isApprox(Eigen::Vector3d(1, 0, 0)));
  EXPECT_NEAR(g.linear().determinant(), 1.0, 1e-12);
  // A point 2 cm to the robot's right (base -y) and 1 cm up of the origin has grasp Y = +0.02, X = +0.01.
  const Eigen::Vector3d p = g.inverse() * Eigen::Vector3d(0.6, -0.02, 0.11);
  EXPECT_TRUE(p.isApprox(Eigen::Vector3d(0.01, 0.02, 0.0), 1e-12)) << p.transpose();
}

TEST(GraspFrame, TiltedIntoShelfIsMadeHorizontal) {
  const Eigen::Isometry3d g = grasp_frame_in_base(Eigen::Vector3d(1, 1, 0.3), Eigen::Vector3d::Zero());
  EXPECT_NEAR(g.linear().col(2).z(), 0.0, 1e-12);
  EXPECT_TRUE(g.linear().col(2).isApprox(Eigen::Vector3d(1, 1, 0).normalized()));
}

TEST(GraspFrame, DegenerateInputsThrow) {
  EXPECT_THROW(grasp_frame_in_base(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d::Zero()), std::invalid_argument);
  EXPECT_THROW(grasp_frame_in_base(Eigen::Vector3d(NAN, 0, 0), Eigen::Vector3d::Zero()), std::invalid_argument);
}

}  // namespace
}  // namespace bookgrasp
