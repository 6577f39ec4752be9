// The straight moves after a planned pre-grasp (INSERT to the grasp pose, EXTRACT's lift and retreat), made by the
// arm driver's own Cartesian law (services/arm_driver/arm_driver_core.h, config/services/arm_driver.yaml) from the
// goal posture the planner chose, for every book of far_cart seeds 1-12 (cycle_reach's poses from the scenes'
// truth): with the request's then_poses the driver completes them; without (the goal posture picked for the
// pre-grasp alone) it stopped at a joint limit (whole-shelf runs: EXTRACT at arm_5's limit, far_cart seeds 1, 6).
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "common/config.h"
#include "services/arm_driver/arm_driver_node.h"
#include "services/coordinator/library_cycle.h"
#include "services/eval_full/cycle_reach.h"
#include "services/planner/planner_config.h"
#include "services/planner/scene_geometry.h"

namespace bookgrasp {
namespace {

const std::string kSrc = BOOKGRASP_SOURCE_DIR;

// The coordinator's straight-move law (library_cycle.cpp, MotionKind::kLinear) on the driver, 100 Hz message time,
// through `waypoints` from posture `q`. "" when every waypoint was reached, else the driver's reason.
std::string drive_straight(const Config& driver_config, const CycleSettings& s, const Eigen::VectorXd& q,
                           const std::vector<Eigen::Isometry3d>& waypoints) {
  ArmDriverCore driver = make_arm_driver_core(driver_config);
  const ArmKinematics kin = ArmKinematics::from_urdf_file(kSrc + "/config/robot/lwa3_pg70.urdf", "base", "gripper");
  int64_t t = 1000000;
  driver.on_measurement(t, q, 0.06);
  Eigen::VectorXd at = q;
  int64_t id = 1;
  for (const Eigen::Isometry3d& target : waypoints) {
    for (int step = 0; step < 6000; ++step) {  // 60 s
      const Eigen::Isometry3d tcp = kin.tip_pose(at);
      const Eigen::Vector3d ep = target.translation() - tcp.translation();
      const Eigen::AngleAxisd er(target.linear() * tcp.linear().transpose());
      if (ep.norm() < s.linear_position_tolerance && std::abs(er.angle()) < s.linear_orientation_tolerance) break;
      Eigen::Vector3d v = s.linear_gain * ep;
      if (v.norm() > s.linear_max_speed) v *= s.linear_max_speed / v.norm();
      Eigen::Vector3d w = s.linear_gain * er.angle() * er.axis();
      if (w.norm() > s.linear_max_angular_speed) w *= s.linear_max_angular_speed / w.norm();
      Eigen::Matrix<double, 6, 1> twist;
      twist << v, w;
      const std::string refused = driver.command_cartesian_velocity(twist, "base", ++id);
      if (!refused.empty()) return "refused: " + refused;
      t += 10000;
      const DriverSetpoint sp = driver.update(t);
      if (driver.state() == DriverState::kStopped || driver.state() == DriverState::kFault) return driver.message();
      at = sp.q;
      driver.on_measurement(t, at, 0.06);
    }
  }
  return "";
}

TEST(StraightMovesAfterPlan, TheDriverCompletesInsertAndExtractFromThePlannedPreGraspPosture) {
  const Config coordinator = Config::load_file(kSrc + "/config/services/coordinator.yaml");
  const CycleSettings cs = CycleSettings::from_config(coordinator);
  const CycleGeometry& g = cs.geometry;
  const Config driver_config = Config::load_file(kSrc + "/config/services/arm_driver.yaml");
  const PlannerSettings settings = PlannerSettings::load(kSrc + "/config/services/planner.yaml");
  const PlannerStack stack(settings);
  const Eigen::Isometry3d flip(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  Eigen::VectorXd park(7);
  for (int j = 0; j < 7; ++j) park[j] = cs.park_joints[j];
  int books = 0, unplannable = 0, completed_with = 0, completed_without = 0;
  for (uint64_t seed = 1; seed <= 12; ++seed) {
    const scene::Scene truth = scene::load_scene(kSrc + "/config/scenes/far_cart.yaml", seed);
    PlanningScene scene = stack.scene;
    scene.set_environment(build_environment(
        settings.geometry, {{"cart", truth.cart_marker.pose * flip}, {"holder", truth.holder_marker.pose * flip}}));
    for (size_t b = 0; b < truth.books.size(); ++b) {
      const std::vector<StageReach> stages = cycle_reach(truth, g, stack.ik, park, b);
      std::map<std::string, const StageReach*> by;
      for (const StageReach& st : stages) by[st.stage] = &st;
      const std::vector<std::string> needed{"pre_grasp", "grasp", "extract_lift", "extract_end"};
      bool reachable = true;
      for (const std::string& n : needed) reachable = reachable && by.at(n)->reachable;
      if (!reachable) continue;  // out of the arm's reach whatever the posture (bookgrasp_cycle_reach)
      ++books;
      const std::vector<Eigen::Isometry3d> then{by.at("grasp")->tcp, by.at("extract_lift")->tcp,
                                                by.at("extract_end")->tcp};
      PlanRequest req;
      req.start = park;
      req.goal_is_pose = true;
      req.goal_pose = by.at("pre_grasp")->tcp;
      req.position_tolerance_m = cs.plan_position_tolerance_m;
      req.orientation_tolerance_rad = cs.plan_orientation_tolerance_rad;
      req.time_budget_s = 2.0;
      req.seed = seed * 100 + b;
      const PlanOutcome without = stack.planner.plan(scene, req);
      req.then_poses = then;
      const PlanOutcome with = stack.planner.plan(scene, req);
      if (!with.success) {  // e.g. the pre-grasp of a book at the shelf's left end: the palm in the holder
        EXPECT_FALSE(without.success) << "then_poses made a plannable goal unplannable: " << with.message;
        ++unplannable;
        continue;
      }
      const std::string why_with = drive_straight(driver_config, cs, with.path.back(), then);
      completed_with += why_with.empty();
      EXPECT_EQ(why_with, "") << "seed " << seed << " book " << b << " (" << with.message << ")";
      if (without.success) completed_without += drive_straight(driver_config, cs, without.path.back(), then).empty();
    }
  }
  std::printf(
      "far_cart seeds 1-12, %d books within reach (%d of them with no collision-free pre-grasp): INSERT + "
      "EXTRACT completed by the driver from the planned pre-grasp posture in %d with then_poses, %d without\n",
      books, unplannable, completed_with, completed_without);
  EXPECT_GT(books, 100);
}

}  // namespace
}  // namespace bookgrasp
