// Cycle geometry worked out by hand: the corner servo's standoff, the regrasp from the holder, and the lower-shelf
// pre-place that centres the planner's held-book box between the shelves.
#include "services/coordinator/cycle_geometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>

namespace bookgrasp {
namespace {

/// The default cart's grasp axes in base: X (up) = base z, Y (right) = -base y, Z (into the shelf) = base x.
Eigen::Matrix3d grasp_axes() {
  Eigen::Matrix3d r;
  r.col(0) = Eigen::Vector3d(0, 0, 1);
  r.col(1) = Eigen::Vector3d(0, -1, 0);
  r.col(2) = Eigen::Vector3d(1, 0, 0);
  return r;
}

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

TEST(CycleGeometry, AMeasuredForeEdgeNarrowsThePlatesOnTheLeftOnly) {
  CycleGeometry g;
  g.grasp_offset_y = -0.015;  // full 6 cm opening: right plate 15 mm right of GP, left plate 45 mm left of it
  g.width_left_clearance = 0.008;
  // A 12 mm fore-edge: the left plate's inner face 8 mm left of the book, the right one where it was.
  const PlateOpening narrow = plate_opening({0.012, 0, 0}, 0.06, g);
  EXPECT_NEAR(narrow.width, 0.035, 1e-12);
  EXPECT_NEAR(narrow.offset_y + 0.5 * narrow.width, 0.015, 1e-12);   // right plate
  EXPECT_NEAR(narrow.offset_y - 0.5 * narrow.width, -0.020, 1e-12);  // left plate: 12 + 8 mm left of GP
  // Not measured (0, NaN, negative), switched off, or a book that needs the full opening: the paper's full opening.
  for (const double w : {0.0, double(NAN), -0.01, 0.040}) {
    const PlateOpening full = plate_opening({w, 0, 0}, 0.06, g);
    EXPECT_EQ(full.width, 0.06) << w;
    EXPECT_EQ(full.offset_y, -0.015) << w;
  }
  CycleGeometry off = g;
  off.width_left_clearance = 0.0;
  EXPECT_EQ(plate_opening({0.012, 0, 0}, 0.06, off).width, 0.06);
  // A measured neighbour changes nothing while left_plate_on_neighbour is off.
  EXPECT_NEAR(plate_opening({0.012, 0.019, 0.020}, 0.06, g).width, 0.035, 1e-12);
}

TEST(CycleGeometry, TheLeftPlateGoesToTheNeighboursMiddle) {
  CycleGeometry g;
  g.grasp_offset_y = -0.015;  // right plate 15 mm right of GP
  g.left_plate_on_neighbour = true;
  g.plate_thickness = 0.010;
  g.left_plate_min_clearance = 0.003;
  // Far_cart seed 1's second book: 17.7 mm, a 7 mm gap, then a 20 mm book whose middle lies 34.7 mm left of R. The
  // full opening put the left plate 45-55 mm left of GP, beyond that book, which then stood between the plates.
  const PlateOpening o = plate_opening({0.0177, 0.0247, 0.020}, 0.06, g);
  const double left_inner = -(o.offset_y - 0.5 * o.width);
  EXPECT_NEAR(left_inner, 0.0347 - 0.005, 1e-12);         // the plate's middle on the neighbour's middle
  EXPECT_NEAR(o.offset_y + 0.5 * o.width, 0.015, 1e-12);  // the right plate where it was
  // A thin neighbour right against the book: the plate keeps its clearance off the book itself.
  const PlateOpening thin = plate_opening({0.020, 0.021, 0.006}, 0.06, g);
  EXPECT_NEAR(-(thin.offset_y - 0.5 * thin.width), 0.023, 1e-12);
  // No neighbour seen: the width rule, here off, so the full opening; a neighbour beyond the full opening: full.
  EXPECT_EQ(plate_opening({0.0177, 0.0, 0.0}, 0.06, g).width, 0.06);
  EXPECT_EQ(plate_opening({0.0177, 0.040, 0.020}, 0.06, g).width, 0.06);
  g.width_left_clearance = 0.008;
  EXPECT_NEAR(plate_opening({0.0177, 0.0, 0.0}, 0.06, g).width, 0.015 + 0.0177 + 0.008, 1e-12);
  // No fore-edge width: nothing to keep the plate off the book, the full opening.
  EXPECT_EQ(plate_opening({0.0, 0.0247, 0.020}, 0.06, g).width, 0.06);
}

TEST(CycleGeometry, ABookNearTheRightSidePanelMovesPlatesAndPalmLeft) {
  CycleGeometry g;
  g.shelf_right_y = 0.40;
  g.grasp_offset_y = -0.015;  // full 6 cm opening: right plate 15 mm right of GP
  g.palm_half_width = 0.057;
  g.right_panel_clearance = 0.005;
  g.right_plate_min_clearance = 0.003;
  const PlateOpening full{0.06, -0.015};
  // Far from the panel: the palm's right side at 300 - 15 + 57 = 342 mm, 58 mm from it. Unchanged.
  EXPECT_LE(palm_over_right_panel(full, 0.30, g), 0.0);
  EXPECT_EQ(plate_opening_clear_of_right_panel(full, 0.30, 0.06, g).offset_y, -0.015);
  // Far_cart seed 5022's GP, 359.6 mm: the palm's right side at 401.6 mm, 1.6 mm into the panel (+ 5 mm clearance).
  EXPECT_NEAR(palm_over_right_panel(full, 0.3596, g), 0.0066, 1e-12);
  const PlateOpening moved = plate_opening_clear_of_right_panel(full, 0.3596, 0.06, g);
  EXPECT_EQ(moved.width, 0.06);
  EXPECT_NEAR(moved.offset_y, -0.0216, 1e-12);
  EXPECT_NEAR(0.3596 + moved.offset_y + 0.057, 0.395, 1e-12);      // the palm 5 mm from the panel
  EXPECT_NEAR(moved.offset_y + 0.5 * moved.width, 0.0084, 1e-12);  // the right plate 8.4 mm right of the book
  EXPECT_LE(palm_over_right_panel(moved, 0.3596, g), 1e-12);
  // Nearer still (375 mm): the right plate stops 3 mm right of the book; the palm still comes 10 mm too near.
  const PlateOpening limited = plate_opening_clear_of_right_panel(full, 0.375, 0.06, g);
  EXPECT_NEAR(limited.offset_y + 0.5 * limited.width, 0.003, 1e-12);
  EXPECT_NEAR(palm_over_right_panel(limited, 0.375, g), 0.010, 1e-12);
  // A narrowed opening (40 mm, right plate 15 mm right of GP, as for a 20 mm book + 5 mm) at seed 5022's GP: moved
  // alone, its right plate would stop 3 mm right of the book with the palm 4.6 mm into the 5 mm clearance (5022
  // ABORTED in INSERT with the narrow opening, stop 30). It opens further on the left instead, to where the full
  // opening's move puts the palm: 5 mm from the panel, the right plate 3 mm right of the book.
  const PlateOpening narrowed{0.040, -0.005};
  const PlateOpening narrow = plate_opening_clear_of_right_panel(narrowed, 0.3596, 0.06, g);
  EXPECT_NEAR(narrow.offset_y, -0.0216, 1e-12);
  EXPECT_NEAR(narrow.offset_y + 0.5 * narrow.width, 0.003, 1e-12);
  EXPECT_NEAR(narrow.width, 0.0492, 1e-12);
  EXPECT_LE(palm_over_right_panel(narrow, 0.3596, g), 1e-12);
  // Never wider than the gripper opens: at 375 mm it is the full opening's limited move.
  const PlateOpening narrow_limited = plate_opening_clear_of_right_panel(narrowed, 0.375, 0.06, g);
  EXPECT_NEAR(narrow_limited.width, 0.06, 1e-12);
  EXPECT_NEAR(narrow_limited.offset_y, limited.offset_y, 1e-12);
  // A narrowed opening that its own move clears stays as narrow: 10 mm nearer the middle of the shelf.
  const PlateOpening near = plate_opening_clear_of_right_panel(narrowed, 0.3496, 0.06, g);
  EXPECT_NEAR(near.width, 0.040, 1e-12);
  EXPECT_LE(palm_over_right_panel(near, 0.3496, g), 1e-12);
  // Off (palm width 0), or no GP known: unchanged.
  for (const double gp_y : {0.3596, double(NAN)}) {
    CycleGeometry off = g;
    if (std::isfinite(gp_y)) off.palm_half_width = 0.0;
    EXPECT_EQ(plate_opening_clear_of_right_panel(full, gp_y, 0.06, off).offset_y, -0.015) << gp_y;
    EXPECT_EQ(palm_over_right_panel(full, gp_y, off), 0.0) << gp_y;
  }
}

TEST(CycleGeometry, ABookNearTheRightSidePanelIsGraspedLessDeepWithThePalmInFrontOfIt) {
  // coordinator.yaml's values: the palm's face 30.9 mm behind the TCP, the panels' front edge at grasp Z 0.
  CycleGeometry g;
  g.shelf_right_y = 0.40;
  g.grasp_offset_y = -0.015;
  g.insertion_depth = 0.03;
  g.palm_half_width = 0.057;
  g.right_panel_clearance = 0.005;
  g.right_plate_min_clearance = 0.003;
  g.plate_thickness = 0.010;
  g.palm_behind_tcp = 0.0309;
  g.min_insertion_depth = 0.005;
  g.side_panel_front_z = 0.0;
  const PlateOpening full{0.06, -0.015};
  const auto expect_unchanged = [&](const PlateGrasp& p, const std::string& what) {
    EXPECT_EQ(p.opening.width, 0.06) << what;
    EXPECT_EQ(p.opening.offset_y, -0.015) << what;
    EXPECT_EQ(p.insertion_depth, 0.03) << what;
  };
  // Far from the panel: the opening and the full insertion.
  expect_unchanged(plate_grasp_clear_of_right_panel(full, Eigen::Vector3d(0.2, 0.30, 0.01), 0.06, g), "far");
  // Far_cart seed 5076's GPs (a 10 mm book, 40 mm from the panel). The fore-edge 3.2 mm deep: the TCP 22.7 mm beyond
  // it puts the palm's face 5 mm in front of the panel; the plates stay where they were.
  const PlateGrasp shallow = plate_grasp_clear_of_right_panel(full, Eigen::Vector3d(0.166, 0.3605, 0.0032), 0.06, g);
  EXPECT_NEAR(shallow.insertion_depth, 0.0227, 1e-12);
  EXPECT_NEAR(0.0032 + shallow.insertion_depth - g.palm_behind_tcp, -0.005, 1e-12);
  EXPECT_EQ(shallow.opening.offset_y, -0.015);
  EXPECT_EQ(shallow.opening.width, 0.06);
  // 18.4 mm deep: 7.5 mm, still over min_insertion_depth_m.
  EXPECT_NEAR(plate_grasp_clear_of_right_panel(full, Eigen::Vector3d(0.166, 0.363, 0.0184), 0.06, g).insertion_depth,
              0.0075, 1e-12);
  // A front standing out of the shelf: the palm is in front of the panel at the full insertion.
  expect_unchanged(plate_grasp_clear_of_right_panel(full, Eigen::Vector3d(0.2, 0.3605, -0.02), 0.06, g), "out");
  // Too deep for min_insertion_depth (24 mm: 1.9 mm), the right plate itself too near the panel (GP at 375 mm: its
  // outer face at 395 mm + 10 mm), the palm's depth unknown (0) or no GP depth: the plates and palm move left, as
  // plate_opening_clear_of_right_panel moves them, at the full insertion.
  CycleGeometry no_depth = g;
  no_depth.palm_behind_tcp = 0.0;
  for (const auto& [gp, geometry] :
       {std::pair{Eigen::Vector3d(0.2, 0.3605, 0.024), g}, std::pair{Eigen::Vector3d(0.2, 0.375, 0.003), g},
        std::pair{Eigen::Vector3d(0.2, 0.3605, 0.003), no_depth},
        std::pair{Eigen::Vector3d(0.2, 0.3605, double(NAN)), g}}) {
    const PlateGrasp p = plate_grasp_clear_of_right_panel(full, gp, 0.06, geometry);
    const PlateOpening moved = plate_opening_clear_of_right_panel(full, gp.y(), 0.06, geometry);
    EXPECT_EQ(p.insertion_depth, 0.03) << gp.transpose();
    EXPECT_EQ(p.opening.offset_y, moved.offset_y) << gp.transpose();
    EXPECT_EQ(p.opening.width, moved.width) << gp.transpose();
    EXPECT_LT(p.opening.offset_y, -0.015) << gp.transpose();
  }
}

TEST(CycleGeometry, TheCornerServoStandoffReachesTheBooksFront) {
  const CycleGeometry g = geometry();
  EXPECT_NEAR(servo_standoff(0.012, g), 0.112, 1e-12);  // TCP at Z -0.10, front at +0.012
  EXPECT_NEAR(servo_standoff(0.0, g), 0.10, 1e-12);
  EXPECT_NEAR(servo_standoff(-0.5, g), 0.02, 1e-12);  // never closer than 2 cm
}

TEST(CycleGeometry, APushedBackFrontKeepsThePreGraspInFrontOfTheShelf) {
  CycleGeometry g = geometry();
  g.pre_grasp_distance = 0.09;
  g.deep_front_z = 0.035;
  g.grasp_offset_x = -0.01;
  g.grasp_offset_y = 0.015;
  // GP frame rotated: its z (into the shelf) along base +x, its x (up) along base +z.
  Eigen::Isometry3d gp = Eigen::Isometry3d::Identity();
  gp.linear() = grasp_axes();
  gp.translation() = Eigen::Vector3d(0.80, -0.20, 0.20);
  // A front at 2 cm: 9 cm straight back along -z, offsets along x (up) and y.
  const Eigen::Vector3d usual = pre_grasp_pose(gp, 0.02, g).translation();
  EXPECT_NEAR(usual.x(), 0.80 - 0.09, 1e-12);
  EXPECT_NEAR(usual.y(), -0.20 - 0.015, 1e-12);
  EXPECT_NEAR(usual.z(), 0.20 - 0.01, 1e-12);
  // At the limit nothing changes; a front pushed back to 9 cm keeps the pre-grasp of a front at 3.5 cm.
  EXPECT_NEAR(pre_grasp_pose(gp, 0.035, g).translation().x(), 0.80 - 0.09, 1e-12);
  gp.translation().x() = 0.80 + 0.055;  // GP 5.5 cm deeper: Z 0.09
  const Eigen::Isometry3d deep = pre_grasp_pose(gp, 0.09, g);
  EXPECT_NEAR(deep.translation().x(), 0.80 + 0.055 - 0.09 - 0.055, 1e-12);
  EXPECT_TRUE(deep.linear().isApprox(gp.linear()));
  // The extraction ends where it ends for a front at the limit too.
  EXPECT_NEAR(moves_front_z(0.09, g), 0.035, 1e-12);
  EXPECT_NEAR(moves_front_z(0.012, g), 0.012, 1e-12);
}

TEST(CycleGeometry, TheGraspFromTheHolderIsLowerAndTheBookHangsLessBelowTheTcp) {
  const CycleGeometry g = geometry();
  EXPECT_NEAR(holder_regrasp_height(0.25, g), 0.235, 1e-12);
  EXPECT_NEAR(height_held_from_holder(0.25, g), 0.24, 1e-12);  // the book dropped 5 mm onto the ledge
}

TEST(CycleGeometry, AShortBooksGraspFromTheHolderStaysHighEnoughForTheLowerShelf) {
  CycleGeometry g = geometry();
  g.holder_regrasp_min_height = 0.15;
  // A tall book: the full 15 mm lower.
  EXPECT_NEAR(holder_regrasp_height(0.25, g), 0.235, 1e-12);
  // 0.16 m: lowered only to 0.15.
  EXPECT_NEAR(holder_regrasp_height(0.16, g), 0.15, 1e-12);
  EXPECT_NEAR(height_held_from_holder(0.16, g), 0.155, 1e-12);
  // A 0.13 m release (a 0.143 m book): not lowered at all, and never above where it was released.
  EXPECT_NEAR(holder_regrasp_height(0.13, g), 0.13, 1e-12);
  // The place on the lower shelf is then 15 mm higher than with the full lowering.
  const Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  CycleGeometry full = g;
  full.holder_regrasp_min_height = 0.0;
  EXPECT_NEAR(lower_place_pose(f, 0.1, 0.02, height_held_from_holder(0.13, g), g).translation().x() -
                  lower_place_pose(f, 0.1, 0.02, height_held_from_holder(0.13, full), full).translation().x(),
              0.015, 1e-12);
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

TEST(CycleGeometry, ExtractEndsAtTheSameHeightAndDepthWhereverItStarts) {
  CycleGeometry g = geometry();
  g.extract_lift = 0.34;
  g.extract_retreat = 0.02;
  // The grasp frame: X = base z, Y = -base y, Z = base x (as the default cart), origin (0.6, -0.05, 0).
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.linear() = grasp_axes();
  f.translation() = Eigen::Vector3d(0.6, -0.05, 0.0);
  const double tcp_height = 0.20, grasp_z = 0.04;  // TCP at grasp X 0.20, Z 0.04 when it closed
  Eigen::Isometry3d at_grasp = f;
  at_grasp.translation() = f * Eigen::Vector3d(tcp_height, 0.1, grasp_z);
  const auto first = extract_moves(at_grasp, f, tcp_height, grasp_z, g);
  ASSERT_EQ(first.size(), 2u);
  const Eigen::Vector3d lifted = f.inverse() * first[0].translation(), out = f.inverse() * first[1].translation();
  EXPECT_NEAR(lifted.x(), 0.54, 1e-12);  // 0.20 + 0.34
  EXPECT_NEAR(lifted.z(), 0.04, 1e-12);
  EXPECT_NEAR(out.x(), 0.54, 1e-12);
  EXPECT_NEAR(out.z(), 0.02, 1e-12);  // 2 cm out
  // Resumed half-way up (0.37), or after the lift and part of the retreat: the same end, nothing beyond it.
  Eigen::Isometry3d half = at_grasp;
  half.translation() = f * Eigen::Vector3d(0.37, 0.1, grasp_z);
  EXPECT_TRUE(extract_moves(half, f, tcp_height, grasp_z, g)[1].translation().isApprox(first[1].translation(), 1e-12));
  Eigen::Isometry3d part_out = at_grasp;
  part_out.translation() = f * Eigen::Vector3d(0.54, 0.1, 0.03);
  const auto again = extract_moves(part_out, f, tcp_height, grasp_z, g);
  EXPECT_TRUE(again[0].translation().isApprox(part_out.translation(), 1e-12));  // no further lift
  EXPECT_TRUE(again[1].translation().isApprox(first[1].translation(), 1e-12));
  // A gripper tilted 10 deg about the grasp Z (a leaning book) still ends 0.34 m above the grasp.
  Eigen::Isometry3d tilted = at_grasp;
  tilted.linear() = f.linear() * Eigen::AngleAxisd(10.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_NEAR((f.inverse() * extract_moves(tilted, f, tcp_height, grasp_z, g)[0].translation()).x(), 0.54, 1e-12);
}

TEST(CycleGeometry, TheNextLowerShelfSlotIsLeftOfTheBookAndTheGap) {
  CycleGeometry g = geometry();
  g.lower_gap = 0.003;
  EXPECT_NEAR(next_lower_right_y(0.10, 0.02, g), 0.077, 1e-12);  // grasp Y grows to the right
}

// A 20 mm book 0.25 m tall with its right cover at grasp Y 0.10 on the default cart (origin (0.6, -0.05, 0)): it
// stands on the lower shelf (grasp X -0.32 .. -0.07), covers Y 0.08 .. 0.10, fore-edge on Z -0.03, 0.30 deep.
TEST(CycleGeometry, ABookOnTheLowerShelfIsABoxFromItsCoversShelfAndForeEdge) {
  const CycleGeometry g = geometry();
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.linear() = grasp_axes();
  f.translation() = Eigen::Vector3d(0.6, -0.05, 0.0);
  const OrientedBox b = lower_shelf_book_box(f, 0.10, 0.02, 0.25, 0.30, g);
  // Centre in grasp (-0.195, 0.09, 0.12) -> base (0.6 + 0.12, -0.05 - 0.09, -0.195).
  EXPECT_TRUE(b.pose.translation().isApprox(Eigen::Vector3d(0.72, -0.14, -0.195), 1e-12)) << b.pose.translation();
  EXPECT_TRUE(b.pose.linear().isApprox(grasp_axes(), 1e-12));
  EXPECT_TRUE(b.size.isApprox(Eigen::Vector3d(0.25, 0.02, 0.30), 1e-12)) << b.size;
  // Its right cover is where the place pose puts the held book's: TCP Y - BW / 2 ... the box's Y extent.
  const Eigen::Vector3d tcp = f.inverse() * lower_place_pose(f, 0.10, 0.02, 0.24, g).translation();
  const Eigen::Vector3d centre = f.inverse() * b.pose.translation();
  EXPECT_NEAR(tcp.y(), centre.y(), 1e-12);
}

TEST(CycleGeometry, TheReleaseOnTheLowerShelfOpensThePlatesOnlyAFewMillimetresOverTheBook) {
  CycleGeometry g = geometry();
  g.lower_release_opening = 0.006;
  EXPECT_NEAR(lower_release_width(0.021, g), 0.027, 1e-12);
  g.lower_release_opening = 0.0;
  EXPECT_EQ(lower_release_width(0.021, g), 0.0) << "0: the gripper's full opening";
}

TEST(CycleGeometry, ADiagonalLiftEndsOutAndUpInOneLineAndTheRetreatStaysWithin) {
  CycleGeometry g = geometry();
  g.extract_lift = 0.34;
  g.extract_lift_out = 0.10;
  g.extract_retreat = 0.02;
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  f.linear() = grasp_axes();
  f.translation() = Eigen::Vector3d(0.8, -0.05, 0.0);
  const double tcp_height = 0.25, grasp_z = 0.05;
  Eigen::Isometry3d at_grasp = f;
  at_grasp.translation() = f * Eigen::Vector3d(tcp_height, -0.3, grasp_z);
  const auto moves = extract_moves(at_grasp, f, tcp_height, grasp_z, g);
  ASSERT_EQ(moves.size(), 2u);
  const Eigen::Vector3d lifted = f.inverse() * moves[0].translation(), end = f.inverse() * moves[1].translation();
  EXPECT_NEAR(lifted.x(), 0.59, 1e-12);   // 0.25 + 0.34
  EXPECT_NEAR(lifted.y(), -0.3, 1e-12);   // never sideways
  EXPECT_NEAR(lifted.z(), -0.05, 1e-12);  // 0.10 out of 0.05
  // The retreat (2 cm) is within the diagonal's 10 cm: it goes nowhere.
  EXPECT_TRUE(end.isApprox(lifted, 1e-12));
  EXPECT_TRUE(moves[0].linear().isApprox(at_grasp.linear(), 1e-12));  // the orientation is kept
  // Resumed half-way along the diagonal: the same end.
  Eigen::Isometry3d half = at_grasp;
  half.translation() = f * Eigen::Vector3d(0.42, -0.3, 0.0);
  EXPECT_TRUE(extract_moves(half, f, tcp_height, grasp_z, g)[0].translation().isApprox(moves[0].translation(), 1e-12));
  // A retreat longer than the diagonal's way out goes on from the lift's end.
  g.extract_retreat = 0.15;
  const Eigen::Vector3d further = f.inverse() * extract_moves(at_grasp, f, tcp_height, grasp_z, g)[1].translation();
  EXPECT_NEAR(further.x(), 0.59, 1e-12);
  EXPECT_NEAR(further.z(), -0.10, 1e-12);
}

TEST(CycleGeometry, AForeEdgeTouchingTheNextIsOnePageFace) {
  CycleGeometry g;
  g.split_fore_edge_gap = 0.0005;
  // Seed 5050: 19.7 mm, and the next fore-edge 19.7 mm left of R, 8.6 mm wide: one 28.3 mm fore-edge, none beyond.
  const ForeEdges joined = join_split_fore_edge({0.0197, 0.0197, 0.0086}, g);
  EXPECT_NEAR(joined.front_width, 0.0283, 1e-12);
  EXPECT_EQ(joined.neighbour_offset, 0.0);
  EXPECT_EQ(joined.neighbour_width, 0.0);
  EXPECT_NEAR(join_split_fore_edge({0.0197, 0.0201, 0.0086}, g).front_width, 0.0287, 1e-12);  // 0.4 mm apart
  // Two books: both covers between their page faces (the nearest seen, 1.5 mm), or just over the key.
  for (const double gap : {0.0015, 0.0006}) {
    const ForeEdges two{0.0197, 0.0197 + gap, 0.0086};
    const ForeEdges kept = join_split_fore_edge(two, g);
    EXPECT_EQ(kept.front_width, two.front_width) << gap;
    EXPECT_EQ(kept.neighbour_offset, two.neighbour_offset) << gap;
    EXPECT_EQ(kept.neighbour_width, two.neighbour_width) << gap;
  }
  // Nothing to join: no next fore-edge, no width, the key 0.
  EXPECT_EQ(join_split_fore_edge({0.0197, 0.0, 0.0}, g).front_width, 0.0197);
  EXPECT_EQ(join_split_fore_edge({0.0, 0.0197, 0.0086}, g).front_width, 0.0);
  EXPECT_EQ(join_split_fore_edge({std::nan(""), 0.0197, 0.0086}, g).neighbour_width, 0.0086);
  g.split_fore_edge_gap = 0.0;
  EXPECT_EQ(join_split_fore_edge({0.0197, 0.0197, 0.0086}, g).front_width, 0.0197);
}

}  // namespace
}  // namespace bookgrasp
