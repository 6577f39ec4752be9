// bookgrasp_eval_hand on one scene: metrics.json structure, and the reported errors are the converged TCP
// against the simulation's ground truth (recomputed here from a freshly generated scene).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <yaml-cpp/yaml.h>

#include "services/eval_hand/hand_scene_eval.h"
#include "services/eval_hand/hand_servo_harness.h"

namespace bookgrasp {
namespace {

const std::string kScene = std::string(BOOKGRASP_SOURCE_DIR) + "/services/eval_hand/scenes/hand_eval.yaml";

int run_tool(const std::string& args) {
  const std::string cmd =
      std::string(BOOKGRASP_EVAL_HAND_EXE) + " " + args + " 2>" + ::testing::TempDir() + "/eval_hand_err.txt";
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

Eigen::Vector3d vec(const YAML::Node& n) {
  return {n[0].as<double>(), n[1].as<double>(), n[2].as<double>()};
}

TEST(EvalHandTool, OneSceneMetricsAgainstTheTruth) {
  const uint64_t seed = 2;
  const std::string out = ::testing::TempDir() + "/eval_hand_one";
  std::filesystem::remove_all(out);
  ASSERT_EQ(run_tool("--scenes 1 --seed " + std::to_string(seed) + " --out " + out), 0);
  const YAML::Node j = YAML::LoadFile(out + "/metrics.json");
  EXPECT_EQ(j["scenes"].as<int>(), 1);
  ASSERT_TRUE(j["failures"].IsSequence());
  for (const char* axis : {"x", "y"})
    for (const char* s : {"mean", "max"}) EXPECT_TRUE(j["stripe_error_mm"][axis][s].IsDefined()) << axis << s;
  for (const char* axis : {"x", "y", "z"})
    for (const char* s : {"mean", "max"}) EXPECT_TRUE(j["p2_error_mm"][axis][s].IsDefined()) << axis << s;
  EXPECT_TRUE(j["stripe_within_tolerance_rate"].IsDefined());
  EXPECT_TRUE(j["slope_error_deg"]["mean"].IsDefined());
  EXPECT_TRUE(j["slope_error_deg"]["max"].IsDefined());
  EXPECT_TRUE(j["servo_iterations"]["median"].IsDefined());
  for (const char* d : {"bwh", "bswh", "markers"}) {
    ASSERT_TRUE(j["ms_per_frame"][d]["median"].IsDefined()) << d;
    EXPECT_GT(j["ms_per_frame"][d]["n"].as<int>(), 0) << d;
  }
  for (const char* f : {"report.md", "figure13_p2_error.png", "figure14_stripe_end.png", "slope_error.png"})
    EXPECT_TRUE(std::filesystem::exists(out + "/" + f)) << f;

  // The truth, independently: the scene generated again (not taken from the run).
  const scene::Scene sc = scene::load_scene(kScene, seed);
  const ground_truth_t t = scene_truth(sc);
  Eigen::Vector3d p1 = Eigen::Vector3d::Constant(NAN);
  for (const auto& b : t.books)
    if (b.rightmost) p1 = Eigen::Vector3d(b.p1_base[0], b.p1_base[1], b.p1_base[2]);
  const Eigen::Vector3d end(t.stripe_end_base[0], t.stripe_end_base[1], t.stripe_end_base[2]);
  ASSERT_EQ(j["runs"].size(), 1u);
  const YAML::Node run = j["runs"][0];
  int checked = 0;
  for (const auto& [task, truth] : {std::make_pair("stripe", end), std::make_pair("corner", p1)}) {
    const YAML::Node r = run[task];
    if (!r["converged"].as<bool>()) continue;
    ++checked;
    // The point compared with is the true one (books settle by less than a millimetre).
    EXPECT_LT((vec(r["truth_base"]) - truth).norm(), 0.002) << task;
    const Eigen::Isometry3d g = grasp_pose_for_cart(sc, truth);
    const Eigen::Vector3d e = g.inverse() * vec(r["tcp_base"]);
    const Eigen::Vector3d reported = vec(r["error_mm"]) * 1e-3;
    EXPECT_NEAR(reported.x(), e.x(), 0.0005) << task;
    EXPECT_NEAR(reported.y(), e.y(), 0.0005) << task;
  }
  EXPECT_GE(checked, 1) << "neither task converged on seed " << seed;
}

TEST(EvalHandTool, BadArgumentsAreRefusedWithAReason) {
  EXPECT_EQ(run_tool("--scenes 0 --seed 1 --out /tmp/x"), 2);
  EXPECT_EQ(run_tool("--scenes 1 --out /tmp/x"), 2);
  EXPECT_EQ(run_tool("--scenes 1 --seed 1"), 2);
  EXPECT_EQ(run_tool("--scenes 1 --seed 1 --scene /no/such.yaml --out /tmp/x"), 2);
  EXPECT_EQ(run_tool("--bogus 1"), 2);
}

TEST(SlopeError, SignedAngleBetweenGripperXAndBookUp) {
  const Eigen::Matrix3d grasp = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d g = Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  // Book up along grasp X (gripper x): body z -> grasp x.
  Eigen::Matrix3d book;
  book.col(2) = Eigen::Vector3d::UnitX();
  book.col(0) = Eigen::Vector3d::UnitZ();
  book.col(1) = book.col(2).cross(book.col(0));
  EXPECT_NEAR(slope_error_deg(grasp, g, book), 0.05 * 180 / M_PI, 1e-9);
  EXPECT_NEAR(slope_error_deg(grasp, grasp, book), 0.0, 1e-9);
}

}  // namespace
}  // namespace bookgrasp
