// HandEyeGeometry against the URDF's numbers and against finite differences.
#include <gtest/gtest.h>

#include "servo_plant.h"
#include "services/visual_servo/hand_eye_geometry.h"

namespace bookgrasp {
namespace {

TEST(HandEyeGeometry, CameraPoseFromUrdfIsAboveAndBehindTheTcp) {
  const HandEyeGeometry g = test::project_geometry();
  const Eigen::Isometry3d t = g.camera_in_gripper();
  // URDF: camera at flange (0.06, 0, 0.06) rotated 90 deg about z; TCP at flange (0, 0, 0.1089).
  EXPECT_NEAR(t.translation().x(), 0.06, 1e-9);
  EXPECT_NEAR(t.translation().y(), 0.0, 1e-9);
  EXPECT_NEAR(t.translation().z(), 0.06 - 0.1089, 1e-9);
  // Optical x = gripper y (right), optical y = -gripper x (down), optical z = gripper z.
  EXPECT_TRUE(t.linear().col(0).isApprox(Eigen::Vector3d(0, 1, 0), 1e-9));
  EXPECT_TRUE(t.linear().col(1).isApprox(Eigen::Vector3d(-1, 0, 0), 1e-9));
  EXPECT_TRUE(t.linear().col(2).isApprox(Eigen::Vector3d(0, 0, 1), 1e-9));
}

TEST(HandEyeGeometry, TargetPixelIsBelowTheCentreByTheCameraOffset) {
  const HandEyeGeometry g = test::project_geometry();
  const double f = g.intrinsics().fy;
  for (double d : {0.1, 0.2, 0.5}) {
    const Eigen::Vector2d px = g.target_pixel(d);
    EXPECT_NEAR(px.x(), 319.5, 1e-9);
    EXPECT_NEAR(px.y(), 239.5 + f * 0.06 / (d + 0.1089 - 0.06), 1e-9) << d;
  }
}

TEST(HandEyeGeometry, BackProjectionInvertsProjection) {
  const HandEyeGeometry g = test::project_geometry();
  const Eigen::Vector3d p(0.031, -0.047, 0.27);
  Eigen::Vector2d px;
  ASSERT_TRUE(g.project_gripper_point(p, &px));
  Eigen::Vector3d q;
  double z = 0;
  ASSERT_TRUE(g.pixel_on_plane(px, 0.27, &q, &z));
  EXPECT_LT((q - p).norm(), 1e-9);
  EXPECT_NEAR(z, 0.27 + 0.0489, 1e-9);
  EXPECT_FALSE(g.pixel_on_plane(px, -0.2, &q));  // plane behind the camera
}

TEST(HandEyeGeometry, TwistTransformsRoundTripAndMatchFiniteDifferences) {
  const HandEyeGeometry g = test::project_geometry();
  GripperTwist t;
  t << 0.01, -0.02, 0.005, 0.1, -0.05, 0.2;
  const Eigen::Matrix<double, 6, 1> c = g.gripper_twist_to_camera(t);
  const GripperTwist back = g.camera_twist_to_gripper(c.head<3>(), c.tail<3>());
  EXPECT_LT((back - t).norm(), 1e-12);

  // Image motion of a point: interaction matrix x camera twist == finite difference of the projection.
  const Eigen::Vector3d p(0.02, 0.03, 0.25);  // gripper frame
  const double dt = 1e-6;
  const Eigen::Isometry3d moved = test::integrate(Eigen::Isometry3d::Identity(), t, dt);
  Eigen::Vector2d a, b;
  ASSERT_TRUE(g.project_gripper_point(p, &a));
  ASSERT_TRUE(g.project_gripper_point(moved.inverse() * p, &b));
  const Eigen::Vector3d pc = g.camera_in_gripper().inverse() * p;
  const Eigen::Vector2d rate = point_interaction_matrix(pc.x() / pc.z(), pc.y() / pc.z(), pc.z()) * c;
  const auto& k = g.intrinsics();
  EXPECT_NEAR((b.x() - a.x()) / dt, k.fx * rate.x(), 1e-2);
  EXPECT_NEAR((b.y() - a.y()) / dt, k.fy * rate.y(), 1e-2);
}

}  // namespace
}  // namespace bookgrasp
