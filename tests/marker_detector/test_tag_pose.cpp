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
  double x, y, z;           // tag centre in the camera, metres
  double roll, pitch, yaw;  // degrees, applied to a tag facing the camera
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

// A camera 1.6 m from an upright tag (a vertical board facing it), looking down at 30 deg: the view
// of the stereo camera onto the cart's rear board.
struct DownwardView {
  Eigen::Isometry3d camera_in_base = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d tag_in_camera = Eigen::Isometry3d::Identity();
  DownwardView() {
    const double p = 30.0 * kPi / 180.0;
    const Eigen::Vector3d z(std::cos(p), 0, -std::sin(p)), x(0, -1, 0);
    camera_in_base.linear() << x, z.cross(x), z;
    Eigen::Isometry3d tag_in_base = Eigen::Isometry3d::Identity();
    tag_in_base.linear() << Eigen::Vector3d(0, -1, 0), Eigen::Vector3d(0, 0, -1), Eigen::Vector3d(1, 0, 0);
    tag_in_base.translation() = 1.6 * z;
    tag_in_camera = camera_in_base.inverse() * tag_in_base;
  }
};

TEST(TagPose, CandidatesAreTheTruthAndItsMirrorBestFirst) {
  const DownwardView v;
  const auto corners = project_tag_corners(v.tag_in_camera, 0.08, intrinsics());
  const std::vector<TagPose> c = estimate_tag_pose_candidates(corners, 0.08, intrinsics());
  ASSERT_EQ(c.size(), 2u);
  EXPECT_LE(c[0].reprojection_error_px, c[1].reprojection_error_px);
  EXPECT_LT(angle_deg(c[0].tag_in_camera.linear(), v.tag_in_camera.linear()), 0.01);
  // The mirror: tilted back by tens of degrees, its corners still within a pixel.
  EXPECT_GT(angle_deg(c[1].tag_in_camera.linear(), v.tag_in_camera.linear()), 20.0);
  EXPECT_LT(c[1].reprojection_error_px, 1.0);
  EXPECT_NEAR(tag_tilt_from_upright(c[0].tag_in_camera, v.camera_in_base), 0.0, 1e-4);
  EXPECT_GT(tag_tilt_from_upright(c[1].tag_in_camera, v.camera_in_base), 20.0 * kPi / 180.0);
}

TEST(TagPose, UprightChoiceTakesTheMountedSolutionWhenTheMirrorFitsSlightlyBetter) {
  const DownwardView v;
  const auto corners = project_tag_corners(v.tag_in_camera, 0.08, intrinsics());
  std::vector<TagPose> c = estimate_tag_pose_candidates(corners, 0.08, intrinsics());
  ASSERT_EQ(c.size(), 2u);
  // Corner noise made the mirror fit best (as seen on a far cart): errors 0.3 px vs 0.6 px.
  std::swap(c[0], c[1]);
  c[0].reprojection_error_px = 0.3;
  c[1].reprojection_error_px = 0.6;
  const double max_tilt = 20.0 * kPi / 180.0;
  const auto upright = choose_upright_pose(c, v.camera_in_base, max_tilt, 1.0);
  ASSERT_TRUE(upright.has_value());
  EXPECT_LT(angle_deg(upright->tag_in_camera.linear(), v.tag_in_camera.linear()), 0.01);
  // Outside the ambiguity window only the mirror is considered: not upright, so no pose.
  EXPECT_FALSE(choose_upright_pose(c, v.camera_in_base, max_tilt, 0.1).has_value());
  // Without a tilt limit that mirror is returned.
  const auto any = choose_upright_pose(c, v.camera_in_base, kPi, 0.1);
  ASSERT_TRUE(any.has_value());
  EXPECT_DOUBLE_EQ(any->reprojection_error_px, 0.3);
  EXPECT_FALSE(choose_upright_pose({}, v.camera_in_base, kPi, 1.0).has_value());
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
