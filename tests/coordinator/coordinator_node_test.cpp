// The coordinator node on memq:// with hand-made messages: what it asks of the planner, the arm and the
// servo, TASK_STATUS, the progress file, bad inputs. Expected values are worked out by hand from
// config/services/coordinator.yaml and the default scene's cart marker.
#include "services/coordinator/coordinator_node.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "bookgrasp/arm_command_t.hpp"
#include "bookgrasp/plan_request_t.hpp"
#include "bookgrasp/servo_request_t.hpp"
#include "bookgrasp/task_status_t.hpp"
#include "common/composition.h"
#include "common/pose_conversion.h"
#include "common/service_host.h"
#include "tests/coordinator/fake_library.h"

namespace bookgrasp {
namespace {

template <typename Msg>
struct Collector {
  std::vector<Msg> got;
  void on(const lcm::ReceiveBuffer*, const std::string&, const Msg* m) { got.push_back(*m); }
};

std::string config_text(const std::string& progress_path) {
  const Config c = Config::load_file(std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/coordinator.yaml");
  std::string text = c.dump();
  const std::string key = "progress_file: logs/coordinator_progress.yaml";
  const auto pos = text.find(key);
  if (pos == std::string::npos) throw std::runtime_error("progress_file not found in the config dump");
  text.replace(pos, key.size(), "progress_file: " + progress_path);
  return text;
}

marker_detections_t markers(int64_t utime) {
  marker_detections_t d;
  d.utime = utime;
  for (const char* role : {"cart", "holder"}) {
    marker_t m;
    m.utime = utime;
    m.role = role;
    m.id = std::string(role) == "cart" ? 0 : 1;
    const Eigen::Isometry3d t =
        std::string(role) == "cart" ? bookgrasp_test::cart_marker_pose() : bookgrasp_test::holder_marker_pose();
    m.pose_in_base = isometry_to_pose(t, "base", role, utime);
    m.pose_in_camera = m.pose_in_base;
    d.markers.push_back(m);
  }
  d.num_markers = static_cast<int32_t>(d.markers.size());
  return d;
}

arm_state_t arm(int64_t utime, int8_t state, int64_t active) {
  arm_state_t a;
  a.utime = utime;
  a.num_joints = 7;
  for (int i = 0; i < 7; ++i) a.joint_names.push_back("arm_" + std::to_string(i + 1));
  a.positions = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7};
  a.velocities.assign(7, 0.0);
  a.end_effector = isometry_to_pose(Eigen::Isometry3d::Identity(), "base", "gripper", utime);
  a.gripper_width_m = 0.06;
  a.gripper_contact = false;
  a.state = state;
  a.active_command_id = active;
  return a;
}

class CoordinatorNodeTest : public testing::Test {
 protected:
  void SetUp() override {
    // One file per test: ctest runs this file's tests as parallel processes, and a shared file let one test's
    // progress overwrite another's corrupt one (CI, stop 30).
    path = testing::TempDir() + "/coordinator_node_test_progress_" +
           testing::UnitTest::GetInstance()->current_test_info()->name() + ".yaml";
    std::remove(path.c_str());
  }
  void TearDown() override { std::remove(path.c_str()); }
  std::string path;
};

TEST_F(CoordinatorNodeTest, ParksPlansToTheStripeStartPersistsAndResumes) {
  Composition comp;
  const Config cfg = Config::from_string(config_text(path), "coordinator.yaml");
  ServiceSettings::from_config(cfg);
  auto& node = comp.add(std::make_unique<CoordinatorNode>(cfg));
  EXPECT_NO_THROW(cfg.require_all_read());
  Collector<servo_request_t> servo;
  Collector<plan_request_t> plans;
  Collector<arm_command_t> commands;
  Collector<task_status_t> status;
  comp.bus().subscribe("SERVO_REQUEST", &Collector<servo_request_t>::on, &servo);
  comp.bus().subscribe("PLAN_REQUEST", &Collector<plan_request_t>::on, &plans);
  comp.bus().subscribe("ARM_COMMAND", &Collector<arm_command_t>::on, &commands);
  comp.bus().subscribe("TASK_STATUS", &Collector<task_status_t>::on, &status);
  auto send = [&](const std::string& ch, const auto& m) {
    comp.bus().publish(ch, &m);
    comp.spin();
  };

  send("MARKERS", markers(1000));
  send("ARM_STATE", arm(2000, arm_state_t::IDLE, 0));
  // First arm state: cancel any servo task left over, then plan to the park joints from where the arm is.
  ASSERT_EQ(servo.got.size(), 1u);
  EXPECT_EQ(servo.got[0].mode, servo_request_t::CANCEL);
  ASSERT_EQ(plans.got.size(), 1u);
  const plan_request_t& park = plans.got[0];
  EXPECT_EQ(park.utime, 2000);
  EXPECT_EQ(park.goal_type, plan_request_t::JOINTS);
  ASSERT_EQ(park.num_joints, 7);
  const double park_deg[7] = {0, -90, 0, -90, 0, -90, 0};
  for (int i = 0; i < 7; ++i) {
    EXPECT_NEAR(park.goal_joints[i], park_deg[i] * M_PI / 180, 1e-12);
    EXPECT_NEAR(park.start_joints[i], 0.1 * (i + 1), 1e-12);
  }
  ASSERT_FALSE(status.got.empty());
  EXPECT_EQ(status.got.back().state, "PARK");

  // The planner answers: the trajectory goes to the arm unchanged.
  plan_result_t res;
  res.utime = 3000;
  res.request_id = park.request_id;
  res.success = true;
  res.failure = plan_result_t::NONE;
  res.trajectory.num_joints = 7;
  res.trajectory.joint_names = arm(0, 0, 0).joint_names;
  for (int k = 0; k < 2; ++k) {
    trajectory_point_t p;
    p.utime = k * 1000000;
    p.num_joints = 7;
    p.positions.assign(7, 0.1 * k);
    p.velocities.assign(7, 0.0);
    p.accelerations.assign(7, 0.0);
    res.trajectory.points.push_back(p);
  }
  res.trajectory.num_points = 2;
  send("PLAN_RESULT", res);
  ASSERT_EQ(commands.got.size(), 1u);
  EXPECT_EQ(commands.got[0].mode, arm_command_t::TRAJECTORY);
  EXPECT_EQ(commands.got[0].trajectory.num_points, 2);
  EXPECT_EQ(commands.got[0].trajectory.points[1].positions[3], 0.1);
  const int64_t cmd = commands.got[0].command_id;

  // While it runs: a heartbeat at most every 0.05 s of message time.
  send("ARM_STATE", arm(3000 + 30000, arm_state_t::EXECUTING, cmd));
  EXPECT_EQ(commands.got.size(), 1u) << "30 ms < heartbeat period";
  send("ARM_STATE", arm(3000 + 60000, arm_state_t::EXECUTING, cmd));
  ASSERT_EQ(commands.got.size(), 2u);
  EXPECT_EQ(commands.got[1].mode, arm_command_t::HEARTBEAT);
  EXPECT_EQ(commands.got[1].utime, 63000);
  send("ARM_STATE", arm(1100000, arm_state_t::IDLE, cmd));
  EXPECT_EQ(status.got.back().state, "WAIT_P1_CHECK");

  // The arbiter has no PS: plan to the stripe servo's start A = grasp (0.10, 0.36, -0.07) (coordinator.yaml)
  // -> base (0.60 - 0.07, -0.05 - 0.36, 0.10) = (0.53, -0.41, 0.10), gripper axes = grasp axes.
  grasp_point_t need;
  need.utime = 1200000;
  need.request_id = 0;
  need.valid = false;
  need.slope_rad = 0;
  need.p1_used = need.p2_used = false;
  need.reason = "NEED_PS: no PS known";
  for (int i = 0; i < 3; ++i) need.p1_grasp[i] = need.p2_grasp[i] = need.ps_grasp[i] = need.gp_grasp[i] = NAN;
  need.gp_base = isometry_to_pose(Eigen::Isometry3d::Identity(), "base", "gripper", 0);
  need.num_steps = 0;
  send("GRASP_POINT", need);
  ASSERT_EQ(plans.got.size(), 2u);
  const plan_request_t& a = plans.got[1];
  EXPECT_EQ(a.goal_type, plan_request_t::POSE);
  EXPECT_NEAR(a.goal_pose.position[0], 0.53, 1e-9);
  EXPECT_NEAR(a.goal_pose.position[1], -0.41, 1e-9);
  EXPECT_NEAR(a.goal_pose.position[2], 0.10, 1e-9);
  const Eigen::Matrix3d r = pose_to_isometry(a.goal_pose).linear();
  EXPECT_TRUE(r.isApprox(bookgrasp_test::hand_grasp_frame().linear(), 1e-9)) << r;
  EXPECT_EQ(a.num_joints, 7);
  EXPECT_EQ(a.goal_joints.size(), 7u) << "array length field shared with start_joints";
  EXPECT_EQ(status.got.back().state, "MOVE_TO_STRIPE_START");

  // Bad inputs are rejected; the node goes on.
  arm_state_t bad_arm = arm(1300000, arm_state_t::IDLE, 0);
  bad_arm.positions[2] = NAN;
  send("ARM_STATE", bad_arm);
  grasp_point_t bad_gp = need;
  bad_gp.reason = "NEXT_REGION: no rank";
  send("GRASP_POINT", bad_gp);
  auto bad_markers = markers(1400000);
  bad_markers.markers[0].pose_in_base.position[0] = NAN;
  send("MARKERS", bad_markers);
  EXPECT_EQ(node.rejected_total(), 3);

  // The progress file holds where the task is; a restarted node resumes from it.
  const auto saved = load_progress(path);
  ASSERT_TRUE(saved);
  EXPECT_EQ(saved->last_state, "MOVE_TO_STRIPE_START");
  EXPECT_EQ(saved->place, BookPlace::kUpperShelf);
  Composition comp2;
  auto& node2 = comp2.add(std::make_unique<CoordinatorNode>(Config::from_string(config_text(path), "c.yaml")));
  EXPECT_EQ(node2.cycle().progress().last_state, "MOVE_TO_STRIPE_START");
  EXPECT_NE(node2.cycle().status().message.find("resuming"), std::string::npos);
}

TEST_F(CoordinatorNodeTest, CorruptProgressFileFailsAtStartNamingTheFile) {
  {
    FILE* f = std::fopen(path.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs("books_moved: [\n", f);
    std::fclose(f);
  }
  try {
    CoordinatorNode n(Config::from_string(config_text(path), "c.yaml"));
    FAIL() << "a corrupt progress file must stop the start";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("move it away"), std::string::npos) << e.what();
  }
}

// A plan with a held book, one straight move after it and two placed books to avoid, as the message the planner reads
// (it decodes after an encode, with every box's name, pose in base and size).
TEST(PlanRequestMessage, CarriesTheHeldBookTheStraightMovesAndTheBoxesToAvoid) {
  CycleSettings s;
  s.planner = "RRTConnect";
  s.plan_position_tolerance_m = 0.002;
  s.plan_orientation_tolerance_rad = 0.02;
  s.plan_time_budget_s = 10.0;
  CycleRequest r;
  r.kind = CycleRequest::Kind::kPlan;
  r.id = 17;
  r.start_joints = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7};
  r.pose.translation() = Eigen::Vector3d(0.6, -0.1, -0.1);
  r.holding_book = true;
  r.book_size = Eigen::Vector3d(0.02, 0.25, 0.30);
  r.then_poses = {r.pose};
  for (int i = 0; i < 2; ++i) {
    OrientedBox b;
    b.pose.translation() = Eigen::Vector3d(0.9, -0.14 + 0.04 * i, -0.19);
    b.size = Eigen::Vector3d(0.27, 0.04, 0.32);
    r.obstacles.emplace_back("lower_shelf_book_" + std::to_string(i), b);
  }
  const plan_request_t m = plan_request_message(r, s, 5000);
  std::vector<uint8_t> buf(m.getEncodedSize());
  ASSERT_EQ(m.encode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  plan_request_t d;
  ASSERT_EQ(d.decode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  EXPECT_EQ(d.request_id, 17);
  EXPECT_EQ(d.planner, "RRTConnect");
  EXPECT_EQ(d.goal_type, plan_request_t::POSE);
  EXPECT_TRUE(d.holding_book);
  EXPECT_EQ(d.held_book_size_m[1], 0.25);
  EXPECT_EQ(d.num_then_poses, 1);
  ASSERT_EQ(d.num_obstacles, 2);
  ASSERT_EQ(d.obstacles.size(), 2u);
  EXPECT_EQ(d.obstacles[1].name, "lower_shelf_book_1");
  EXPECT_EQ(d.obstacles[1].pose.frame, "base");
  EXPECT_NEAR(d.obstacles[1].pose.position[1], -0.10, 1e-12);
  EXPECT_NEAR(d.obstacles[1].pose.orientation[0], 1.0, 1e-12);
  EXPECT_EQ(d.obstacles[0].size_m[0], 0.27);
  EXPECT_EQ(d.obstacles[0].size_m[2], 0.32);
  r.obstacles.clear();
  EXPECT_EQ(plan_request_message(r, s, 5000).num_obstacles, 0);
}

TEST(DecisionFromMessage, ParsesOutcomeAndRank) {
  grasp_point_t g;
  g.utime = 5;
  g.request_id = 9;
  g.valid = false;
  g.reason = "NEXT_REGION rank 2: BwH chose a false region [P1 from 'god']";
  for (int i = 0; i < 3; ++i) g.p1_grasp[i] = g.p2_grasp[i] = g.ps_grasp[i] = g.gp_grasp[i] = 0.1;
  g.gp_base = isometry_to_pose(Eigen::Isometry3d::Identity(), "base", "gripper", 0);
  const DecisionEvent d = decision_from_message(g);
  EXPECT_EQ(d.outcome, "NEXT_REGION");
  EXPECT_EQ(d.next_rank, 2);
  EXPECT_EQ(d.request_id, 9);
  EXPECT_TRUE(d.p1_present);
  g.reason = "GRASP: GP = (1, 2, 3) mm";
  EXPECT_EQ(decision_from_message(g).outcome, "GRASP");
  g.p1_grasp[1] = NAN;
  EXPECT_FALSE(decision_from_message(g).p1_present);
}

}  // namespace
}  // namespace bookgrasp
