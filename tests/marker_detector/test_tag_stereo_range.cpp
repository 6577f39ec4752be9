// range_tag_in_stereo on a tag drawn into both images of a rectified pair at a known pose (the right camera
// 0.12 m along the left's +x): the depth against the drawn one, and the inputs it refuses.
#include "services/marker_detector/tag_stereo_range.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include <apriltag/tag36h11.h>

#include "synthetic_tag.h"

namespace bookgrasp {
namespace {

constexpr double kFx = 625.0, kCx = 319.5, kCy = 239.5, kBaseline = 0.12, kSize = 0.08;

struct Family {
  apriltag_family_t* f = tag36h11_create();
  ~Family() { tag36h11_destroy(f); }
};

// A textured background (books, shelves) the patch must not match by chance.
cv::Mat background(unsigned seed) {
  cv::Mat small(30, 40, CV_8UC1);
  std::mt19937 rng(seed);
  for (int r = 0; r < small.rows; ++r)
    for (int c = 0; c < small.cols; ++c) small.at<uint8_t>(r, c) = static_cast<uint8_t>(60 + rng() % 120);
  cv::Mat big;
  cv::resize(small, big, cv::Size(640, 480), 0, 0, cv::INTER_LINEAR);
  return big;
}

struct Pair {
  cv::Mat left, right;
  std::array<cv::Point2d, 4> corners;  // projected into the left image, AprilTag order
};

// The tag at `tag_in_left`; the background is the same wall seen by both cameras (shifted by a far disparity).
Pair draw_pair(const Eigen::Isometry3d& tag_in_left) {
  Family fam;
  Pair p;
  p.left = background(3);
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, -10, 0, 1, 0);
  cv::warpAffine(p.left, p.right, shift, p.left.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  Eigen::Isometry3d tag_in_right = Eigen::Translation3d(-kBaseline, 0, 0) * tag_in_left;
  test::draw_tag(p.left, fam.f, 0, kSize, tag_in_left, kFx, kFx, kCx, kCy);
  test::draw_tag(p.right, fam.f, 0, kSize, tag_in_right, kFx, kFx, kCx, kCy);
  const double h = kSize / 2;
  const Eigen::Vector3d c[4] = {{-h, h, 0}, {h, h, 0}, {h, -h, 0}, {-h, -h, 0}};
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d x = tag_in_left * c[i];
    p.corners[static_cast<size_t>(i)] = cv::Point2d(kFx * x.x() / x.z() + kCx, kFx * x.y() / x.z() + kCy);
  }
  return p;
}

Eigen::Isometry3d tag_at(double x, double y, double z, double yaw_deg) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  t.translation() = Eigen::Vector3d(x, y, z);
  return t;
}

TEST(TagStereoRange, TheDepthOfASmallFarTagWithinHalfAPercent) {
  // 0.08 m at 1.6 m: ~31 px, as the cart tag in the stereo camera (one px of its size is 3 % of range).
  for (const auto& [z, yaw] : std::vector<std::pair<double, double>>{{1.6, 0}, {1.6, 25}, {1.2, -20}, {0.7, 10}}) {
    const Eigen::Isometry3d t = tag_at(0.1, -0.05, z, yaw);
    const Pair p = draw_pair(t);
    const TagStereoRange r = range_tag_in_stereo(p.left, p.right, p.corners, kFx, kCx, kCx, kBaseline, {});
    ASSERT_TRUE(r.ok) << r.reason;
    EXPECT_GT(r.score, 0.9);
    EXPECT_NEAR(r.depth_m, z, 0.005 * z) << "tag at " << z << " m, yaw " << yaw << " deg";
    EXPECT_NEAR(r.disparity_px, kFx * kBaseline / z, 0.005 * kFx * kBaseline / z);
  }
}

TEST(TagStereoRange, PrincipalPointsThatDifferAreAccountedFor) {
  // The right image's principal point 4 px further right: every right column moves 4 px; the depth must not.
  const Eigen::Isometry3d t = tag_at(0.0, 0.0, 1.5, 10);
  Pair p = draw_pair(t);
  cv::Mat moved;
  const cv::Mat by4 = (cv::Mat_<double>(2, 3) << 1, 0, 4, 0, 1, 0);
  cv::warpAffine(p.right, moved, by4, p.right.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  const TagStereoRange r = range_tag_in_stereo(p.left, moved, p.corners, kFx, kCx, kCx + 4, kBaseline, {});
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_NEAR(r.depth_m, 1.5, 0.0075);
}

TEST(TagStereoRange, SlidingThePoseToADepthKeepsItsRayAndOrientation) {
  const Eigen::Isometry3d t = tag_at(0.2, -0.1, 1.0, 30);
  const Eigen::Isometry3d s = tag_pose_at_depth(t, 1.5);
  EXPECT_NEAR(s.translation().z(), 1.5, 1e-12);
  EXPECT_NEAR(s.translation().normalized().dot(t.translation().normalized()), 1.0, 1e-12);
  EXPECT_TRUE(s.linear().isApprox(t.linear(), 1e-12));
}

TEST(TagStereoRange, ATagOutsideTheRightImageIsNamedSo) {
  // 0.7 m away, 87 px from the left image's left edge: the right camera (0.12 m to the right) sees it 107 px further
  // left, i.e. cut by its left border (far_cart's holder tag).
  const Pair p = draw_pair(tag_at(-0.26, 0.0, 0.7, 0));
  const TagStereoRange r = range_tag_in_stereo(p.left, p.right, p.corners, kFx, kCx, kCx, kBaseline, {}, 0.7);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("outside the right image: at its monocular depth 0.70 m"), std::string::npos) << r.reason;
  // Without the monocular depth the same failure is a poor match, as before.
  const TagStereoRange unknown = range_tag_in_stereo(p.left, p.right, p.corners, kFx, kCx, kCx, kBaseline, {});
  EXPECT_FALSE(unknown.ok);
  EXPECT_EQ(unknown.reason.find("outside the right image"), std::string::npos) << unknown.reason;
  // A tag well inside both images is ranged with its monocular depth given too.
  const Pair inside = draw_pair(tag_at(0.1, 0.0, 0.7, 0));
  EXPECT_TRUE(range_tag_in_stereo(inside.left, inside.right, inside.corners, kFx, kCx, kCx, kBaseline, {}, 0.7).ok);
}

TEST(TagStereoRange, InputsItCannotRangeAreRefusedWithAReason) {
  const Pair p = draw_pair(tag_at(0.0, 0.0, 1.6, 0));
  const TagStereoRangeParams d;
  // A right image that does not show the tag: the best match is poor.
  const TagStereoRange blank = range_tag_in_stereo(p.left, background(9), p.corners, kFx, kCx, kCx, kBaseline, d);
  EXPECT_FALSE(blank.ok);
  EXPECT_NE(blank.reason.find("min_score"), std::string::npos) << blank.reason;
  // Images of different sizes or types.
  cv::Mat half;
  cv::resize(p.right, half, cv::Size(320, 240));
  EXPECT_NE(range_tag_in_stereo(p.left, half, p.corners, kFx, kCx, kCx, kBaseline, d).reason.find("one size"),
            std::string::npos);
  // A patch partly outside the image, a corner that is NaN, no baseline.
  std::array<cv::Point2d, 4> edge = p.corners;
  for (auto& c : edge) c.x -= 300;
  EXPECT_NE(range_tag_in_stereo(p.left, p.right, edge, kFx, kCx, kCx, kBaseline, d).reason.find("leaves the image"),
            std::string::npos);
  std::array<cv::Point2d, 4> nan = p.corners;
  nan[2].y = std::nan("");
  EXPECT_NE(range_tag_in_stereo(p.left, p.right, nan, kFx, kCx, kCx, kBaseline, d).reason.find("non-finite"),
            std::string::npos);
  EXPECT_FALSE(range_tag_in_stereo(p.left, p.right, p.corners, kFx, kCx, kCx, 0.0, d).ok);
  // The same image twice: disparity 0 (a pair that is not one).
  const TagStereoRange same = range_tag_in_stereo(p.left, p.left, p.corners, kFx, kCx, kCx, kBaseline, d);
  EXPECT_FALSE(same.ok);
  EXPECT_NE(same.reason.find("not positive"), std::string::npos) << same.reason;
}

}  // namespace
}  // namespace bookgrasp
