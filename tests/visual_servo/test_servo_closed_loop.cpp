// The servo loop closed in simulation: SimWorld core stepped by the harness, arm_driver,
// hand_camera (sim, rendered), bwh/bswh detectors and visual_servo composed on memq.
// Measured against the simulation's ground truth (P1 of the right-most book, stripe end).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "bookgrasp/servo_request_t.hpp"
#include "bookgrasp/servo_status_t.hpp"
#include "common/grasp_frame.h"
#include "services/eval_hand/hand_servo_harness.h"

namespace bookgrasp {
namespace {

HandServoOptions options(const std::string& prefix) {
  HandServoOptions o;
  o.config_dir = std::string(BOOKGRASP_SOURCE_DIR) + "/config/services";
  o.camera_rate_hz = 15.0;
  if (const char* d = std::getenv("BOOKGRASP_DEBUG_IMAGES")) o.debug_image_dir = d;
  if (const char* n = std::getenv("BOOKGRASP_DEBUG_EVERY")) o.debug_every_frames = std::atoi(n);
  o.debug_prefix = prefix;
  return o;
}

scene::Scene load(uint64_t seed) {
  return scene::load_scene(std::string(BOOKGRASP_SOURCE_DIR) + "/services/eval_hand/scenes/hand_eval.yaml", seed);
}

const book_truth_t* rightmost(const ground_truth_t& t) {
  for (const auto& b : t.books)
    if (b.rightmost) return &b;
  return nullptr;
}

/// Error of a TCP position against a true point, in the grasp frame (X up, Y right), metres.
Eigen::Vector3d grasp_error(const scene::Scene& s, const Eigen::Vector3d& tcp, const Eigen::Vector3d& truth) {
  const Eigen::Isometry3d g = grasp_pose_for_cart(s, truth);
  return g.inverse() * tcp;
}

struct CornerCase {
  uint64_t seed;
  double dx, dy;  // start offset from P1 (grasp frame, m)
};

class CornerClosedLoop : public ::testing::TestWithParam<CornerCase> {};

TEST_P(CornerClosedLoop, ConvergesOntoTheTrueCorner) {
  const CornerCase c = GetParam();
  const scene::Scene s = load(c.seed);
  const ground_truth_t truth0 = scene_truth(s);
  HandServoTask task;
  task.mode = servo_request_t::BOOK_CORNER;
  task.standoff_m = 0.22;
  task.timeout_s = 15;
  const auto start = corner_start(s, truth0, c.dx, c.dy, task.standoff_m);
  ASSERT_TRUE(start.has_value());
  task.start_tcp = *start;
  const HandServoResult r = run_hand_servo_task(s, task, options("corner_" + std::to_string(c.seed) + "_"));
  ASSERT_TRUE(r.ik_ok) << r.ik_message;
  ASSERT_EQ(r.state, servo_status_t::CONVERGED) << r.message;
  const book_truth_t* b = rightmost(r.truth);
  ASSERT_NE(b, nullptr);
  const Eigen::Vector3d p1(b->p1_base[0], b->p1_base[1], b->p1_base[2]);
  const Eigen::Vector3d e = grasp_error(s, r.converged_pose->translation(), p1);
  // The paper's grasping tolerance is 2 cm (X) and 1.5 cm (Y); we require much less.
  EXPECT_LT(std::abs(e.x()), 0.004) << "P2 - P1 up (m), seed " << c.seed;
  EXPECT_LT(std::abs(e.y()), 0.003) << "P2 - P1 right (m), seed " << c.seed;
  EXPECT_NEAR(e.z(), -task.standoff_m, 0.005) << "standoff kept";
  RecordProperty("iterations", r.iterations);
}

INSTANTIATE_TEST_SUITE_P(Offsets, CornerClosedLoop,
                         ::testing::Values(CornerCase{1, 0.05, 0.0}, CornerCase{2, -0.035, 0.035},
                                           CornerCase{3, 0.0, -0.05}, CornerCase{4, 0.03, 0.04}));

void run_stripe(uint64_t seed, const Eigen::Vector3d& a_grasp, std::optional<bool> require_occlusion) {
  const scene::Scene s = load(seed);
  HandServoTask task;
  task.mode = servo_request_t::STRIPE_END;
  task.standoff_m = s.shelf_depth_m - a_grasp.z();
  task.timeout_s = 20;
  task.start_tcp = cart_grasp_pose(s, a_grasp);
  HandServoOptions o = options("stripe_" + std::to_string(seed) + "_");
  o.require_occlusion = require_occlusion;
  const HandServoResult r = run_hand_servo_task(s, task, o);
  ASSERT_TRUE(r.ik_ok) << r.ik_message;
  ASSERT_EQ(r.state, servo_status_t::CONVERGED) << "seed " << seed << ": " << r.message;
  const Eigen::Vector3d end(r.truth.stripe_end_base[0], r.truth.stripe_end_base[1], r.truth.stripe_end_base[2]);
  const Eigen::Vector3d e = grasp_error(s, r.converged_pose->translation(), end);
  // Paper: always within 1 cm (Y) and 1.5 cm (X).
  EXPECT_LT(std::abs(e.y()), 0.005) << "PS - end right (m), seed " << seed;
  EXPECT_LT(std::abs(e.x()), 0.005) << "PS - end up (m), seed " << seed;
}

// Station A as the coordinator computes it (right part of the stripe, 0.46 m from the rear board): the
// search goes left along the stripe (end_side) until the end where the right-most book hides it.
TEST(StripeClosedLoop, FromTheCoordinatorsStationAToTheTrueStripeEnd) {
  for (uint64_t seed : {1, 2, 3}) run_stripe(seed, Eigen::Vector3d(0.10, 0.30, -0.10), std::nullopt);
}

TEST(StripeClosedLoop, FromInFrontOfTheCartMarkerPastTheBooks) {
  // The paper's station A: in front of the cart marker (left part of this cart), searching right.
  const scene::Scene s = load(4);
  const Eigen::Vector3d m = cart_marker_in_grasp(s, scene_truth(s));
  run_stripe(4, Eigen::Vector3d(0.10, m.y(), -0.10), true);
}

TEST(ServoClosedLoop, LookingAwayFromTheCartStopsWithFeatureLost) {
  const scene::Scene s = load(5);
  const ground_truth_t truth0 = scene_truth(s);
  HandServoTask task;
  task.mode = servo_request_t::BOOK_CORNER;
  task.standoff_m = 0.22;
  task.timeout_s = 10;
  // Start in front of the cart but pitched 40 degrees up (about the gripper y axis): the camera
  // sees the rear board's top and the room above the books, no fore-edge. (Until stop 22 the pose was pitched
  // down, to the shelf and the floor: fore-edges in view, rejected only while page_faces dropped a whole region
  // that touched the top border; it now finds their corners, debug images BOOKGRASP_DEBUG_IMAGES.)
  const auto start = corner_start(s, truth0, 0.0, 0.0, 0.22);
  ASSERT_TRUE(start.has_value());
  Eigen::Isometry3d away = *start;
  away.linear() = start->linear() * Eigen::AngleAxisd(40.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  task.start_tcp = away;
  const HandServoResult r = run_hand_servo_task(s, task, options("away_"));
  ASSERT_TRUE(r.ik_ok) << r.ik_message;
  EXPECT_EQ(r.state, servo_status_t::FEATURE_LOST) << r.message;
  EXPECT_NE(r.message.find("BwH"), std::string::npos) << r.message;
  EXPECT_LT(r.sim_time_s, 1.0);  // feature_lost_timeout_s 0.6 + a frame
}

}  // namespace
}  // namespace bookgrasp
