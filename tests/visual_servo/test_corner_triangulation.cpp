// triangulate_corner: exact and noisy rays against a known point, and every refusal with its reason.
#include "services/visual_servo/corner_triangulation.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace bookgrasp {
namespace {

CameraIntrinsics intrinsics() {
  CameraIntrinsics k;
  k.fx = k.fy = 433.0;
  k.cx = 319.5;
  k.cy = 239.5;
  return k;
}

/// A camera looking along base +x (optical z) from `centre`, optical x = base -y, optical y = base -z.
Eigen::Isometry3d camera_at(const Eigen::Vector3d& centre) {
  Eigen::Isometry3d c = Eigen::Isometry3d::Identity();
  c.linear().col(0) = -Eigen::Vector3d::UnitY();
  c.linear().col(1) = -Eigen::Vector3d::UnitZ();
  c.linear().col(2) = Eigen::Vector3d::UnitX();
  c.translation() = centre;
  return c;
}

CornerSighting sight(const Eigen::Vector3d& point, const Eigen::Vector3d& centre,
                     const Eigen::Vector2d& noise_px = Eigen::Vector2d::Zero()) {
  const CameraIntrinsics k = intrinsics();
  CornerSighting s;
  s.camera_in_base = camera_at(centre);
  const Eigen::Vector3d p = s.camera_in_base.inverse() * point;
  s.pixel = Eigen::Vector2d(k.fx * p.x() / p.z() + k.cx, k.fy * p.y() / p.z() + k.cy) + noise_px;
  return s;
}

const Eigen::Vector3d kCorner(0.70, -0.15, 0.42);

/// Views from centres 0.20 m in front of the corner, moving up by `span` in `n` steps.
std::vector<CornerSighting> upward_views(double span, int n, double noise_px = 0) {
  std::vector<CornerSighting> v;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d c(0.50, -0.15, 0.40 + span * i / (n - 1));
    const double sign = i % 2 ? 1.0 : -1.0;  // alternating noise: the worst case for a fixed amplitude
    v.push_back(sight(kCorner, c, Eigen::Vector2d(0.5 * sign * noise_px, sign * noise_px)));
  }
  return v;
}

TEST(CornerTriangulation, ExactRaysGiveThePoint) {
  std::string why;
  const auto t = triangulate_corner(upward_views(0.03, 10), intrinsics(), CornerTriangulationParams{}, &why);
  ASSERT_TRUE(t.has_value()) << why;
  EXPECT_LT((t->point - kCorner).norm(), 1e-9);
  EXPECT_NEAR(t->baseline_m, 0.03, 1e-12);
  EXPECT_EQ(t->sightings, 10);
  EXPECT_LT(t->rms_px, 1e-6);
  // A long servo's 200 views: 40 of them, evenly spread, still over the whole baseline.
  const auto many = triangulate_corner(upward_views(0.03, 200), intrinsics(), CornerTriangulationParams{}, &why);
  ASSERT_TRUE(many.has_value()) << why;
  EXPECT_EQ(many->sightings, 40);
  EXPECT_NEAR(many->baseline_m, 0.03, 1e-12);
  EXPECT_LT((many->point - kCorner).norm(), 1e-9);
}

TEST(CornerTriangulation, HalfAPixelOfNoiseOverThreeCentimetresStaysWithinAFewMillimetres) {
  // Depth error ~ Z^2 / (f B) per pixel: 0.2^2 / (433 * 0.03) = 3.1 mm for a pixel of disparity error; the
  // alternating +-0.5 px averages over 10 views, so well under that.
  std::string why;
  const auto t = triangulate_corner(upward_views(0.03, 10, 0.5), intrinsics(), CornerTriangulationParams{}, &why);
  ASSERT_TRUE(t.has_value()) << why;
  EXPECT_LT(std::abs(t->point.x() - kCorner.x()), 3e-3);
  EXPECT_LT((t->point - kCorner).tail<2>().norm(), 1e-3);
  EXPECT_GT(t->rms_px, 0.2);
}

TEST(CornerTriangulation, AViewOfAnotherPointIsDropped) {
  // R jumps 20 px in two views (a shadow edge taken for the top on the way): those views are dropped.
  std::vector<CornerSighting> jump = upward_views(0.03, 10);
  jump[2].pixel.y() += 20;
  jump[6].pixel.x() -= 25;
  std::string why;
  const auto t = triangulate_corner(jump, intrinsics(), CornerTriangulationParams{}, &why);
  ASSERT_TRUE(t.has_value()) << why;
  EXPECT_EQ(t->sightings, 8);
  EXPECT_LT((t->point - kCorner).norm(), 1e-9);
  EXPECT_EQ(t->agreeing, (std::vector<size_t>{0, 1, 3, 4, 5, 7, 8, 9}));  // the views that saw R here
  // Early views of a point far off put the least-squares point behind them: they are dropped too.
  std::vector<CornerSighting> far_off = upward_views(0.06, 12);
  for (int i = 0; i < 3; ++i) far_off[i].pixel = Eigen::Vector2d(20.0 + 10 * i, 470.0);
  const auto u = triangulate_corner(far_off, intrinsics(), CornerTriangulationParams{}, &why);
  ASSERT_TRUE(u.has_value()) << why;
  EXPECT_EQ(u->sightings, 9);
  EXPECT_LT((u->point - kCorner).norm(), 1e-9);
}

TEST(CornerTriangulation, RefusesWithAReason) {
  const CornerTriangulationParams p;
  auto refused = [&](const std::vector<CornerSighting>& v, const std::string& words) {
    std::string why;
    EXPECT_FALSE(triangulate_corner(v, intrinsics(), p, &why).has_value()) << words;
    EXPECT_NE(why.find(words), std::string::npos) << why;
  };
  refused(upward_views(0.03, 3), "3 sightings of R, need 4");
  refused(upward_views(0.01, 10), "moved 10.0 mm while seeing R, need 15.0 mm");
  // Half the views see another point 3 cm lower (two edges taken for R in turn): each half alone spans too little.
  std::vector<CornerSighting> two = upward_views(0.03, 10);
  for (int i = 5; i < 10; ++i)
    two[i] = sight(kCorner - Eigen::Vector3d(0, 0, 0.03), two[i].camera_in_base.translation());
  refused(two, "the 5 views of R that agree span 13.3 mm, need 15.0 mm");
  // Every ray points the same way from centres along it: parallel.
  std::vector<CornerSighting> parallel;
  for (int i = 0; i < 5; ++i) parallel.push_back(sight(kCorner, Eigen::Vector3d(0.30 + 0.01 * i, -0.15, 0.42)));
  refused(parallel, "parallel");
  // The same viewing lines from cameras turned round (180 deg about their y; v mirrored about cy keeps each
  // line): the lines meet at the corner, which is behind every camera.
  std::vector<CornerSighting> behind = upward_views(0.03, 10);
  for (CornerSighting& s : behind) {
    s.camera_in_base.linear() = s.camera_in_base.linear() * Eigen::Vector3d(-1, 1, -1).asDiagonal();
    s.pixel.y() = 2 * intrinsics().cy - s.pixel.y();
  }
  refused(behind, "behind the cameras");
}

}  // namespace
}  // namespace bookgrasp
