// Tests of estimate_tag_pose on tags rendered at known poses from the family's code bits.
#include <cmath>

#include <gtest/gtest.h>

#include <apriltag/tag36h11.h>

#include "services/marker_detector/tag_detector.h"
#include "services/marker_detector/tag_pose.h"
#include "synthetic_tag.h"

namespace bookgrasp {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Family {
  apriltag_family_t* f = tag36h11_create();
  ~Family() { tag36h11_destroy(f); }
};

TagDetectorParams params() {
  TagDetectorParams p;
  p.quad_decimate = 1.0;
  p.refine_edges = true;
  p.max_hamming = 0;
  return p;
}

TagCameraIntrinsics intrinsics() {
  TagCameraIntrinsics k;
  k.fx = 600.0;
  k.fy = 600.0;
  k.cx = 319.5;
  k.cy = 239.5;
  return k;
}

double angle_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() * 180.0 / kPi;
}

struct PoseCase {
  double x, y, z;          // tag centre in the camera, metres
  double roll, pitch, yaw; // degrees, applied to a tag facing the camera
};

class RenderedPose : public ::testing::TestWithParam<PoseCase> {};

TEST_P(RenderedPose, RecoveredWithinMillimetresAndADegree) {
  const PoseCase c = GetParam();
  const double size = 0.10;
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  truth.translation() = Eigen::Vector3d(c.x, c.y, c.z);
  truth.linear() = (Eigen::AngleAxisd(c.yaw * kPi / 180, Eigen::Vector3d::UnitZ()) *
                    Eigen::AngleAxisd(c.pitch * kPi / 180, Eigen::Vector3d::UnitY()) *
                    Eigen::AngleAxisd(c.roll * kPi / 180, Eigen::Vector3d::UnitX()))
                       .toRotationMatrix();
  Family fam;
  const TagCameraIntrinsics k = intrinsics();
  cv::Mat image(480, 640, CV_8UC1, cv::Scalar(140));
  test::draw_tag(image, fam.f, 7, size, truth, k.fx, k.fy, k.cx, k.cy);

  TagDetector detector(params());
  const auto found = detector.detect(image);
  ASSERT_EQ(found.size(), 1u);
  ASSERT_EQ(found[0].id, 7);
  // Corner order: detector corner k is the projection of the tag-frame corner k.
  const auto expected = project_tag_corners(truth, size, k);
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(found[0].corners[i].x, expected[i].x, 1.0) << "corner " << i;
    EXPECT_NEAR(found[0].corners[i].y, expected[i].y, 1.0) << "corner " << i;
  }
  const TagPose pose = estimate_tag_pose(found[0].corners, size, k);
  EXPECT_LT((pose.tag_in_camera.translation() - truth.translation()).norm(), 0.004)
      << "estimated " << pose.tag_in_camera.translation().transpose() << " true " << truth.translation().transpose();
  EXPECT_LT(angle_deg(pose.tag_in_camera.linear(), truth.linear()), 1.0);
  EXPECT_LT(pose.reprojection_error_px, 0.5);
}

INSTANTIATE_TEST_SUITE_P(Poses, RenderedPose,
                         ::testing::Values(PoseCase{0.0, 0.0, 0.6, 0, 0, 0}, PoseCase{0.08, -0.05, 0.7, 20, 0, 10},
                                           PoseCase{-0.1, 0.06, 0.8, 0, 30, -25},
                                           PoseCase{0.05, 0.05, 1.0, -25, 15, 90}),
                         [](const ::testing::TestParamInfo<PoseCase>& info) {
                           return "case" + std::to_string(info.index);
                         });

TEST(TagPose, ExactCornersGiveExactPose) {
  const TagCameraIntrinsics k = intrinsics();
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  truth.translation() = Eigen::Vector3d(0.1, -0.02, 0.9);
  truth.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 0.5).normalized()).toRotationMatrix();
  const auto corners = project_tag_corners(truth, 0.08, k);
  const TagPose pose = estimate_tag_pose(corners, 0.08, k);
  EXPECT_LT((pose.tag_in_camera.translation() - truth.translation()).norm(), 1e-6);
  EXPECT_LT(angle_deg(pose.tag_in_camera.linear(), truth.linear()), 1e-4);
  EXPECT_LT(pose.reprojection_error_px, 1e-6);
}

TEST(TagPose, DistortionIsUsed) {
  TagCameraIntrinsics k = intrinsics();
  k.distortion = {-0.2, 0.05, 0.001, -0.001, 0.0};
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  truth.translation() = Eigen::Vector3d(-0.15, 0.1, 0.7);
  const auto corners = project_tag_corners(truth, 0.08, k);
  const TagPose pose = estimate_tag_pose(corners, 0.08, k);
  EXPECT_LT((pose.tag_in_camera.translation() - truth.translation()).norm(), 1e-6);
}

TEST(TagPose, BadInputsThrow) {
  const TagCameraIntrinsics k = intrinsics();
  const std::array<cv::Point2d, 4> corners{{{300, 260}, {340, 260}, {340, 220}, {300, 220}}};
  EXPECT_THROW(estimate_tag_pose(corners, 0.0, k), std::invalid_argument);
  TagCameraIntrinsics bad = k;
  bad.fx = std::nan("");
  EXPECT_THROW(estimate_tag_pose(corners, 0.1, bad), std::invalid_argument);
  auto nan_corners = corners;
  nan_corners[2].x = std::nan("");
  EXPECT_THROW(estimate_tag_pose(nan_corners, 0.1, k), std::invalid_argument);
}

}  // namespace
}  // namespace bookgrasp
