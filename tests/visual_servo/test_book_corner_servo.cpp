// IBVS on the corner R against a camera-model plant: at convergence the TCP's
// approach axis passes through the TRUE 3D corner and the gripper is rolled
// like the book's top edge.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "servo_plant.h"
#include "services/visual_servo/book_corner_servo.h"

namespace bookgrasp {
namespace {

BookCornerServoParams params() {
  BookCornerServoParams p;
  p.gain = 2.0;
  p.slope_gain = 2.0;
  p.max_linear_speed = 0.06;
  p.max_angular_speed = 0.3;
  p.converged_px = 1.0;
  p.converged_slope_rad = 0.005;
  p.converged_frames = 3;
  p.align_slope = true;
  return p;
}

struct RunResult {
  bool converged = false;
  int iterations = 0;
  Eigen::Isometry3d tcp = Eigen::Isometry3d::Identity();
};

// 30 Hz images, the command applied one frame late (image latency).
RunResult run(const test::CornerScene& scene, Eigen::Isometry3d tcp, double standoff, const BookCornerServoParams& p) {
  const HandEyeGeometry g = test::project_geometry();
  BookCornerServo servo(g, p);
  GripperTwist pending = GripperTwist::Zero();
  RunResult r;
  for (int i = 0; i < 600; ++i) {
    Eigen::Vector2d px;
    double slope = 0;
    if (!scene.observe(g, tcp, &px, &slope)) break;
    const CornerServoStep s = servo.step(px, slope, standoff);
    r.iterations = i + 1;
    if (s.converged) {
      r.converged = true;
      break;
    }
    tcp = test::integrate(tcp, pending, 1.0 / 30);
    pending = s.twist;
  }
  r.tcp = tcp;
  return r;
}

TEST(BookCornerServo, ConvergesFromOffsetsUpTo5cmOntoTheTrueCorner) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> off(-0.05, 0.05), roll(-0.06, 0.06);
  for (int trial = 0; trial < 30; ++trial) {
    test::CornerScene scene;
    scene.corner = Eigen::Vector3d(0.01, -0.02, 0.25);
    scene.roll_rad = roll(rng);
    const double standoff = 0.20;
    Eigen::Isometry3d start = Eigen::Isometry3d::Identity();
    start.translation() = scene.corner - Eigen::Vector3d(0, 0, standoff) + Eigen::Vector3d(off(rng), off(rng), 0);
    const RunResult r = run(scene, start, standoff, params());
    ASSERT_TRUE(r.converged) << "trial " << trial;
    // TCP axis through the true corner: up and right within 0.5 mm, depth kept.
    const Eigen::Vector3d e = r.tcp.translation() - (scene.corner - Eigen::Vector3d(0, 0, standoff));
    EXPECT_LT(std::abs(e.x()), 5e-4) << trial;
    EXPECT_LT(std::abs(e.y()), 5e-4) << trial;
    EXPECT_LT(std::abs(e.z()), 1e-9) << trial;
    // Gripper y parallel to the book's top edge.
    const Eigen::Vector3d y = r.tcp.linear().col(1);
    const double roll_err = std::atan2(y.x(), y.y()) - (-scene.roll_rad);
    EXPECT_LT(std::abs(roll_err), 0.01) << trial << " roll " << scene.roll_rad;
    EXPECT_LT(r.iterations, 150) << trial;
  }
}

TEST(BookCornerServo, WrongStandoffLeavesABoundedParallaxError) {
  // The target pixel depends on the assumed standoff (camera 6 cm above the TCP):
  // a 2 cm standoff error moves the converged TCP by about 0.06 * 0.02 / d_cam in X.
  test::CornerScene scene;
  scene.corner = Eigen::Vector3d(0, 0, 0.22);
  Eigen::Isometry3d start = Eigen::Isometry3d::Identity();
  start.translation() = Eigen::Vector3d(0.02, 0.02, 0.0);
  const RunResult r = run(scene, start, 0.20, params());
  ASSERT_TRUE(r.converged);
  EXPECT_NEAR(r.tcp.translation().y(), 0.0, 5e-4);
  const double expected_dx = 0.06 * ((0.22 + 0.0489) / (0.20 + 0.0489) - 1.0);
  EXPECT_NEAR(r.tcp.translation().x(), expected_dx, 1e-3);
}

TEST(BookCornerServo, SaturatesAndReportsTheError) {
  const HandEyeGeometry g = test::project_geometry();
  BookCornerServo servo(g, params());
  const CornerServoStep s = servo.step(Eigen::Vector2d(600, 50), 0.1, 0.2);
  EXPECT_LE(s.twist.head<3>().norm(), 0.06 + 1e-12);
  EXPECT_LE(s.twist.tail<3>().norm(), 0.3 + 1e-12);
  EXPECT_NEAR(s.error_px.x(), 600 - 319.5, 1e-9);
  EXPECT_GT(s.twist(1), 0.0);  // R right of the target: move right
  EXPECT_GT(s.twist(0), 0.0);  // R above the target: move up
  EXPECT_EQ(s.twist(2), 0.0);  // standoff kept
  EXPECT_FALSE(s.converged);
}

TEST(BookCornerServo, ConvergenceNeedsConsecutiveFrames) {
  const HandEyeGeometry g = test::project_geometry();
  BookCornerServoParams p = params();
  BookCornerServo servo(g, p);
  const Eigen::Vector2d t = g.target_pixel(0.2);
  EXPECT_FALSE(servo.step(t, 0.0, 0.2).converged);
  EXPECT_FALSE(servo.step(t, 0.0, 0.2).converged);
  EXPECT_FALSE(servo.step(t + Eigen::Vector2d(5, 0), 0.0, 0.2).converged);  // resets
  EXPECT_FALSE(servo.step(t, 0.0, 0.2).converged);
  EXPECT_FALSE(servo.step(t, 0.0, 0.2).converged);
  EXPECT_TRUE(servo.step(t, 0.0, 0.2).converged);
}

}  // namespace
}  // namespace bookgrasp
