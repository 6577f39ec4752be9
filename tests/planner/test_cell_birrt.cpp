// CellBiRRT as an OMPL planner on its own: solves through a narrow opening,
// its cell samples satisfy the end-effector constraint, it times out cleanly.
#include "services/planner/cell_birrt.h"

#include <gtest/gtest.h>
#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/goals/GoalStates.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathGeometric.h>

#include "services/planner/planner_config.h"

namespace bookgrasp {
namespace {
namespace ob = ompl::base;

const std::string kConfig = std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/planner.yaml";

SceneBox box(const std::string& name, const Eigen::Vector3d& centre, const Eigen::Vector3d& size) {
  SceneBox b;
  b.name = name;
  b.pose.translation() = centre;
  b.size = size;
  return b;
}

struct Fixture {
  PlannerSettings settings = PlannerSettings::load(kConfig);
  PlannerStack stack{settings};
  PlanningScene scene = stack.scene;
  ob::SpaceInformationPtr si;
  Fixture() {
    auto space = std::make_shared<ob::RealVectorStateSpace>(7);
    ob::RealVectorBounds b(7);
    for (int k = 0; k < 7; ++k) {
      b.setLow(k, stack.kinematics.lower_limits()[k]);
      b.setHigh(k, stack.kinematics.upper_limits()[k]);
    }
    space->setBounds(b);
    si = std::make_shared<ob::SpaceInformation>(space);
    si->setStateValidityChecker([this](const ob::State* s) {
      const auto* v = s->as<ob::RealVectorStateSpace::StateType>()->values;
      return scene.is_valid(Eigen::Map<const Eigen::VectorXd>(v, 7));
    });
    si->setStateValidityCheckingResolution(0.002);
    si->setup();
  }
  ob::ProblemDefinitionPtr problem(const Eigen::VectorXd& a, const Eigen::VectorXd& g) {
    auto pdef = std::make_shared<ob::ProblemDefinition>(si);
    ob::ScopedState<> s(si->getStateSpace());
    for (int k = 0; k < 7; ++k) s[k] = a[k];
    pdef->addStartState(s);
    auto goals = std::make_shared<ob::GoalStates>(si);
    for (int k = 0; k < 7; ++k) s[k] = g[k];
    goals->addState(s);
    pdef->setGoal(goals);
    return pdef;
  }
  CellBiRrtProblem cell_problem(const Eigen::VectorXd& a, const Eigen::VectorXd& g) {
    CellBiRrtProblem p;
    p.start_tip = stack.kinematics.tip_pose(a);
    p.goal_tip = stack.kinematics.tip_pose(g);
    p.seed = 3;
    const auto env = scene.environment();
    p.point_free = [env](const Eigen::Vector3d& x) {
      for (const auto& b : env)
        if (((b.pose.inverse() * x).cwiseAbs() - 0.5 * b.size).maxCoeff() < 0) return false;
      return true;
    };
    return p;
  }
};

CellBiRrtParams params() {
  CellBiRrtParams p;
  p.range_rad = 0.4;
  p.cell_size_m = 0.1;
  p.workspace_min = Eigen::Vector3d(-1.1, -1.1, -0.55);
  p.workspace_max = Eigen::Vector3d(1.1, 1.1, 1.3);
  return p;
}

TEST(CellBiRRT, ReachesIntoAShelfSlot) {
  Fixture s;
  // A shelf slot 0.23 m high in front of the robot: boards above and below, a back wall.
  s.scene.set_environment({box("upper", {0.75, 0, 0.50}, {0.4, 1.0, 0.02}), box("lower", {0.75, 0, 0.25}, {0.4, 1.0, 0.02}),
                           box("back", {0.96, 0, 0.3}, {0.02, 1.0, 0.6}), box("floor", {0, 0, -0.6}, {3, 3, 0.1})});
  const Eigen::VectorXd start = Eigen::VectorXd::Zero(7);
  Eigen::Isometry3d inside = Eigen::Isometry3d::Identity();
  inside.linear().col(0) = Eigen::Vector3d::UnitZ();
  inside.linear().col(1) = -Eigen::Vector3d::UnitY();
  inside.linear().col(2) = Eigen::Vector3d::UnitX();
  inside.translation() = Eigen::Vector3d(0.70, -0.35, 0.35);  // TCP 15 cm deep in the slot
  const IkResult ik = s.stack.ik.solve(inside, s.settings.ik.preferred_posture);
  ASSERT_TRUE(ik.success) << ik.reason;
  ASSERT_TRUE(s.scene.is_valid(ik.q)) << s.scene.check(ik.q).describe();
  auto pdef = s.problem(start, ik.q);
  CellBiRRT planner(s.si, s.stack.ik, params(), s.cell_problem(start, ik.q));
  planner.setProblemDefinition(pdef);
  planner.setup();
  const ob::PlannerStatus st = planner.solve(ob::timedPlannerTerminationCondition(5.0));
  ASSERT_EQ(st, ob::PlannerStatus::EXACT_SOLUTION);
  const auto* path = pdef->getSolutionPath()->as<ompl::geometric::PathGeometric>();
  ASSERT_GE(path->getStateCount(), 2u);
  EXPECT_GT(planner.cell_samples_tried(), 0);
  // Every edge is collision-free at a fine resolution with the exact geometry.
  for (size_t i = 1; i < path->getStateCount(); ++i) {
    const auto* a = path->getState(i - 1)->as<ob::RealVectorStateSpace::StateType>()->values;
    const auto* b = path->getState(i)->as<ob::RealVectorStateSpace::StateType>()->values;
    const Eigen::VectorXd qa = Eigen::Map<const Eigen::VectorXd>(a, 7), qb = Eigen::Map<const Eigen::VectorXd>(b, 7);
    for (int k = 0; k <= 200; ++k) EXPECT_FALSE(s.scene.check(qa + (k / 200.0) * (qb - qa), false).collision);
  }
}

TEST(CellBiRRT, TimeoutAndInvalidGoal) {
  Fixture s;
  // A pillar between the arm pointing left and the arm pointing right.
  s.scene.set_environment({box("pillar", {0.55, 0.0, 0.1}, {0.2, 0.2, 1.2})});
  Eigen::VectorXd start(7), goal(7);
  start << -1.0, 1.2, 0.0, 0.8, 0.0, 0.6, 0.0;
  goal << 1.0, 1.2, 0.0, 0.8, 0.0, 0.6, 0.0;
  ASSERT_TRUE(s.scene.is_valid(start) && s.scene.is_valid(goal));
  {
    auto pdef = s.problem(start, goal);
    CellBiRRT planner(s.si, s.stack.ik, params(), s.cell_problem(start, goal));
    planner.setProblemDefinition(pdef);
    planner.setup();
    EXPECT_EQ(planner.solve(ob::timedPlannerTerminationCondition(1e-6)), ob::PlannerStatus::TIMEOUT);
    EXPECT_FALSE(pdef->hasExactSolution());
  }
  {
    // Goal with the forearm through the pillar.
    Eigen::VectorXd bad = Eigen::VectorXd::Zero(7);
    bad[1] = 1.5707963;
    ASSERT_FALSE(s.scene.is_valid(bad));
    auto pdef = s.problem(start, bad);
    CellBiRRT planner(s.si, s.stack.ik, params(), s.cell_problem(start, bad));
    planner.setProblemDefinition(pdef);
    planner.setup();
    EXPECT_EQ(planner.solve(ob::timedPlannerTerminationCondition(1.0)), ob::PlannerStatus::INVALID_GOAL);
  }
  {
    // And it does solve the same problem given time, deterministically for a seed.
    auto p1 = s.problem(start, goal), p2 = s.problem(start, goal);
    CellBiRRT a(s.si, s.stack.ik, params(), s.cell_problem(start, goal)), b(s.si, s.stack.ik, params(), s.cell_problem(start, goal));
    a.setProblemDefinition(p1);
    b.setProblemDefinition(p2);
    a.setup();
    b.setup();
    ASSERT_EQ(a.solve(ob::timedPlannerTerminationCondition(5.0)), ob::PlannerStatus::EXACT_SOLUTION);
    ASSERT_EQ(b.solve(ob::timedPlannerTerminationCondition(5.0)), ob::PlannerStatus::EXACT_SOLUTION);
    const auto* pa = p1->getSolutionPath()->as<ompl::geometric::PathGeometric>();
    const auto* pb = p2->getSolutionPath()->as<ompl::geometric::PathGeometric>();
    ASSERT_EQ(pa->getStateCount(), pb->getStateCount());
    for (size_t i = 0; i < pa->getStateCount(); ++i) EXPECT_EQ(s.si->distance(pa->getState(i), pb->getState(i)), 0.0);
  }
}

}  // namespace
}  // namespace bookgrasp
