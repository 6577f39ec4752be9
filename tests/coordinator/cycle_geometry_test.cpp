// Cycle geometry worked out by hand: the corner servo's standoff, the regrasp from the holder, and the lower-shelf
// pre-place that centres the planner's held-book box between the shelves.
#include "services/coordinator/cycle_geometry.h"

#include <gtest/gtest.h>

namespace bookgrasp {
namespace {

CycleGeometry geometry() {
  CycleGeometry g;
  g.bwh_start_z = -0.10;
  g.lower_drop = 0.32;
  g.lower_front_z = -0.03;
  g.insertion_depth = 0.03;
  g.place_clearance = 0.005;
  g.holder_regrasp_lower = 0.015;
  g.lower_pre_place_offset = Eigen::Vector3d(0.01, 0.0, -0.25);
  g.lower_shelf_gap = 0.30;
  g.held_top_above_tcp = 0.015;
  return g;
}

TEST(CycleGeometry, TheCornerServoStandoffReachesTheBooksFront) {
  const CycleGeometry g = geometry();
  EXPECT_NEAR(servo_standoff(0.012, g), 0.112, 1e-12);  // TCP at Z -0.10, front at +0.012
  EXPECT_NEAR(servo_standoff(0.0, g), 0.10, 1e-12);
  EXPECT_NEAR(servo_standoff(-0.5, g), 0.02, 1e-12);  // never closer than 2 cm
}

TEST(CycleGeometry, TheGraspFromTheHolderIsLowerAndTheBookHangsLessBelowTheTcp) {
  const CycleGeometry g = geometry();
  EXPECT_NEAR(holder_regrasp_height(0.25, g), 0.235, 1e-12);
  EXPECT_NEAR(height_held_from_holder(0.25, g), 0.24, 1e-12);  // the book dropped 5 mm onto the ledge
}

TEST(CycleGeometry, TheLowerPrePlaceCentresTheHeldBookBetweenTheShelves) {
  const CycleGeometry g = geometry();
  const Eigen::Isometry3d f = Eigen::Isometry3d::Identity();  // the grasp frame is base here
  for (const double box : {0.14, 0.20, 0.26}) {
    const double h = box - 0.01;  // held from the holder
    const Eigen::Isometry3d place = lower_place_pose(f, 0.2, 0.02, h, g);
    const Eigen::Isometry3d pre = lower_pre_place_pose(f, 0.2, 0.02, h, box, g);
    const double tcp_x = pre.translation().x(), place_x = place.translation().x();
    const double bottom = tcp_x + 0.015 - box, top = tcp_x + 0.015;
    // Equal room below (to the lower shelf at -0.32) and above (to the upper one's underside at -0.02).
    EXPECT_NEAR(bottom - (-0.32), -0.02 - top, 1e-9) << "box " << box;
    EXPECT_GE(tcp_x, place_x + 0.01 - 1e-12) << "box " << box;
    EXPECT_NEAR(pre.translation().z() - place.translation().z(), -0.25, 1e-12);  // Z offset as configured
  }
  // Without the gap only the configured offset.
  CycleGeometry plain = g;
  plain.lower_shelf_gap = 0;
  const Eigen::Isometry3d p0 = lower_place_pose(f, 0.2, 0.02, 0.19, plain);
  const Eigen::Isometry3d q0 = lower_pre_place_pose(f, 0.2, 0.02, 0.19, 0.20, plain);
  EXPECT_NEAR(q0.translation().x() - p0.translation().x(), 0.01, 1e-12);
}

}  // namespace
}  // namespace bookgrasp
