// The benchmark's library queries: feasible by construction (valid starts, goals with a
// collision-free IK solution), the three kinds in turn, deterministic for a seed.
#include "services/planner/bench_queries.h"

#include <gtest/gtest.h>

namespace bookgrasp {
namespace {

const std::string kConfig = std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/planner.yaml";

TEST(BenchQueries, FeasibleKindsInTurnAndDeterministic) {
  const PlannerSettings settings = PlannerSettings::load(kConfig);
  const PlannerStack stack(settings);
  const auto a = make_library_queries(settings, stack, 9, 4);
  const auto b = make_library_queries(settings, stack, 9, 4);
  ASSERT_EQ(a.size(), 9u);
  const char* kinds[] = {"pregrasp", "holder", "lower"};
  PlanningScene scene = stack.scene;
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].kind, kinds[i % 3]);
    EXPECT_EQ(a[i].holding_book, i % 3 != 0);
    EXPECT_TRUE(a[i].request.start == b[i].request.start);
    EXPECT_TRUE(a[i].request.goal_pose.isApprox(b[i].request.goal_pose));
    apply_query_scene(a[i], settings.held_book, scene);
    EXPECT_TRUE(scene.is_valid(a[i].request.start)) << a[i].kind << ": " << scene.check(a[i].request.start).describe();
    // The pre-grasp pose is in front of the cart (base x 0.4 .. 0.65) at upper-shelf book height.
    if (a[i].kind == "pregrasp") {
      EXPECT_GT(a[i].request.goal_pose.translation().x(), 0.3);
      EXPECT_LT(a[i].request.goal_pose.translation().x(), 0.7);
      EXPECT_GT(a[i].request.goal_pose.translation().z(), 0.1);
    }
  }
  EXPECT_TRUE(scene.kinematics().within_limits(bench_home_joints()));
}

}  // namespace
}  // namespace bookgrasp
