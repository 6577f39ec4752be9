// The arm driver in the loop with the real planner and the simulated arm, composed on memq and
// driven by simulation time: a planned trajectory is executed and ends at its goal; losing the
// heartbeat stops the arm.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <vector>

#include "bookgrasp/arm_command_t.hpp"
#include "bookgrasp/arm_state_t.hpp"
#include "bookgrasp/plan_request_t.hpp"
#include "bookgrasp/plan_result_t.hpp"
#include "common/composition.h"
#include "services/arm_driver/arm_driver_node.h"
#include "services/planner/planner_config.h"
#include "services/planner/planner_node.h"
#include "services/sim_world/sim_world_node.h"

namespace bookgrasp {
namespace {

const std::string kSrc = BOOKGRASP_SOURCE_DIR;

/// Latest message of a type on a channel.
template <typename Msg>
struct Latest {
  std::vector<Msg> all;
  void on(const lcm::ReceiveBuffer*, const std::string&, const Msg* m) { all.push_back(*m); }
};

class DriverInSimulation : public testing::Test {
 protected:
  void SetUp() override {
    const Config sim_cfg = Config::load_file(kSrc + "/config/services/sim_world.yaml");
    SimWorldSettings sim_settings = SimWorldSettings::from_config(sim_cfg);
    sim_settings.drive = "external";  // the test advances simulation time itself
    sim_ = &comp_.add(std::make_unique<SimWorldNode>(sim_settings));
    comp_.add(std::make_unique<ArmDriverNode>(Config::load_file(kSrc + "/config/services/arm_driver.yaml")));
    PlannerSettings planner = PlannerSettings::from_config(Config::load_file(kSrc + "/config/services/planner.yaml"));
    planner.defer_until_markers = false;  // no marker detector here: the nominal scene
    comp_.add(std::make_unique<PlannerNode>(planner));
    comp_.bus().subscribe("ARM_STATE", &Latest<arm_state_t>::on, &state_);
    comp_.bus().subscribe("PLAN_RESULT", &Latest<plan_result_t>::on, &plan_);
    t_ = sim_->world().now_utime();
    advance(0.2);
  }
  /// Advances simulation time by `seconds` in 10 ms steps, sending a heartbeat every 0.1 s if asked.
  void advance(double seconds, bool heartbeat = false) {
    const int steps = static_cast<int>(std::lround(seconds / 0.01));
    for (int i = 0; i < steps; ++i) {
      t_ += 10000;
      if (heartbeat && i % 10 == 0) {
        arm_command_t hb{};
        hb.utime = t_;
        hb.mode = arm_command_t::HEARTBEAT;
        hb.twist_frame = "base";
        comp_.bus().publish("ARM_COMMAND", &hb);
      }
      sim_->advance_to(t_);
      comp_.spin();
    }
  }
  Eigen::VectorXd measured() const {
    const auto& s = state_.all.back();
    return Eigen::Map<const Eigen::VectorXd>(s.positions.data(), s.num_joints);
  }
  plan_result_t plan_to(const Eigen::VectorXd& goal) {
    plan_request_t r{};
    r.utime = t_;
    r.request_id = 11;
    r.planner = "CellBiRRT";
    r.goal_type = plan_request_t::JOINTS;
    const Eigen::VectorXd start = measured();
    r.num_joints = static_cast<int32_t>(start.size());
    r.start_joints.assign(start.data(), start.data() + start.size());
    r.goal_joints.assign(goal.data(), goal.data() + goal.size());
    r.goal_pose.orientation[0] = 1;
    r.time_budget_s = 5.0;
    r.held_book_size_m[0] = r.held_book_size_m[1] = r.held_book_size_m[2] = 0;
    plan_.all.clear();
    comp_.bus().publish("PLAN_REQUEST", &r);
    comp_.spin();
    EXPECT_EQ(plan_.all.size(), 1u);
    return plan_.all.empty() ? plan_result_t{} : plan_.all.back();
  }
  void execute(const plan_result_t& plan) {
    arm_command_t c{};
    c.utime = t_;
    c.command_id = 21;
    c.mode = arm_command_t::TRAJECTORY;
    c.trajectory = plan.trajectory;
    c.twist_frame = "base";
    comp_.bus().publish("ARM_COMMAND", &c);
    comp_.spin();
  }

  Composition comp_;
  SimWorldNode* sim_ = nullptr;
  Latest<arm_state_t> state_;
  Latest<plan_result_t> plan_;
  int64_t t_ = 0;
};

Eigen::VectorXd goal_pose() {
  Eigen::VectorXd g(7);
  g << 0.8, 0.3, 0.0, 1.2, 0.0, 1.0, 0.0;  // gripper at about (0.43, -0.44, 0.42) m: above, right of the cart
  return g;
}

TEST_F(DriverInSimulation, ExecutesAPlannedTrajectoryToItsGoal) {
  ASSERT_FALSE(state_.all.empty()) << "no ARM_STATE: the driver did not see SIM_STATE";
  const plan_result_t plan = plan_to(goal_pose());
  ASSERT_TRUE(plan.success) << plan.message;
  ASSERT_GT(plan.trajectory.num_points, 1);
  execute(plan);
  EXPECT_EQ(state_.all.back().state, arm_state_t::EXECUTING) << state_.all.back().message;
  const double duration = plan.trajectory.points.back().utime * 1e-6;
  advance(duration + 1.5, true);
  const auto& s = state_.all.back();
  EXPECT_EQ(s.state, arm_state_t::IDLE) << s.message;
  const Eigen::VectorXd err = measured() - goal_pose();
  EXPECT_LT(err.cwiseAbs().maxCoeff(), 0.01) << "joint error (rad): " << err.transpose();
  // The gripper where forward kinematics puts the goal, within 1 mm.
  const ArmKinematics kin = ArmKinematics::from_urdf_file(kSrc + "/config/robot/lwa3_pg70.urdf", "base", "gripper");
  const Eigen::Vector3d want = kin.tip_pose(goal_pose()).translation();
  const Eigen::Vector3d got(s.end_effector.position[0], s.end_effector.position[1], s.end_effector.position[2]);
  EXPECT_LT((got - want).norm(), 0.001) << "TCP " << got.transpose() << " vs goal " << want.transpose();
}

TEST_F(DriverInSimulation, HeartbeatLossStopsTheArm) {
  const plan_result_t plan = plan_to(goal_pose());
  ASSERT_TRUE(plan.success) << plan.message;
  execute(plan);
  advance(0.3, true);
  advance(1.0, false);  // the commander goes silent
  const auto& s = state_.all.back();
  EXPECT_EQ(s.state, arm_state_t::STOPPED);
  EXPECT_NE(s.message.find("heartbeat"), std::string::npos) << s.message;
  const Eigen::VectorXd held = measured();
  advance(1.0, false);
  EXPECT_LT((measured() - held).cwiseAbs().maxCoeff(), 0.01) << "the arm keeps still after the stop";
  EXPECT_GT((measured() - goal_pose()).cwiseAbs().maxCoeff(), 0.05) << "it stopped short of the goal";
}

}  // namespace
}  // namespace bookgrasp

namespace bookgrasp {
namespace {

// The planner must never produce what the driver refuses: its velocity and acceleration limits lie
// within the driver's, and both use the same tool workspace.
TEST(DriverAndPlannerConfigs, PlannerLimitsLieWithinTheDriverLimits) {
  const Config drv = Config::load_file(kSrc + "/config/services/arm_driver.yaml");
  const Config pln = Config::load_file(kSrc + "/config/services/planner.yaml");
  const ArmDriverCore core = make_arm_driver_core(drv);
  const PlannerSettings ps = PlannerSettings::from_config(pln);
  const auto pv = pln.get<std::vector<double>>("planner.max_velocity_rad_s");
  const auto pa = pln.get<std::vector<double>>("planner.max_acceleration_rad_s2");
  ASSERT_EQ(pv.size(), 7u);
  ASSERT_EQ(pa.size(), 7u);
  for (int j = 0; j < 7; ++j) {
    EXPECT_LE(pv[j], core.limits().max_velocity[j]) << "joint " << j;
    EXPECT_LE(pa[j], core.limits().max_acceleration[j]) << "joint " << j;
  }
  EXPECT_TRUE(ps.scene.tool_min.isApprox(core.limits().workspace_min));
  EXPECT_TRUE(ps.scene.tool_max.isApprox(core.limits().workspace_max));
}

}  // namespace
}  // namespace bookgrasp

namespace bookgrasp {
namespace {

// A preferred posture outside the joint limits is a configuration error naming the key.
TEST(DriverConfig, NullspacePostureOutsideTheLimitsIsRefused) {
  std::ifstream in(kSrc + "/config/services/arm_driver.yaml");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  const std::string good = "preferred_posture: [0.0, 0.6, 0.0, 1.5, 0.0, 0.6, 0.0]";
  const auto at = text.find(good);
  ASSERT_NE(at, std::string::npos) << "arm_driver.yaml changed: update this test";
  EXPECT_NO_THROW(make_arm_driver_core(Config::from_string(text, "arm_driver.yaml")));
  text.replace(at, good.size(), "preferred_posture: [0.0, 0.6, 0.0, 2.5, 0.0, 0.6, 0.0]");
  try {
    make_arm_driver_core(Config::from_string(text, "arm_driver.yaml"));
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("cartesian_nullspace.preferred_posture"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("joint 4"), std::string::npos) << e.what();
  }
}

// arm_driver.yaml with `good` (which must occur in it) replaced by each of `bads` is refused with an error
// naming `key`.
void expect_config_refused(const std::string& good, const std::vector<std::string>& bads, const std::string& key) {
  std::ifstream in(kSrc + "/config/services/arm_driver.yaml");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  const auto at = text.find(good);
  ASSERT_NE(at, std::string::npos) << "arm_driver.yaml changed: update this test";
  for (const std::string& bad : bads) {
    std::string changed = text;
    changed.replace(at, good.size(), bad);
    try {
      make_arm_driver_core(Config::from_string(changed, "arm_driver.yaml"));
      FAIL() << "no error for '" << bad << "'";
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
}

// A negative or missing gripper.open_margin_m is a configuration error naming the key.
TEST(DriverConfig, GripperOpenMarginOutOfRangeOrMissingIsRefused) {
  expect_config_refused("open_margin_m: 0.003", {"open_margin_m: -0.001", ""}, "open_margin_m");
}

// The null-space limit push: a negative, too large or missing margin or gain is refused, naming the key.
TEST(DriverConfig, NullspaceLimitPushOutOfRangeOrMissingIsRefused) {
  expect_config_refused("limit_margin_rad: 0.4", {"limit_margin_rad: -0.1", "limit_margin_rad: 2.0", ""},
                        "cartesian_nullspace.limit_margin_rad");
  expect_config_refused("limit_gain: 2.0", {"limit_gain: -1", "limit_gain: .nan", ""},
                        "cartesian_nullspace.limit_gain");
}

}  // namespace
}  // namespace bookgrasp
