// The arbiter node composed on memq:// with hand-made messages. Every expected number is worked out by
// hand below from the geometry of the default scene, not taken from the code.
//
// Cart marker (AprilTag frame: x right as seen from the robot, y down, z into the board) at base
// (0.959, 0.15, 0.37), facing the robot: x_t = -y_base, y_t = -z_base, z_t = +x_base. With
// grasp_origin_in_marker_m = (-0.37, 0.20, -0.359) the grasp frame is X = +z_base, Y = -y_base,
// Z = +x_base, origin (0.60, -0.05, 0.0) (the cart origin of config/scenes/default.yaml), so
//     p_grasp = (z_b, -(y_b + 0.05), x_b - 0.60)   and   p_base = (0.60 + Z, -0.05 - Y, X).
#include "services/arbiter/arbiter_node.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "common/composition.h"
#include "common/config.h"
#include "common/pose_conversion.h"
#include "common/service_host.h"

namespace bookgrasp {
namespace {

constexpr double kTol = 1e-9;

template <typename Msg>
struct Collector {
  std::vector<Msg> got;
  void on(const lcm::ReceiveBuffer*, const std::string&, const Msg* m) { got.push_back(*m); }
};

Config arbiter_config() {
  return Config::load_file(std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/arbiter.yaml");
}

Eigen::Matrix3d grasp_rotation() {
  Eigen::Matrix3d r;
  r.col(0) = Eigen::Vector3d(0, 0, 1);   // X up
  r.col(1) = Eigen::Vector3d(0, -1, 0);  // Y right
  r.col(2) = Eigen::Vector3d(1, 0, 0);   // Z into the shelf
  return r;
}

marker_detections_t markers(int64_t utime) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear().col(0) = Eigen::Vector3d(0, -1, 0);
  t.linear().col(1) = Eigen::Vector3d(0, 0, -1);
  t.linear().col(2) = Eigen::Vector3d(1, 0, 0);
  t.translation() = Eigen::Vector3d(0.959, 0.15, 0.37);
  marker_t m;
  m.utime = utime;
  m.family = "tag36h11";
  m.id = 0;
  m.role = "cart";
  m.pose_in_base = isometry_to_pose(t, "base", "cart", utime);
  m.pose_in_camera = m.pose_in_base;
  marker_detections_t d;
  d.utime = utime;
  d.implementation = "apriltag3";
  d.camera_frame = "stereo_left";
  d.markers = {m};
  d.num_markers = 1;
  return d;
}

book_corner_stereo_t corner(int64_t utime, const std::string& impl, bool found, Eigen::Vector3d p1_base) {
  book_corner_stereo_t c;
  c.utime = utime;
  c.implementation = impl;
  c.found = found;
  c.failure_reason = found ? "" : "no candidate";
  for (int i = 0; i < 3; ++i) {
    c.p1_base[i] = p1_base[i];
    c.p1_grasp[i] = 0;
  }
  c.num_regions = 0;
  return c;
}

servo_request_t request(int64_t utime, int64_t id, int8_t mode, int rank = 0) {
  servo_request_t r;
  r.utime = utime;
  r.request_id = id;
  r.mode = mode;
  r.start_pose = isometry_to_pose(Eigen::Isometry3d::Identity(), "base", "gripper", utime);
  r.rank_from_right = rank;
  r.timeout_s = 10;
  return r;
}

servo_status_t status(int64_t utime, int64_t id, int8_t mode, int8_t state, Eigen::Vector3d pos_base,
                      double slope = 0.0) {
  servo_status_t s{};  // every field zero: no triangulated corner, no widths
  s.utime = utime;
  s.request_id = id;
  s.mode = mode;
  s.state = state;
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = grasp_rotation() * Eigen::AngleAxisd(slope, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  t.translation() = pos_base;
  s.converged_pose = isometry_to_pose(t, "base", "gripper", utime);
  return s;
}

arm_state_t arm(int64_t utime, double width, bool contact, bool executing = false) {
  arm_state_t a{};
  a.utime = utime;
  a.num_joints = 0;
  a.end_effector = isometry_to_pose(Eigen::Isometry3d::Identity(), "base", "gripper", utime);
  a.gripper_width_m = width;
  a.gripper_contact = contact;
  a.state = executing ? arm_state_t::EXECUTING : arm_state_t::IDLE;
  return a;
}

void expect_vec(const double (&v)[3], const Eigen::Vector3d& want, const char* what) {
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(v[i], want[i], kTol) << what << "[" << i << "]";
}

bool starts_with(const std::string& s, const std::string& p) { return s.rfind(p, 0) == 0; }

class ArbiterNodeTest : public testing::Test {
 protected:
  ArbiterNodeTest() {
    node = &comp.add(std::make_unique<ArbiterNode>(arbiter_config()));
    comp.bus().subscribe("GRASP_POINT", &Collector<grasp_point_t>::on, &out);
  }
  template <typename Msg>
  void send(const std::string& channel, const Msg& m) {
    comp.bus().publish(channel, &m);
    comp.spin();
  }
  /// Markers, a P1 of `god` and a converged stripe servo giving PS.
  void first_run(const Eigen::Vector3d& p1_base, const Eigen::Vector3d& ps_base) {
    send("MARKERS", markers(1000));
    send("BOOK_CORNER_STEREO", corner(2000, "god", true, p1_base));
    send("SERVO_REQUEST", request(3000, 1, servo_request_t::STRIPE_END));
    send("SERVO_STATUS", status(4000, 1, servo_request_t::STRIPE_END, servo_status_t::CONVERGED, ps_base));
  }
  /// The first run with P1 59 mm right of the measured PS (P1 base y -0.364 -> grasp 0.314, PS.y 0.255): P1 stays
  /// invalid and BwH starts from it, the second message.
  void first_run_p1_right_of_ps() {
    first_run({0.61, -0.364, 0.25}, {0.45, -0.305, 0.10});
    ASSERT_EQ(out.got.size(), 2u);
    EXPECT_TRUE(starts_with(out.got[1].reason, "P1_INVALID: P1 invalid (59.0 mm right of the measured stripe end"))
        << out.got[1].reason;
    EXPECT_FALSE(out.got[1].p1_used);
    expect_vec(out.got[1].gp_grasp, {0.25, 0.314, 0.01}, "BwH start = P1, front depth");
  }
  /// A BOOK_CORNER servo request `id` of BwH rank `rank` at `t`, converged 1 ms later with the TCP at `tcp_base`.
  void corner_converged(int64_t t, int64_t id, int rank, const Eigen::Vector3d& tcp_base) {
    send("SERVO_REQUEST", request(t, id, servo_request_t::BOOK_CORNER, rank));
    send("SERVO_STATUS", status(t + 1000, id, servo_request_t::BOOK_CORNER, servo_status_t::CONVERGED, tcp_base));
  }
  /// The first run, then BwH rank 0 converging where P1 is: the GRASP decision, the third message. PS grasp (0.10,
  /// 0.255, -0.15).
  void grasp_decided() {
    first_run({0.61, -0.30, 0.25}, {0.45, -0.305, 0.10});
    send("SERVO_REQUEST", request(5000, 2, servo_request_t::BOOK_CORNER, 0));
    send("SERVO_STATUS", status(6000, 2, servo_request_t::BOOK_CORNER, servo_status_t::CONVERGED, {0.45, -0.31, 0.26}));
    ASSERT_EQ(out.got.size(), 3u);
    ASSERT_EQ(out.got[2].reason.rfind("GRASP", 0), 0u) << out.got[2].reason;
  }
  /// grasp_decided(), then plates closing to 31 mm (BOOK_WIDTH moves PS 31 mm left) and opening to 45 mm, at the
  /// shelf or after the TCP went 10 cm up (EXTRACT's lift).
  void grasp_then_open(bool carried_away) {
    grasp_decided();
    for (int64_t t = 100000; t <= 400000; t += 100000) send("ARM_STATE", arm(t, 0.031, true));
    ASSERT_EQ(out.got.size(), 4u);
    ASSERT_EQ(out.got[3].reason.rfind("BOOK_WIDTH: BW = 31.0 mm", 0), 0u) << out.got[3].reason;
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(out.got[3].ps_grasp[i], (Eigen::Vector3d(0.10, 0.229, -0.15))(i), 1e-9);
    arm_state_t away = arm(500000, 0.031, true, true);
    if (carried_away) away.end_effector.position[2] += 0.10;
    send("ARM_STATE", away);
    arm_state_t open = arm(600000, 0.045, false, true);
    open.end_effector = away.end_effector;
    send("ARM_STATE", open);
  }
  Composition comp;
  ArbiterNode* node = nullptr;
  Collector<grasp_point_t> out;
};

TEST_F(ArbiterNodeTest, WholeBookP1ValidGraspWidthAndNextPs) {
  // P1 base (0.61, -0.30, 0.25) -> grasp (0.25, 0.25, 0.01). PS base (0.45, -0.305, 0.10) -> (0.10, 0.255, -0.15).
  first_run({0.61, -0.30, 0.25}, {0.45, -0.305, 0.10});
  // Before PS: the P1 message answered NEED_PS. After PS: |0.25 - 0.255| = 5 mm <= 10 mm -> P1_VALID.
  ASSERT_EQ(out.got.size(), 2u);
  EXPECT_TRUE(starts_with(out.got[0].reason, "NEED_PS")) << out.got[0].reason;
  const grasp_point_t& check = out.got[1];
  EXPECT_TRUE(starts_with(check.reason, "P1_VALID")) << check.reason;
  EXPECT_FALSE(check.valid);
  EXPECT_TRUE(check.p1_used);
  EXPECT_EQ(check.utime, 4000);
  expect_vec(check.p1_grasp, {0.25, 0.25, 0.01}, "p1_grasp");
  expect_vec(check.ps_grasp, {0.10, 0.255, -0.15}, "ps_grasp");
  expect_vec(check.gp_grasp, {0.25, 0.25, 0.01}, "BwH start = P1");
  EXPECT_NEAR(check.gp_base.position[0], 0.61, kTol);
  EXPECT_NEAR(check.gp_base.position[1], -0.30, kTol);
  EXPECT_NEAR(check.gp_base.position[2], 0.25, kTol);
  EXPECT_EQ(check.num_steps, static_cast<int32_t>(check.steps.size()));

  // BwH rank 0 converges at base (0.45, -0.31, 0.26) -> grasp (0.26, 0.26, -0.15): dy = +10 mm < 15,
  // dx = +10 mm < 20 -> GP = (P2.x, P2.y, P1.z) = (0.26, 0.26, 0.01) -> base (0.61, -0.31, 0.26).
  corner_converged(5000, 2, 0, {0.45, -0.31, 0.26});
  ASSERT_EQ(out.got.size(), 3u);
  const grasp_point_t& gp = out.got[2];
  EXPECT_TRUE(starts_with(gp.reason, "GRASP")) << gp.reason;
  EXPECT_TRUE(gp.valid);
  EXPECT_EQ(gp.utime, 6000);
  EXPECT_EQ(gp.request_id, 2);
  EXPECT_TRUE(gp.p1_used);
  EXPECT_TRUE(gp.p2_used);
  expect_vec(gp.gp_grasp, {0.26, 0.26, 0.01}, "gp_grasp");
  expect_vec(gp.p2_grasp, {0.26, 0.26, -0.15}, "p2_grasp");
  EXPECT_NEAR(gp.gp_base.position[0], 0.61, kTol);
  EXPECT_NEAR(gp.gp_base.position[1], -0.31, kTol);
  EXPECT_NEAR(gp.gp_base.position[2], 0.26, kTol);
  const Eigen::Matrix3d r = pose_to_isometry(gp.gp_base).linear();
  EXPECT_TRUE(r.isApprox(grasp_rotation(), 1e-9)) << "gripper frame = grasp frame (slope 0)\n" << r;
  // Every rule of the strategy is in the trace, the P1 source first.
  std::vector<std::string> rules;
  for (const auto& s : gp.steps) rules.push_back(s.rule);
  ASSERT_GE(rules.size(), 6u);
  EXPECT_EQ(rules[0], "P1 source");
  EXPECT_EQ(rules[1], "P1.y vs PS.y");
  EXPECT_EQ(rules[2], "P2.y vs measured PS.y");  // PS from the stripe servo: P2 5 mm right of it
  EXPECT_EQ(rules[3], "P2.y vs P1.y");
  EXPECT_EQ(rules[4], "P2.x vs P1.x");
  EXPECT_EQ(rules[5], "GP.z");
  EXPECT_NEAR(gp.steps[2].value_m, 0.005, kTol);
  EXPECT_NEAR(gp.steps[3].value_m, 0.01, kTol);

  // A repeated CONVERGED status of the same request is not decided twice.
  send("SERVO_STATUS", status(6100, 2, servo_request_t::BOOK_CORNER, servo_status_t::CONVERGED, {0.45, -0.31, 0.26}));
  EXPECT_EQ(out.got.size(), 3u);

  // The open plates touch a neighbour while the gripper goes in (contact at the full opening, steady for
  // 0.5 s): that is not the book's width.
  send("ARM_STATE", arm(6200, 0.0601, true));
  send("ARM_STATE", arm(506200, 0.0601, true));
  EXPECT_EQ(out.got.size(), 3u) << "a steady width at the full opening (L_max) is not a book";
  // Gripper closes: contact at 25.4 mm (still closing), then 25.0 mm held for 0.3 s -> BW = 25 mm.
  send("ARM_STATE", arm(607000, 0.040, false));
  send("ARM_STATE", arm(608000, 0.0254, true));
  send("ARM_STATE", arm(618000, 0.0250, true));
  send("ARM_STATE", arm(718000, 0.0250, true));
  EXPECT_EQ(out.got.size(), 3u) << "0.1 s steady is less than settle_s 0.2";
  send("ARM_STATE", arm(918000, 0.0250, true));
  ASSERT_EQ(out.got.size(), 4u);
  const grasp_point_t& bw = out.got[3];
  EXPECT_TRUE(starts_with(bw.reason, "BOOK_WIDTH")) << bw.reason;
  EXPECT_TRUE(bw.valid) << "15 mm <= 25 mm <= 30 mm";
  EXPECT_EQ(bw.request_id, 2);
  // PS.y = GP.y - BW = 0.26 - 0.025 = 0.235; x, z kept from PS.
  expect_vec(bw.ps_grasp, {0.10, 0.235, -0.15}, "next PS");
  send("ARM_STATE", arm(1000000, 0.0250, true));
  EXPECT_EQ(out.got.size(), 4u) << "the width is measured once per grasp";

  // Next book: P1 base (0.61, -0.285, 0.18) -> grasp (0.18, 0.235, 0.01): 0 mm from the updated PS.
  send("BOOK_CORNER_STEREO", corner(1100000, "god", true, {0.61, -0.285, 0.18}));
  ASSERT_EQ(out.got.size(), 5u);
  EXPECT_TRUE(starts_with(out.got[4].reason, "P1_VALID")) << out.got[4].reason;
  EXPECT_NEAR(out.got[4].steps[1].value_m, 0.0, kTol);
}

// Narrowed plates (36.7 mm, after a grasp that closed on two books) touch the neighbour while the arm still inserts
// them: steady contact for 0.5 s, but the arm moves, so it is no width (far_cart seed 2003 took it for an 18 mm
// book's). The close with the arm still gives the width.
TEST_F(ArbiterNodeTest, AContactWhileTheArmMovesIsNoBookWidth) {
  grasp_decided();
  for (int64_t t = 10000; t <= 510000; t += 100000) send("ARM_STATE", arm(t, 0.0367, true, true));
  EXPECT_EQ(out.got.size(), 3u) << "a plate touching something while the arm moves is not a grasp";
  for (int64_t t = 520000; t <= 820000; t += 100000) send("ARM_STATE", arm(t, 0.018, true));
  ASSERT_EQ(out.got.size(), 4u);
  EXPECT_TRUE(starts_with(out.got[3].reason, "BOOK_WIDTH: BW = 18.0 mm")) << out.got[3].reason;
}

// A frame taken while the arm moves (or within p1.arm_still_s after) shows the arm in front of the shelf:
// its P1 neither replaces the latest P1 nor makes a P1 check; the attempt freezes the P1 of the still arm.
TEST_F(ArbiterNodeTest, P1FromAFrameTakenWhileTheArmMovedIsNotUsed) {
  const double still_s = ArbiterSettings::from_config(arbiter_config()).p1_arm_still_s;
  ASSERT_GT(still_s, 0.0);
  const int64_t still_us = static_cast<int64_t>(still_s * 1e6);
  first_run({0.61, -0.30, 0.25}, {0.45, -0.305, 0.10});  // P1 valid at utime 4000 (the arm never moved)
  ASSERT_EQ(out.got.size(), 2u);
  ASSERT_TRUE(starts_with(out.got[1].reason, "P1_VALID")) << out.got[1].reason;
  // The arm moves (a joint at 0.5 rad/s) from t = 10 s to 12 s, then stands still.
  arm_state_t a = arm(10000000, 0.05, false);
  a.num_joints = 1;
  a.joint_names = {"arm_1_joint"};
  a.positions = {0.0};
  a.velocities = {0.5};
  for (int64_t t = 10000000; t <= 12000000; t += 500000) {
    a.utime = t;
    send("ARM_STATE", a);
  }
  a.velocities = {0.0};
  a.state = arm_state_t::IDLE;
  a.utime = 12010000;
  send("ARM_STATE", a);
  // A frame during the motion and one just after it (within still_s): a P1 180 mm to the left is ignored.
  send("BOOK_CORNER_STEREO", corner(11000000, "god", true, {0.61, -0.12, 0.25}));
  send("BOOK_CORNER_STEREO", corner(12000000 + still_us / 2, "god", true, {0.61, -0.12, 0.25}));
  EXPECT_EQ(out.got.size(), 2u) << "no P1 check from a frame of the moving arm";
  EXPECT_EQ(node->p1_skipped_arm_moving(), 2);
  // The attempt's BwH request freezes the still arm's P1: BwH starts from it (P1_VALID earlier; GP uses P1.z).
  send("SERVO_REQUEST", request(12000000 + still_us / 2 + 1000, 2, servo_request_t::BOOK_CORNER, 0));
  send("SERVO_STATUS",
       status(13000000, 2, servo_request_t::BOOK_CORNER, servo_status_t::CONVERGED, {0.45, -0.31, 0.26}));
  ASSERT_EQ(out.got.size(), 3u);
  EXPECT_TRUE(starts_with(out.got[2].reason, "GRASP")) << out.got[2].reason;
  expect_vec(out.got[2].p1_grasp, {0.25, 0.25, 0.01}, "the still arm's P1");
  // A frame taken still_s after the arm stopped counts again.
  send("BOOK_CORNER_STEREO", corner(12010000 + still_us, "god", true, {0.61, -0.30, 0.25}));
  EXPECT_EQ(node->p1_skipped_arm_moving(), 2);
}

// Plates that open again where they closed gave the grasp up (the coordinator's plate-distance check backs out of two
// books): PS goes back to what it was before that BW moved it (the deployed seed 1 took the next book otherwise).
TEST_F(ArbiterNodeTest, PlatesOpenedWhereTheyClosedRestorePs) {
  grasp_then_open(false);
  ASSERT_EQ(out.got.size(), 5u);
  EXPECT_TRUE(starts_with(out.got[4].reason,
                          "PS_RESTORED: the plates opened to 45.0 mm where they had closed to "
                          "31.0 mm"))
      << out.got[4].reason;
  expect_vec(out.got[4].ps_grasp, {0.10, 0.255, -0.15}, "PS restored");
  EXPECT_FALSE(out.got[4].valid);
}

// Plates that open after the TCP carried the book away (the holder) leave PS where BW put it.
TEST_F(ArbiterNodeTest, PlatesOpenedAwayFromTheShelfKeepTheWidthsPs) {
  grasp_then_open(true);
  EXPECT_EQ(out.got.size(), 4u) << "the book went with the TCP: BW stands";
}

TEST_F(ArbiterNodeTest, FalseRegionAsksForNextRankThenGrasps) {
  first_run({0.61, -0.30, 0.25}, {0.45, -0.305, 0.10});
  // Rank 0 converges 30 mm right of P1 (grasp y 0.28, base y -0.33): false region -> NEXT_REGION rank 1.
  corner_converged(5000, 2, 0, {0.45, -0.33, 0.25});
  ASSERT_EQ(out.got.size(), 3u);
  EXPECT_TRUE(starts_with(out.got[2].reason, "NEXT_REGION rank 1")) << out.got[2].reason;
  EXPECT_FALSE(out.got[2].valid);
  // A new BwS frame during the servo (arm in view) must not replace the frozen P1 or answer a check.
  send("BOOK_CORNER_STEREO", corner(6500, "god", true, {0.61, -0.10, 0.40}));
  EXPECT_EQ(out.got.size(), 3u);
  // Rank 1 converges 3 mm LEFT of P1 (8 mm left of the measured PS, within tolerances.p2_measured_ps_y_m) and 30 mm
  // BELOW it: P2.y accepted, P2.x = P1.x. P2 grasp (0.22, 0.247, -0.15) -> GP = (0.25, 0.247, 0.01).
  corner_converged(7000, 3, 1, {0.45, -0.297, 0.22});
  ASSERT_EQ(out.got.size(), 4u);
  EXPECT_TRUE(starts_with(out.got[3].reason, "GRASP")) << out.got[3].reason;
  expect_vec(out.got[3].gp_grasp, {0.25, 0.247, 0.01}, "gp after rank 1");
  expect_vec(out.got[3].p1_grasp, {0.25, 0.25, 0.01}, "frozen P1");
}

// A thin right-most book beside a taller one: P1 on the taller book passes the PS check, BwH goes to that book's
// corner 15 mm left of the measured PS. No grasp; the next P1 check at the same PS ignores P1 (BwH from PS), and a
// PS measured anew is trusted with P1 again.
TEST_F(ArbiterNodeTest, AP1ThatLedBwhToTheNeighbourIsNotUsedAgainAtThatPs) {
  // P1 base y -0.298 -> grasp 0.248, 7 mm left of PS.y 0.255: valid.
  first_run({0.61, -0.298, 0.25}, {0.45, -0.305, 0.10});
  ASSERT_EQ(out.got.size(), 2u);
  EXPECT_TRUE(starts_with(out.got[1].reason, "P1_VALID")) << out.got[1].reason;
  // P2 grasp y 0.240 (base -0.29): 15 mm left of PS, 8 mm left of P1.
  corner_converged(5000, 2, 0, {0.45, -0.29, 0.26});
  ASSERT_EQ(out.got.size(), 3u);
  EXPECT_TRUE(starts_with(out.got[2].reason, "P1_LED_ASTRAY: P2 is 15.0 mm left of the stripe end"))
      << out.got[2].reason;
  EXPECT_FALSE(out.got[2].valid);
  // The coordinator's next attempt asks for the P1 check again (a new BwS frame).
  send("BOOK_CORNER_STEREO", corner(7000, "god", true, {0.61, -0.298, 0.25}));
  ASSERT_EQ(out.got.size(), 4u);
  EXPECT_TRUE(starts_with(out.got[3].reason, "P1_INVALID: P1 (-7.0 mm from PS) led BwH")) << out.got[3].reason;
  EXPECT_FALSE(out.got[3].p1_used);
  expect_vec(out.got[3].gp_grasp, {0.10, 0.255, 0.01}, "BwH start = PS, front depth");
  // From PS, BwH converges at the thin book's corner (grasp (0.20, 0.253)): grasped, P1 not used.
  corner_converged(8000, 3, 0, {0.45, -0.303, 0.20});
  ASSERT_EQ(out.got.size(), 5u);
  EXPECT_TRUE(starts_with(out.got[4].reason, "GRASP")) << out.got[4].reason;
  EXPECT_FALSE(out.got[4].p1_used);
  // A new stripe measurement 8 mm away (another book's end): P1 is checked as usual again.
  send("SERVO_REQUEST", request(10000, 4, servo_request_t::STRIPE_END));
  send("SERVO_STATUS", status(11000, 4, servo_request_t::STRIPE_END, servo_status_t::CONVERGED, {0.45, -0.297, 0.10}));
  ASSERT_EQ(out.got.size(), 6u);
  EXPECT_TRUE(starts_with(out.got[5].reason, "P1_VALID")) << out.got[5].reason;
}

// Far_cart seed 5021: P1 passed the PS check at 9.9 mm and BwH started from it; a cart marker turned by 2 mrad
// before the decision moved P1 to 10.2 mm from PS in the new grasp frame. The decision keeps the check's verdict:
// P2 15 mm left of the measured stripe end is the neighbour P1 led BwH to (P1_LED_ASTRAY: BwH from PS next), not a
// shorter neighbour found from PS "without a valid P1" (RAISE_BWH_START, which sent BwH above every book there).
TEST_F(ArbiterNodeTest, TheDecisionKeepsTheVerdictOfTheP1CheckThatStartedBwh) {
  // P1 base y -0.2951 -> grasp 0.2451, 9.9 mm left of PS.y 0.255: valid.
  first_run({0.61, -0.2951, 0.25}, {0.45, -0.305, 0.10});
  ASSERT_EQ(out.got.size(), 2u);
  EXPECT_TRUE(starts_with(out.got[1].reason, "P1_VALID")) << out.got[1].reason;
  marker_detections_t turned = markers(4500);
  Eigen::Isometry3d t = pose_to_isometry(turned.markers[0].pose_in_base);
  t.linear() = Eigen::AngleAxisd(-0.002, Eigen::Vector3d::UnitZ()).toRotationMatrix() * t.linear();
  turned.markers[0].pose_in_base = isometry_to_pose(t, "base", "cart", 4500);
  send("MARKERS", turned);
  // P2 base y -0.290: 15 mm left of PS.
  corner_converged(5000, 2, 0, {0.45, -0.290, 0.26});
  ASSERT_EQ(out.got.size(), 3u);
  const grasp_point_t& d = out.got[2];
  ASSERT_LT(d.p1_grasp[1] - d.ps_grasp[1], -0.0101) << "the turned frame puts P1 beyond the 10 mm tolerance now";
  EXPECT_TRUE(starts_with(d.reason, "P1_LED_ASTRAY: P2 is 15.")) << d.reason;
  EXPECT_TRUE(d.p1_used);
  bool noted = false;
  for (const auto& st : d.steps)
    noted |= st.decision.find("-9.9 mm from PS as when BwH started from it") != std::string::npos;
  EXPECT_TRUE(noted) << "the P1 step says which distance it judged";
}

// A tall right-most book: P1 failed the PS check, BwH from PS at the stripe's height centred the shorter left
// neighbour's corner 25 mm left of the measured PS. No grasp; the next P1 check at the same PS starts BwH higher
// (tolerances.raised_bwh_start_m), from where the tall book's own corner is grasped.
TEST_F(ArbiterNodeTest, ANeighbourCornerFromPsRaisesTheNextBwhStart) {
  // P1 base y -0.285 -> grasp 0.235, 20 mm left of PS.y 0.255 (on the shorter neighbour): invalid, BwH from PS.
  first_run({0.61, -0.285, 0.25}, {0.45, -0.305, 0.10});
  ASSERT_EQ(out.got.size(), 2u);
  EXPECT_TRUE(starts_with(out.got[1].reason, "P1_INVALID")) << out.got[1].reason;
  // P2 grasp (0.16, 0.230): 25 mm left of the measured PS.
  corner_converged(5000, 2, 0, {0.45, -0.28, 0.16});
  ASSERT_EQ(out.got.size(), 3u);
  EXPECT_TRUE(starts_with(out.got[2].reason, "RAISE_BWH_START: P2 is 25.0 mm left of the stripe end"))
      << out.got[2].reason;
  EXPECT_FALSE(out.got[2].valid);
  // The next attempt's P1 check: BwH starts 100 mm above that neighbour's corner (grasp X 0.16 -> 0.26; PS.x is
  // 0.10), same Y and depth.
  send("BOOK_CORNER_STEREO", corner(7000, "god", true, {0.61, -0.285, 0.25}));
  ASSERT_EQ(out.got.size(), 4u);
  EXPECT_TRUE(starts_with(out.got[3].reason, "P1_INVALID")) << out.got[3].reason;
  EXPECT_NE(out.got[3].reason.find("100.0 mm above that corner (160.0 mm above PS)"), std::string::npos)
      << out.got[3].reason;
  expect_vec(out.got[3].gp_grasp, {0.26, 0.255, 0.01}, "BwH start = the neighbour's corner raised, front depth");
  // From the raised start BwH centres another neighbour's corner 40 mm left of PS: no grasp, no second raise.
  corner_converged(7500, 3, 0, {0.45, -0.265, 0.30});
  ASSERT_EQ(out.got.size(), 5u);
  EXPECT_TRUE(starts_with(out.got[4].reason, "NO_GRASP: P2 is still 40.0 mm left of the stripe end"))
      << out.got[4].reason;
  // The stripe end measured again 0.2 mm away is the same book's: the next start is still raised.
  send("SERVO_REQUEST", request(9000, 4, servo_request_t::STRIPE_END));
  send("SERVO_STATUS", status(9100, 4, servo_request_t::STRIPE_END, servo_status_t::CONVERGED, {0.45, -0.3052, 0.10}));
  ASSERT_EQ(out.got.size(), 6u);
  EXPECT_TRUE(starts_with(out.got[5].reason, "P1_INVALID")) << out.got[5].reason;
  expect_vec(out.got[5].gp_grasp, {0.26, 0.2552, 0.01}, "BwH start = the neighbour's corner raised, re-measured PS");
  // From there BwH centres the tall book's corner (grasp (0.30, 0.253)): grasped.
  corner_converged(10000, 5, 0, {0.45, -0.303, 0.30});
  ASSERT_EQ(out.got.size(), 7u);
  EXPECT_TRUE(starts_with(out.got[6].reason, "GRASP")) << out.got[6].reason;
  expect_vec(out.got[6].gp_grasp, {0.30, 0.253, 0.01}, "GP at the tall book's corner");
}

// The stripe servo took its end at a shadow left of the right-most book: BwS's P1 lies 59 mm right of the measured
// PS. P1 stays invalid, but BwH starts from it (tolerances.start_from_p1_right_of_measured_ps) and the corner it
// centres next to P1 is grasped.
TEST_F(ArbiterNodeTest, AP1RightOfTheMeasuredStripeEndStartsBwhFromP1) {
  first_run_p1_right_of_ps();
  // P2 grasp (0.26, 0.324): 10 mm right of P1, 69 mm right of PS: both sensors agree, grasped.
  corner_converged(5000, 2, 0, {0.45, -0.374, 0.26});
  ASSERT_EQ(out.got.size(), 3u);
  EXPECT_TRUE(starts_with(out.got[2].reason, "GRASP")) << out.got[2].reason;
  expect_vec(out.got[2].gp_grasp, {0.26, 0.324, 0.01}, "GP at the corner BwH found from P1");
}

// The right-most book leans on the side panel (far_cart seeds 5445, 5456): BwH from the P1 right of the measured PS
// finds no fore-edge. The next P1 checks at that PS start BwH from PS again (the paper).
TEST_F(ArbiterNodeTest, BwhFromAP1RightOfPsThatFoundNoCornerFallsBackToPs) {
  first_run_p1_right_of_ps();
  send("SERVO_REQUEST", request(5000, 2, servo_request_t::BOOK_CORNER, 0));
  send("SERVO_STATUS", status(6000, 2, servo_request_t::BOOK_CORNER, servo_status_t::FEATURE_LOST, {0, 0, 0}));
  ASSERT_EQ(out.got.size(), 3u);
  EXPECT_TRUE(starts_with(out.got[2].reason, "NO_GRASP: no P2")) << out.got[2].reason;
  send("BOOK_CORNER_STEREO", corner(7000, "god", true, {0.61, -0.364, 0.25}));
  ASSERT_EQ(out.got.size(), 4u);
  EXPECT_NE(out.got[3].reason.find("BwH from it found no corner at this PS before"), std::string::npos)
      << out.got[3].reason;
  expect_vec(out.got[3].gp_grasp, {0.10, 0.255, 0.01}, "BwH start = PS");
  // The stripe end measured again 0.2 mm away is the same: still from PS.
  send("SERVO_REQUEST", request(8000, 3, servo_request_t::STRIPE_END));
  send("SERVO_STATUS", status(8100, 3, servo_request_t::STRIPE_END, servo_status_t::CONVERGED, {0.45, -0.3052, 0.10}));
  ASSERT_EQ(out.got.size(), 5u);
  expect_vec(out.got[4].gp_grasp, {0.10, 0.2552, 0.01}, "BwH start = the re-measured PS");
}

// After a grasp, PS is the estimate GP.y - BW. The next right-most book is tall and leans left: its P1 fails the PS
// check on the left; BwH from PS centres a shorter neighbour's corner left of and below P1. No grasp; the next P1
// check takes that P1 as valid (tolerances.invalid_p1_over_p2), and from it the tall book is grasped.
TEST_F(ArbiterNodeTest, ANeighbourCornerUnderAP1LeftOfPsSendsTheNextBwhToThatP1AfterAGrasp) {
  grasp_decided();
  for (int64_t t = 100000; t <= 400000; t += 100000) send("ARM_STATE", arm(t, 0.031, true));
  ASSERT_EQ(out.got.size(), 4u);
  ASSERT_TRUE(starts_with(out.got[3].reason, "BOOK_WIDTH: BW = 31.0 mm")) << out.got[3].reason;
  expect_vec(out.got[3].ps_grasp, {0.10, 0.229, -0.15}, "next PS = GP.y - BW");
  // P1 base (0.61, -0.266, 0.30) -> grasp (0.30, 0.216, 0.01): 13 mm left of PS, invalid.
  send("BOOK_CORNER_STEREO", corner(1100000, "god", true, {0.61, -0.266, 0.30}));
  ASSERT_EQ(out.got.size(), 5u);
  EXPECT_TRUE(starts_with(out.got[4].reason, "P1_INVALID")) << out.got[4].reason;
  // P2 grasp (0.17, 0.186): 30 mm left of and 130 mm below P1.
  corner_converged(1200000, 3, 0, {0.45, -0.236, 0.17});
  ASSERT_EQ(out.got.size(), 6u);
  EXPECT_TRUE(starts_with(out.got[5].reason, "START_FROM_P1: P2 is 30.0 mm left of and 130.0 mm below the P1"))
      << out.got[5].reason;
  EXPECT_FALSE(out.got[5].valid);
  // The next P1 check: P1 valid, BwH starts from it.
  send("BOOK_CORNER_STEREO", corner(1300000, "god", true, {0.61, -0.266, 0.30}));
  ASSERT_EQ(out.got.size(), 7u);
  EXPECT_TRUE(starts_with(out.got[6].reason, "P1_VALID")) << out.got[6].reason;
  expect_vec(out.got[6].gp_grasp, {0.30, 0.216, 0.01}, "BwH start = P1");
  // From there BwH centres the tall book's corner (grasp (0.30, 0.217)): grasped at it, GP.z = P1.z.
  corner_converged(1400000, 4, 0, {0.45, -0.267, 0.30});
  ASSERT_EQ(out.got.size(), 8u);
  EXPECT_TRUE(starts_with(out.got[7].reason, "GRASP")) << out.got[7].reason;
  expect_vec(out.got[7].gp_grasp, {0.30, 0.217, 0.01}, "GP at the tall book's corner");
}

TEST_F(ArbiterNodeTest, NoRegionLeftGivesNoGrasp) {
  first_run({0.61, -0.30, 0.25}, {0.45, -0.305, 0.10});
  corner_converged(5000, 2, 2, {0.45, -0.33, 0.25});
  ASSERT_EQ(out.got.size(), 3u);
  EXPECT_TRUE(starts_with(out.got[2].reason, "NO_GRASP")) << out.got[2].reason;
  EXPECT_NE(out.got[2].reason.find("max_rank 3"), std::string::npos) << out.got[2].reason;
}

TEST_F(ArbiterNodeTest, InvalidP1StartsBwhFromPsAndTakesZFromCartModel) {
  // P1 base y -0.285 -> grasp y 0.235, 20 mm left of PS.y 0.255 -> invalid; BwH starts from PS.
  first_run({0.61, -0.285, 0.25}, {0.45, -0.305, 0.10});
  ASSERT_EQ(out.got.size(), 2u);
  EXPECT_TRUE(starts_with(out.got[1].reason, "P1_INVALID")) << out.got[1].reason;
  EXPECT_FALSE(out.got[1].p1_used);
  // BwH starts from PS in X and Y; Z is the front depth the corner servo assumes: P1 grasp (0.25, 0.235, 0.01)
  // is invalid in Y but its Z lies within invalid_p1_depth_range_m of book_front_z_m 0.01 -> 0.01.
  expect_vec(out.got[1].gp_grasp, {0.10, 0.255, 0.01}, "BwH start = PS, front depth");
  // P2 grasp (0.24, 0.26, -0.15): 5 mm right of PS -> valid; no P1 -> X as is, Z = book_front_z_m 0.01.
  corner_converged(5000, 2, 0, {0.45, -0.31, 0.24});
  ASSERT_EQ(out.got.size(), 3u);
  EXPECT_TRUE(starts_with(out.got[2].reason, "GRASP")) << out.got[2].reason;
  EXPECT_FALSE(out.got[2].p1_used);
  expect_vec(out.got[2].gp_grasp, {0.24, 0.26, 0.01}, "gp without P1");
}

// The target's front pushed back to grasp Z 0.08, spanning grasp Y 0.230..0.254 and X 0..0.20: in base the
// plane x = 0.60 + 0.08 (normal +x), y = -0.05 - Y in [-0.304, -0.280], z = X. With PS.y 0.255 the probe band
// Y 0.245..0.253 (stereo_front.probe_left_of_ps_m) lies inside it.
plane_region_t pushed_front_region() {
  plane_region_t r;
  r.utime = 2000;
  r.label = 7;
  r.pixel_count = 300;
  for (int i = 0; i < 4; ++i) r.bbox_px[i] = 0;
  r.normal_base[0] = 1;
  r.normal_base[1] = 0;
  r.normal_base[2] = 0;
  r.offset_m = 0.68;
  const double lo[3] = {0.68, -0.304, 0.0}, hi[3] = {0.68, -0.280, 0.20};
  for (int i = 0; i < 3; ++i) {
    r.extent_min_base[i] = lo[i];
    r.extent_max_base[i] = hi[i];
  }
  r.candidate = false;
  r.reject_reason = "too small";
  return r;
}

TEST_F(ArbiterNodeTest, AStereoFrontLeftOfPsGivesTheDepthWhenP1IsInvalid) {
  const plane_region_t good = pushed_front_region();
  plane_region_t bad = good;
  bad.extent_min_base[0] = NAN;  // one bad field: not a plane to measure (its finite corners alone gave 0.08)
  // P1 2 cm left of PS: invalid; its own Z 0.01 is the depth without a usable region.
  for (const auto& [region, front_z] : {std::pair{good, 0.08}, std::pair{bad, 0.01}}) {
    SCOPED_TRACE("front " + std::to_string(front_z));
    out.got.clear();
    book_corner_stereo_t c = corner(2000, "god", true, {0.61, -0.285, 0.25});
    c.regions = {region};
    c.num_regions = 1;
    send("SERVO_REQUEST", request(1500, 0, servo_request_t::CANCEL));  // a fresh attempt for each case
    send("MARKERS", markers(1000));
    send("BOOK_CORNER_STEREO", c);
    send("SERVO_REQUEST", request(3000, 1, servo_request_t::STRIPE_END));
    send("SERVO_STATUS", status(4000, 1, servo_request_t::STRIPE_END, servo_status_t::CONVERGED, {0.45, -0.305, 0.10}));
    ASSERT_EQ(out.got.size(), 2u);
    EXPECT_TRUE(starts_with(out.got[1].reason, "P1_INVALID")) << out.got[1].reason;
    expect_vec(out.got[1].gp_grasp, {0.10, 0.255, front_z}, "BwH start = PS, the front's depth");
    // P2 grasp (0.24, 0.26, -0.15) -> GP = (0.24, 0.26, front depth).
    send("SERVO_REQUEST", request(5000, 2, servo_request_t::BOOK_CORNER, 0));
    send("SERVO_STATUS", status(6000, 2, servo_request_t::BOOK_CORNER, servo_status_t::CONVERGED, {0.45, -0.31, 0.24}));
    ASSERT_EQ(out.got.size(), 3u);
    EXPECT_TRUE(starts_with(out.got[2].reason, "GRASP")) << out.got[2].reason;
    expect_vec(out.got[2].gp_grasp, {0.24, 0.26, front_z}, "gp from the front's depth");
  }
}

// Not in the paper: R triangulated by the corner servo gives GP.z and P2.x (arbiter.yaml hand_corner), here
// over a valid P1 whose depth (0.01) is the unpushed front's while R stands 7 cm deeper.
TEST_F(ArbiterNodeTest, TheServosTriangulatedCornerGivesGpZAndX) {
  first_run({0.61, -0.30, 0.25}, {0.45, -0.305, 0.10});
  send("SERVO_REQUEST", request(5000, 2, servo_request_t::BOOK_CORNER, 0));
  servo_status_t st = status(6000, 2, servo_request_t::BOOK_CORNER, servo_status_t::CONVERGED, {0.45, -0.31, 0.24});
  st.corner_triangulated = true;
  st.corner_base[0] = 0.68;  // grasp (0.235, 0.262, 0.08)
  st.corner_base[1] = -0.312;
  st.corner_base[2] = 0.235;
  send("SERVO_STATUS", st);
  ASSERT_EQ(out.got.size(), 3u);
  EXPECT_TRUE(starts_with(out.got[2].reason, "GRASP")) << out.got[2].reason;
  expect_vec(out.got[2].gp_grasp, {0.235, 0.26, 0.08}, "GP = (R.x, P2.y, R.z)");
  bool said = false;
  for (const validation_step_t& v : out.got[2].steps) said |= v.decision.find("hand camera") != std::string::npos;
  EXPECT_TRUE(said);
}

// An attempt whose GRASP came with R triangulated 12 cm deep, then failed before the plates closed (an insertion that
// timed out): PS stays, and the next P1 check without a valid P1 starts the corner servo at R's depth, not at the
// model's plane (whole-shelf far_cart seed 1, book 7). A new PS forgets it.
TEST_F(ArbiterNodeTest, ACornerTriangulatedAtThisPsGivesTheNextAttemptsDepth) {
  first_run({0.61, -0.30, 0.25}, {0.45, -0.305, 0.10});
  send("SERVO_REQUEST", request(5000, 2, servo_request_t::BOOK_CORNER, 0));
  servo_status_t st = status(6000, 2, servo_request_t::BOOK_CORNER, servo_status_t::CONVERGED, {0.45, -0.31, 0.24});
  st.corner_triangulated = true;
  st.corner_base[0] = 0.73;  // grasp (0.235, 0.262, 0.13): 12 cm behind the model's plane (0.01)
  st.corner_base[1] = -0.312;
  st.corner_base[2] = 0.235;
  send("SERVO_STATUS", st);
  ASSERT_EQ(out.got.size(), 3u);
  ASSERT_TRUE(starts_with(out.got[2].reason, "GRASP")) << out.got[2].reason;
  ASSERT_NEAR(out.got[2].gp_grasp[2], 0.13, kTol);
  // The next attempt: BwS sees no book near PS (P1 3 cm right of it: invalid, at the model's depth).
  send("BOOK_CORNER_STEREO", corner(7000, "god", true, {0.61, -0.335, 0.25}));
  ASSERT_EQ(out.got.size(), 4u);
  EXPECT_TRUE(starts_with(out.got[3].reason, "P1_INVALID")) << out.got[3].reason;
  EXPECT_NEAR(out.got[3].gp_grasp[2], 0.13, kTol) << "the corner servo's depth: R's, not the model's 0.01";
  // A new stripe measurement (another PS): the model's depth again.
  send("SERVO_REQUEST", request(8000, 3, servo_request_t::STRIPE_END));
  send("SERVO_STATUS", status(9000, 3, servo_request_t::STRIPE_END, servo_status_t::CONVERGED, {0.45, -0.303, 0.10}));
  ASSERT_EQ(out.got.size(), 5u);
  EXPECT_TRUE(starts_with(out.got[4].reason, "P1_INVALID")) << out.got[4].reason;
  EXPECT_NEAR(out.got[4].gp_grasp[2], 0.01, kTol);
}

TEST_F(ArbiterNodeTest, ServoFailureIsNoGraspAndOpensANewAttempt) {
  first_run({0.61, -0.30, 0.25}, {0.45, -0.305, 0.10});
  send("SERVO_REQUEST", request(5000, 2, servo_request_t::BOOK_CORNER, 0));
  send("SERVO_STATUS", status(6000, 2, servo_request_t::BOOK_CORNER, servo_status_t::FEATURE_LOST, {0, 0, 0}));
  ASSERT_EQ(out.got.size(), 3u);
  EXPECT_TRUE(starts_with(out.got[2].reason, "NO_GRASP")) << out.got[2].reason;
  EXPECT_NE(out.got[2].reason.find("did not converge"), std::string::npos);
  // The next attempt answers P1 checks again (P1 no longer frozen).
  send("BOOK_CORNER_STEREO", corner(7000, "god", true, {0.61, -0.30, 0.25}));
  ASSERT_EQ(out.got.size(), 4u);
  EXPECT_TRUE(starts_with(out.got[3].reason, "P1_VALID")) << out.got[3].reason;
}

TEST_F(ArbiterNodeTest, CancelReopensTheAttempt) {
  first_run({0.61, -0.30, 0.25}, {0.45, -0.305, 0.10});
  send("BOOK_CORNER_STEREO", corner(4500, "god", true, {0.61, -0.30, 0.25}));
  EXPECT_EQ(out.got.size(), 2u) << "frozen by the stripe request";
  send("SERVO_REQUEST", request(5000, 0, servo_request_t::CANCEL));
  send("BOOK_CORNER_STEREO", corner(6000, "god", true, {0.61, -0.30, 0.25}));
  ASSERT_EQ(out.got.size(), 3u);
  EXPECT_TRUE(starts_with(out.got[2].reason, "P1_VALID")) << out.got[2].reason;
}

TEST_F(ArbiterNodeTest, SlopeOfTheServoTurnsTheGripperAboutZ) {
  first_run({0.61, -0.30, 0.25}, {0.45, -0.305, 0.10});
  send("SERVO_REQUEST", request(5000, 2, servo_request_t::BOOK_CORNER, 0));
  send("SERVO_STATUS",
       status(6000, 2, servo_request_t::BOOK_CORNER, servo_status_t::CONVERGED, {0.45, -0.31, 0.26}, 0.05));
  ASSERT_EQ(out.got.size(), 3u);
  EXPECT_NEAR(out.got[2].slope_rad, 0.05, 1e-9);
  // Gripper x = cos(0.05) X + sin(0.05) Y = (0, -sin 0.05, cos 0.05) in base.
  const Eigen::Matrix3d r = pose_to_isometry(out.got[2].gp_base).linear();
  EXPECT_NEAR(r(0, 0), 0.0, 1e-9);
  EXPECT_NEAR(r(1, 0), -std::sin(0.05), 1e-9);
  EXPECT_NEAR(r(2, 0), std::cos(0.05), 1e-9);
}

TEST_F(ArbiterNodeTest, DetectorSwitchSelectsTheImplementationAndShows) {
  send("MARKERS", markers(1000));
  send("SERVO_REQUEST", request(1500, 1, servo_request_t::STRIPE_END));
  send("SERVO_STATUS", status(1600, 1, servo_request_t::STRIPE_END, servo_status_t::CONVERGED, {0.45, -0.305, 0.10}));
  ASSERT_EQ(out.got.size(), 1u);  // P1 check without P1: invalid, start from PS
  EXPECT_TRUE(starts_with(out.got[0].reason, "P1_INVALID")) << out.got[0].reason;
  send("SERVO_REQUEST", request(1700, 0, servo_request_t::CANCEL));
  send("BOOK_CORNER_STEREO", corner(2000, "pcl", true, {0.61, -0.30, 0.25}));
  EXPECT_EQ(out.got.size(), 1u) << "pcl is not followed yet";
  detector_switch_t sw;
  sw.utime = 2500;
  sw.logical_channel = "BOOK_CORNER_STEREO";
  sw.implementation = "pcl";
  sw.reason = "operator test";
  send("DETECTOR_SWITCH", sw);
  EXPECT_EQ(node->followed_implementation(), "pcl");
  EXPECT_NE(node->last_error().find("now following BOOK_CORNER_STEREO implementation 'pcl'"), std::string::npos)
      << node->last_error();
  send("BOOK_CORNER_STEREO", corner(3000, "god", true, {0.61, -0.30, 0.25}));
  EXPECT_EQ(out.got.size(), 1u) << "god is no longer followed";
  send("BOOK_CORNER_STEREO", corner(3100, "pcl", true, {0.61, -0.30, 0.25}));
  ASSERT_EQ(out.got.size(), 2u);
  EXPECT_TRUE(starts_with(out.got[1].reason, "P1_VALID")) << out.got[1].reason;
  EXPECT_NE(out.got[1].reason.find("'pcl'"), std::string::npos) << out.got[1].reason;
  EXPECT_EQ(out.got[1].steps[0].rule, "P1 source");
  EXPECT_NE(out.got[1].steps[0].decision.find("operator test"), std::string::npos);
  // A switch for another logical channel changes nothing.
  sw.logical_channel = "BOOK_FEATURES_HAND";
  sw.implementation = "other";
  send("DETECTOR_SWITCH", sw);
  EXPECT_EQ(node->followed_implementation(), "pcl");
}

TEST_F(ArbiterNodeTest, BadInputsAreRejectedAndTheNodeGoesOn) {
  constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
  send("MARKERS", markers(1000));
  const uint8_t garbage[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18};
  comp.bus().publish("BOOK_CORNER_STEREO", garbage, sizeof(garbage));
  comp.spin();
  send("BOOK_CORNER_STEREO", corner(1100, "god", true, {kNan, 0, 0}));
  auto bad_markers = markers(1200);
  bad_markers.markers[0].pose_in_base.orientation[0] = 0;
  bad_markers.markers[0].pose_in_base.orientation[1] = 0;
  bad_markers.markers[0].pose_in_base.orientation[2] = 0;
  bad_markers.markers[0].pose_in_base.orientation[3] = 0;
  send("MARKERS", bad_markers);
  send("SERVO_REQUEST", request(1300, 5, 9));
  auto bad_status = status(1400, 1, servo_request_t::STRIPE_END, servo_status_t::CONVERGED, {kNan, 0, 0});
  send("SERVO_STATUS", bad_status);
  send("ARM_STATE", arm(1500, kNan, true));
  detector_switch_t sw;
  sw.utime = 1600;
  sw.logical_channel = "BOOK_CORNER_STEREO";
  sw.implementation = "";
  send("DETECTOR_SWITCH", sw);
  EXPECT_EQ(node->rejected_total(), 7);
  EXPECT_TRUE(out.got.empty());
  // Still works: the earlier good marker frame is kept.
  send("BOOK_CORNER_STEREO", corner(2000, "god", true, {0.61, -0.30, 0.25}));
  send("SERVO_REQUEST", request(3000, 1, servo_request_t::STRIPE_END));
  send("SERVO_STATUS", status(4000, 1, servo_request_t::STRIPE_END, servo_status_t::CONVERGED, {0.45, -0.305, 0.10}));
  ASSERT_EQ(out.got.size(), 2u);
  EXPECT_TRUE(starts_with(out.got[1].reason, "P1_VALID")) << out.got[1].reason;
}

TEST_F(ArbiterNodeTest, SameInputsGiveTheSameOutputsBitForBit) {
  auto run = [](std::vector<std::vector<uint8_t>>* encoded) {
    Composition c;
    c.add(std::make_unique<ArbiterNode>(arbiter_config()));
    Collector<grasp_point_t> col;
    c.bus().subscribe("GRASP_POINT", &Collector<grasp_point_t>::on, &col);
    auto pub = [&](const std::string& ch, const auto& m) {
      c.bus().publish(ch, &m);
      c.spin();
    };
    pub("MARKERS", markers(1000));
    pub("BOOK_CORNER_STEREO", corner(2000, "god", true, {0.61, -0.30, 0.25}));
    pub("SERVO_REQUEST", request(3000, 1, servo_request_t::STRIPE_END));
    pub("SERVO_STATUS", status(4000, 1, servo_request_t::STRIPE_END, servo_status_t::CONVERGED, {0.45, -0.305, 0.10}));
    pub("SERVO_REQUEST", request(5000, 2, servo_request_t::BOOK_CORNER, 0));
    pub("SERVO_STATUS", status(6000, 2, servo_request_t::BOOK_CORNER, servo_status_t::CONVERGED, {0.45, -0.31, 0.26}, 0.02));
    for (const auto& g : col.got) {
      std::vector<uint8_t> buf(g.getEncodedSize());
      g.encode(buf.data(), 0, static_cast<int>(buf.size()));
      encoded->push_back(buf);
    }
  };
  std::vector<std::vector<uint8_t>> a, b;
  run(&a);
  run(&b);
  ASSERT_EQ(a.size(), 3u);
  EXPECT_EQ(a, b);
}

TEST(ArbiterConfig, ShippedConfigReadsCompletelyAndBadValuesNameTheKey) {
  const Config cfg = arbiter_config();
  ServiceSettings::from_config(cfg);
  ArbiterNode node(cfg);
  EXPECT_NO_THROW(cfg.require_all_read());
  std::string text = cfg.dump();
  const auto pos = text.find("y_m: 0.015");
  ASSERT_NE(pos, std::string::npos);
  text.replace(pos, 10, "y_m: -1");
  try {
    ArbiterNode bad(Config::from_string(text, "arbiter.yaml"));
    FAIL() << "a negative tolerance must be refused";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("tolerances.y_m"), std::string::npos) << e.what();
  }
}

TEST(ArbiterConfig, BadDepthKeysNameTheKey) {
  std::ifstream f(std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/arbiter.yaml");
  std::stringstream ss;
  ss << f.rdbuf();
  const std::string shipped = ss.str();
  for (const auto& [key, line, bad] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {"tolerances.invalid_p1_depth_range_m", "invalid_p1_depth_range_m: 0.15", "invalid_p1_depth_range_m: -0.1"},
           {"stereo_front.probe_left_of_ps_m", "probe_left_of_ps_m: [0.002, 0.010]",
            "probe_left_of_ps_m: [0.01, 0.002]"},
           {"stereo_front.depth_range_m", "depth_range_m: [-0.05, 0.20]", "depth_range_m: [0.20, -0.05]"},
           {"stereo_front.max_tilt_deg", "max_tilt_deg: 20.0", "max_tilt_deg: 95"},
           {"tolerances.raised_bwh_start_m", "raised_bwh_start_m: 0.10", "raised_bwh_start_m: 0.5"},
           {"tolerances.invalid_p1_over_p2", "invalid_p1_over_p2: true", "invalid_p1_over_p2: 0.2"},
           {"tolerances.raise_over_neighbour_corner", "raise_over_neighbour_corner: true",
            "raise_over_neighbour_corner: yes please"},
           {"tolerances.start_from_p1_right_of_measured_ps", "start_from_p1_right_of_measured_ps: true",
            "start_from_p1_right_of_measured_ps: 3"}}) {
    std::string text = shipped;
    const auto pos = text.find(line);
    ASSERT_NE(pos, std::string::npos) << line;
    text.replace(pos, line.size(), bad);
    try {
      ArbiterNode node(Config::from_string(text, "arbiter.yaml"));
      ADD_FAILURE() << "accepted " << bad;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace bookgrasp
