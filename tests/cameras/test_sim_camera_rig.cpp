// The simulated cameras against the scene's ground truth (SimModel::ground_truth):
// depth at P1, corner projections, determinism, seeds.
#include "common/sim_render/sim_camera_rig.h"

#include <cmath>
#include <memory>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "common/pose_conversion.h"

namespace bookgrasp::sim_render {
namespace {

const std::string kScene = BOOKGRASP_SOURCE_DIR "/config/scenes/default.yaml";

/// The camera as a consumer sees it: from the published calibration message only.
PinholeCamera from_message(const camera_calibration_t& c) {
  PinholeCamera cam;
  cam.frame = c.frame;
  cam.width = c.width;
  cam.height = c.height;
  cam.fx = c.fx;
  cam.fy = c.fy;
  cam.cx = c.cx;
  cam.cy = c.cy;
  cam.camera_in_base = pose_to_isometry(c.camera_in_base);
  return cam;
}

Eigen::Vector3d corner(const book_truth_t& b, int i) {
  return Eigen::Vector3d(b.corners_base[i][0], b.corners_base[i][1], b.corners_base[i][2]);
}

/// Result of comparing the rendered depth with the true front face near P1.
struct P1Check {
  int face_pixels = 0;        ///< book pixels on the true front face near P1 (>= 1.5 px inside it)
  double worst_pixel_error = 0;  ///< max |rendered z - true z| over those pixels
  double p1_error = 0;        ///< |z of the plane fitted to the rendered depth, at P1 - true z of P1|
};

P1Check check_p1(const CameraImage& img, const PinholeCamera& cam, const book_truth_t& b) {
  P1Check out;
  // Front face corners: bit 0 clear; 4 = P1 (top right), 6 top left, 2 bottom left, 0 bottom right.
  const int face[4] = {4, 6, 2, 0};
  std::vector<cv::Point2f> quad;
  for (int i : face) {
    const Eigen::Vector2d uv = cam.project(corner(b, i));
    quad.emplace_back(static_cast<float>(uv.x()), static_cast<float>(uv.y()));
  }
  const Eigen::Vector3d p1c = cam.to_camera(corner(b, 4));
  const Eigen::Vector3d n = (cam.to_camera(corner(b, 6)) - p1c).cross(cam.to_camera(corner(b, 0)) - p1c);
  const Eigen::Vector2d p1_px = cam.project(corner(b, 4));
  cv::Mat a(0, 3, CV_64F), rhs(0, 1, CV_64F);
  for (int r = static_cast<int>(p1_px.y()) - 14; r <= static_cast<int>(p1_px.y()) + 14; ++r) {
    for (int c = static_cast<int>(p1_px.x()) - 14; c <= static_cast<int>(p1_px.x()) + 14; ++c) {
      if (r < 0 || c < 0 || r >= img.depth.rows || c >= img.depth.cols) continue;
      if (img.owner.at<int>(r, c) != b.id) continue;
      if (cv::pointPolygonTest(quad, cv::Point2f(static_cast<float>(c), static_cast<float>(r)), true) < 1.5) continue;
      const Eigen::Vector3d ray = cam.ray(c, r);
      const double z_true = n.dot(p1c) / n.dot(ray);  // ray (x, y, 1) * z hits the plane
      const double z = img.depth.at<float>(r, c);
      out.worst_pixel_error = std::max(out.worst_pixel_error, std::abs(z - z_true));
      ++out.face_pixels;
      const double row[3] = {static_cast<double>(c), static_cast<double>(r), 1.0};
      a.push_back(cv::Mat(1, 3, CV_64F, const_cast<double*>(row)).clone());
      rhs.push_back(1.0 / z);
    }
  }
  if (out.face_pixels >= 6) {
    cv::Mat coef;
    cv::solve(a, rhs, coef, cv::DECOMP_SVD);  // 1/z is affine in (u, v) on a plane
    const double inv_z = coef.at<double>(0) * p1_px.x() + coef.at<double>(1) * p1_px.y() + coef.at<double>(2);
    out.p1_error = std::abs(1.0 / inv_z - p1c.z());
  }
  return out;
}

class RigTest : public ::testing::TestWithParam<uint64_t> {};

TEST_P(RigTest, DepthAtEachVisibleP1MatchesTruthWithin1mm) {
  SimCameraRig rig(kScene, GetParam());
  const ground_truth_t truth = rig.model().ground_truth(0);
  for (const char* name : {"stereo_left", "stereo_right"}) {
    const CameraImage img = rig.capture(name, 0, true, true);
    const PinholeCamera cam = from_message(img.camera.to_message(0));
    int visible = 0;
    bool rightmost_visible = false;
    for (const book_truth_t& b : truth.books) {
      const P1Check check = check_p1(img, cam, b);
      if (check.face_pixels < 6) continue;  // P1's face hidden from this camera
      ++visible;
      rightmost_visible = rightmost_visible || b.rightmost;
      EXPECT_LT(check.worst_pixel_error, 1e-3) << name << " book " << b.id;
      EXPECT_LT(check.p1_error, 1e-3) << name << " book " << b.id;
    }
    EXPECT_TRUE(rightmost_visible) << name << " seed " << GetParam() << ": the right-most book's P1 is hidden";
    EXPECT_GE(visible, 3) << name << " seed " << GetParam();
  }
}

TEST_P(RigTest, ProjectedCornersLandWithin1pxOfTheRenderedMask) {
  SimCameraRig rig(kScene, GetParam());
  const ground_truth_t truth = rig.model().ground_truth(0);
  const CameraImage img = rig.capture("stereo_left", 0, true, true);
  const PinholeCamera cam = from_message(img.camera.to_message(0));
  int corners_checked = 0;
  bool p1_of_rightmost_checked = false;
  for (const book_truth_t& b : truth.books) {
    // The silhouette of a box is the convex hull of its projected corners.
    std::vector<cv::Point2f> pts;
    std::vector<double> corner_z;
    for (int i = 0; i < 8; ++i) {
      const Eigen::Vector2d uv = cam.project(corner(b, i));
      pts.emplace_back(static_cast<float>(uv.x()), static_cast<float>(uv.y()));
    }
    std::vector<cv::Point2f> hull;
    cv::convexHull(pts, hull);
    for (int i = 0; i < 8; ++i) {
      const cv::Point2f v = pts[i];
      if (cv::pointPolygonTest(hull, v, true) < -1e-3 || cv::pointPolygonTest(hull, v, true) > 1e-3) continue;
      if (v.x < 5 || v.y < 5 || v.x > cam.width - 6 || v.y > cam.height - 6) continue;
      const double z_corner = cam.to_camera(corner(b, i)).z();
      // Around a silhouette corner: every pixel more than 1 px inside the
      // silhouette is the book unless something nearer covers it; every pixel
      // more than 1 px outside is not the book. Only corners not covered by
      // anything (all inside pixels are the book) count as visible.
      bool covered = false;
      int inside = 0, outside = 0, wrong = 0;
      for (int r = static_cast<int>(v.y) - 4; r <= static_cast<int>(v.y) + 4; ++r) {
        for (int c = static_cast<int>(v.x) - 4; c <= static_cast<int>(v.x) + 4; ++c) {
          const double s = cv::pointPolygonTest(hull, cv::Point2f(static_cast<float>(c), static_cast<float>(r)), true);
          const bool is_book = img.owner.at<int>(r, c) == b.id;
          if (s > 1.0) {
            ++inside;
            if (!is_book) covered = covered || img.depth.at<float>(r, c) < z_corner + 0.002;
            if (!is_book && !(img.depth.at<float>(r, c) < z_corner + 0.002)) ++wrong;
          } else if (s < -1.0) {
            ++outside;
            if (is_book) ++wrong;
          }
        }
      }
      if (covered || inside == 0 || outside == 0) continue;
      EXPECT_EQ(wrong, 0) << "book " << b.id << " corner " << i << " at " << v.x << "," << v.y;
      ++corners_checked;
      if (b.rightmost && i == 4) p1_of_rightmost_checked = true;
    }
  }
  EXPECT_GE(corners_checked, 8) << "seed " << GetParam();
  EXPECT_TRUE(p1_of_rightmost_checked) << "seed " << GetParam() << ": P1 of the right-most book not visible";
}

INSTANTIATE_TEST_SUITE_P(Seeds, RigTest, ::testing::Values(1u, 2u, 3u));

TEST(SimCameraRig, SameSceneAndSeedGiveIdenticalImagesOtherSeedsDiffer) {
  SimCameraRig a(kScene, 5);
  SimCameraRig b(kScene, 5);
  SimCameraRig c(kScene, 6);
  for (const char* name : {"stereo_left", "stereo_right", "hand_camera"}) {
    const cv::Mat ia = a.capture(name, 123456).rgb;
    const cv::Mat ib = b.capture(name, 123456).rgb;
    EXPECT_EQ(cv::norm(ia, ib, cv::NORM_INF), 0.0) << name;
  }
  // Different seeds: different books, so the left images differ well beyond the sensor noise.
  const cv::Mat l5 = a.capture("stereo_left", 0).rgb, l6 = c.capture("stereo_left", 0).rgb;
  cv::Mat diff;
  cv::absdiff(l5, l6, diff);
  cv::cvtColor(diff, diff, cv::COLOR_RGB2GRAY);
  EXPECT_GT(cv::countNonZero(diff > 40), 2000);
  const ground_truth_t t5 = a.model().ground_truth(0), t6 = c.model().ground_truth(0);
  EXPECT_TRUE(t5.num_books != t6.num_books || t5.books[0].width_m != t6.books[0].width_m);
}

TEST(SimCameraRig, StereoPairIsRectifiedWithTheSceneBaseline) {
  SimCameraRig rig(kScene, 1);
  const CameraImage l = rig.capture("stereo_left", 0), r = rig.capture("stereo_right", 0);
  EXPECT_TRUE(l.camera.camera_in_base.linear().isApprox(r.camera.camera_in_base.linear(), 1e-9));
  const Eigen::Vector3d d = l.camera.camera_in_base.inverse() * r.camera.camera_in_base.translation();
  EXPECT_NEAR(d.x(), rig.scene().stereo_baseline_m, 1e-9);  // right camera along the left optical +x
  EXPECT_NEAR(d.y(), 0.0, 1e-9);
  EXPECT_NEAR(d.z(), 0.0, 1e-9);
  EXPECT_EQ(l.rgb.cols, rig.scene().stereo_left.width);
  EXPECT_EQ(l.rgb.rows, rig.scene().stereo_left.height);
}

TEST(SimCameraRig, HandCameraFollowsTheArm) {
  SimCameraRig rig(kScene, 1);
  sim_state_t state = rig.model().state(1000);
  const CameraImage before = rig.capture("hand_camera", 1000);
  state.utime = 2000;
  for (int i = 0; i < state.num_joints; ++i)
    if (state.joint_names[i] == "arm_1_joint") state.joint_positions[i] += 0.3;
  rig.apply(state);
  const CameraImage after = rig.capture("hand_camera", 2000);
  // Joint 1 turns about base -z (the URDF flips the chain upright with rpy = pi about x):
  // the camera position rotates by -0.3 rad about base z, the optical axes with it.
  const Eigen::Vector3d p0 = before.camera.camera_in_base.translation();
  const Eigen::Vector3d p1 = after.camera.camera_in_base.translation();
  EXPECT_NEAR(std::atan2(p1.y(), p1.x()) - std::atan2(p0.y(), p0.x()), -0.3, 1e-6);
  const Eigen::Matrix3d expected_rotation =
      Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix() * before.camera.camera_in_base.linear();
  EXPECT_TRUE(after.camera.camera_in_base.linear().isApprox(expected_rotation, 1e-6));
  EXPECT_NEAR(p1.z(), p0.z(), 1e-9);
  EXPECT_NEAR(std::hypot(p1.x(), p1.y()), std::hypot(p0.x(), p0.y()), 1e-9);
}

TEST(SimCameraRig, BadStatesAreRefusedWithAReason) {
  SimCameraRig rig(kScene, 1);
  const sim_state_t good = rig.model().state(0);
  EXPECT_EQ(check_sim_state(good), "");
  sim_state_t s = good;
  s.joint_names.pop_back();
  s.joint_positions.pop_back();
  s.joint_velocities.pop_back();
  s.num_joints -= 1;
  EXPECT_NE(check_sim_state(s).find("missing"), std::string::npos) << check_sim_state(s);
  s = good;
  s.num_joints += 1;
  EXPECT_NE(check_sim_state(s).find("num_joints"), std::string::npos);
  s = good;
  s.joint_positions[2] = std::nan("");
  EXPECT_NE(check_sim_state(s).find("not finite"), std::string::npos);
  s = good;
  s.joint_names[1] = s.joint_names[0];
  EXPECT_NE(check_sim_state(s).find("twice"), std::string::npos);
  s = good;
  ASSERT_GT(s.num_bodies, 0);
  s.bodies[0].orientation[0] = 0.0;
  s.bodies[0].orientation[1] = 0.0;
  s.bodies[0].orientation[2] = 0.0;
  s.bodies[0].orientation[3] = 0.0;
  EXPECT_NE(check_sim_state(s).find("quaternion"), std::string::npos);
  s = good;
  s.num_bodies += 2;
  EXPECT_NE(check_sim_state(s).find("num_bodies"), std::string::npos);
  s = good;
  s.gripper_width_m = -0.0017;  // a closed gripper in CI (soft joint limits): not an error
  EXPECT_EQ(check_sim_state(s), "");
  s.gripper_width_m = -0.002;  // both fingers at the URDF's lower limit, -1 mm each
  EXPECT_EQ(check_sim_state(s), "");
  s.gripper_width_m = -0.006;
  EXPECT_NE(check_sim_state(s).find("gripper_width_m"), std::string::npos);
  s.gripper_width_m = 0.11;
  EXPECT_NE(check_sim_state(s).find("gripper_width_m"), std::string::npos);
  s = good;
  s.seed = 99;
  EXPECT_THROW(rig.apply(s), std::invalid_argument);
  EXPECT_THROW(rig.capture("no_camera", 0), std::invalid_argument);
}

}  // namespace
}  // namespace bookgrasp::sim_render
