// front_depth_left_of: which BwS region is the target's front just left of PS, and its depth.

#include "services/arbiter/stereo_front_depth.h"

#include <gtest/gtest.h>

#include <cmath>

namespace bookgrasp {
namespace {

using V = Eigen::Vector3d;

/// A region of the plane z = depth (normal +Z) covering [y0, y1] x [x0, x1].
FrontPlane front(double depth, double y0, double y1, double x0 = 0.0, double x1 = 0.20, int pixels = 400) {
  FrontPlane p;
  p.normal = V(0, 0, 1);
  p.offset = depth;
  p.min = V(x0, y0, depth);
  p.max = V(x1, y1, depth);
  p.pixels = pixels;
  return p;
}

const V kPs(-0.07, 0.150, -0.07);  // PS: on the stripe, the target's right edge at Y = 0.150

TEST(StereoFrontDepth, TheFrontJustLeftOfPsGivesItsDepth) {
  // The target (pushed 7 cm back) spans Y 0.128..0.151; its left neighbour stands at the shelf's edge.
  const std::vector<FrontPlane> planes = {front(0.01, 0.100, 0.127), front(0.08, 0.128, 0.151)};
  const auto z = front_depth_left_of(planes, kPs, StereoFrontProbe{});
  ASSERT_TRUE(z.has_value());
  EXPECT_DOUBLE_EQ(*z, 0.08);
}

TEST(StereoFrontDepth, ATiltedPlaneIsEvaluatedAtTheProbe) {
  // Normal turned 10 degrees about X: z = (offset - ny * y) / nz at the band's middle, Y = 0.144.
  FrontPlane p = front(0.0, 0.128, 0.151);
  const double a = 10.0 * M_PI / 180.0;
  p.normal = V(0, std::sin(a), std::cos(a));
  p.offset = std::sin(a) * 0.144 + std::cos(a) * 0.05;  // passes through (x, 0.144, 0.05)
  const auto z = front_depth_left_of({p}, kPs, StereoFrontProbe{});
  ASSERT_TRUE(z.has_value());
  EXPECT_NEAR(*z, 0.05, 1e-12);
}

TEST(StereoFrontDepth, CoversShelfEdgesAndFarPlanesAreNotFronts) {
  FrontPlane cover = front(0.05, 0.128, 0.151);
  cover.normal = V(0, 1, 0);  // a book's side: normal along Y
  const FrontPlane shelf_edge = front(0.0, 0.0, 0.3, -0.03, 0.0);  // below the shelf's surface
  const FrontPlane rear_board = front(0.36, -0.4, 0.4);             // beyond max_z
  const FrontPlane right_of_ps = front(0.08, 0.152, 0.180);         // the book already taken was there
  EXPECT_FALSE(front_depth_left_of({cover, shelf_edge, rear_board, right_of_ps}, kPs, StereoFrontProbe{}));
}

TEST(StereoFrontDepth, TheLargestQualifyingRegionWins) {
  const std::vector<FrontPlane> planes = {front(0.03, 0.140, 0.146, 0.10, 0.20, 30),
                                          front(0.09, 0.128, 0.151, 0.0, 0.20, 900)};
  EXPECT_DOUBLE_EQ(*front_depth_left_of(planes, kPs, StereoFrontProbe{}), 0.09);
}

TEST(StereoFrontDepth, BadInputsGiveNothing) {
  FrontPlane nan_plane = front(0.08, 0.128, 0.151);
  nan_plane.offset = NAN;
  EXPECT_FALSE(front_depth_left_of({nan_plane}, kPs, StereoFrontProbe{}));
  EXPECT_FALSE(front_depth_left_of({front(0.08, 0.128, 0.151)}, V(NAN, 0.15, 0), StereoFrontProbe{}));
  FrontPlane zero_normal = front(0.08, 0.128, 0.151);
  zero_normal.normal = V::Zero();
  EXPECT_FALSE(front_depth_left_of({zero_normal}, kPs, StereoFrontProbe{}));
}

}  // namespace
}  // namespace bookgrasp
