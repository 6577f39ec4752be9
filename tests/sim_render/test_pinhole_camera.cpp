#include "common/sim_render/pinhole_camera.h"

#include <cmath>

#include <gtest/gtest.h>

#include "common/pose_conversion.h"

namespace bookgrasp::sim_render {
namespace {

TEST(PinholeCamera, FocalFromVerticalFieldOfView) {
  EXPECT_NEAR(focal_from_fovy(90.0, 480), 240.0, 1e-9);
  EXPECT_NEAR(focal_from_fovy(60.0, 480), 240.0 * std::sqrt(3.0), 1e-9);
}

TEST(PinholeCamera, ProjectsThroughTheOpticalFrame) {
  PinholeCamera cam;
  cam.frame = "stereo_left";
  cam.width = 640;
  cam.height = 480;
  cam.fx = cam.fy = 500.0;
  cam.cx = 319.5;
  cam.cy = 239.5;
  // Camera 1 m above base, looking straight down (z forward = -z base), x right = +x base.
  cam.camera_in_base.linear() << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  cam.camera_in_base.translation() = Eigen::Vector3d(0, 0, 1);
  const Eigen::Vector2d centre = cam.project(Eigen::Vector3d(0, 0, 0));
  EXPECT_NEAR(centre.x(), 319.5, 1e-12);
  EXPECT_NEAR(centre.y(), 239.5, 1e-12);
  // 0.1 m along base +x is 50 px right; 0.1 m along +y (base left) is up in the image (rows decrease)
  // because the optical y axis points along -y base.
  EXPECT_NEAR(cam.project(Eigen::Vector3d(0.1, 0, 0)).x(), 369.5, 1e-9);
  EXPECT_NEAR(cam.project(Eigen::Vector3d(0, 0.1, 0)).y(), 189.5, 1e-9);
  const Eigen::Vector3d r = cam.ray(369.5, 189.5);
  EXPECT_NEAR(r.x(), 0.1, 1e-12);
  EXPECT_NEAR(r.y(), -0.1, 1e-12);
  EXPECT_DOUBLE_EQ(r.z(), 1.0);

  const camera_calibration_t msg = cam.to_message(42);
  EXPECT_EQ(msg.utime, 42);
  EXPECT_EQ(msg.frame, "stereo_left");
  EXPECT_EQ(msg.width, 640);
  EXPECT_EQ(msg.distortion_model, "none");
  EXPECT_EQ(msg.num_distortion, 0);
  EXPECT_EQ(msg.camera_in_base.frame, "base");
  EXPECT_EQ(msg.camera_in_base.child, "stereo_left");
  EXPECT_TRUE(pose_to_isometry(msg.camera_in_base).isApprox(cam.camera_in_base, 1e-12));
}

}  // namespace
}  // namespace bookgrasp::sim_render
