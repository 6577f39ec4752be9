// The BwS evaluation's statistics on hand-made scene results whose counts and errors are worked out by hand.
#include "services/eval_bws/bws_scene_eval.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

namespace bookgrasp::eval_bws {
namespace {

SceneResult scene(uint64_t seed, bool found, bool wrong, double x_mm, double y_mm, double z_mm) {
  SceneResult r;
  r.seed = seed;
  r.found = found;
  r.wrong_book = wrong;
  r.error_grasp = Eigen::Vector3d(x_mm, y_mm, z_mm) / 1000.0;
  if (!found) r.failure = "no P1: no region passed the book-front tests";
  if (wrong) r.failure = "wrong book";
  return r;
}

TEST(BwsSceneEval, CountsFailuresTolerancesAndFarOffCorners) {
  const std::vector<SceneResult> rs = {
      scene(1, true, false, 5.0, -3.0, 2.0),     // right book, within |X| <= 20, |Y| <= 15 mm
      scene(2, true, false, -60.0, 2.0, 1.0),    // right book, 60 mm low: not within, far off (> 50 mm)
      scene(3, true, false, 19.0, 16.0, -4.0),   // right book, Y just outside 15 mm: not within, not far off
      scene(4, true, true, -100.0, -40.0, 3.0),  // wrong book: not in the error statistics
      scene(5, false, false, 0.0, 0.0, 0.0),     // no P1
  };
  std::vector<SceneResult> with_crease = rs;
  with_crease[0].top_crease_shift_m = -0.004;  // P1's height from the top's crease: 4 mm down
  with_crease[4].top_crease_shift_m = 0.002;   // no P1: not counted
  const YAML::Node j = YAML::Load(metrics_json(with_crease, "god", "config/scenes/default.yaml", 1));
  EXPECT_EQ(j["top_crease_applied"].as<int>(), 1);
  EXPECT_NEAR(j["per_scene"][0]["top_crease_shift_mm"].as<double>(), -4.0, 1e-9);
  EXPECT_TRUE(j["per_scene"][1]["top_crease_shift_mm"].IsNull());
  EXPECT_EQ(j["scenes"].as<int>(), 5);
  EXPECT_EQ(j["found"].as<int>(), 4);
  EXPECT_EQ(j["no_p1"].as<int>(), 1);
  EXPECT_EQ(j["wrong_book"].as<int>(), 1);
  EXPECT_EQ(j["failures"].as<int>(), 2);
  EXPECT_EQ(j["correct"].as<int>(), 3);
  EXPECT_EQ(j["within_tolerance"].as<int>(), 1);
  EXPECT_EQ(j["far_off"].as<int>(), 1);
  // |X| over the three correct scenes: 5, 60, 19 -> mean 28, median 19, max 60.
  EXPECT_NEAR(j["p1_error_mm"]["x"]["mean"].as<double>(), 28.0, 1e-3);
  EXPECT_NEAR(j["p1_error_mm"]["x"]["median"].as<double>(), 19.0, 1e-3);
  EXPECT_NEAR(j["p1_error_mm"]["x"]["max"].as<double>(), 60.0, 1e-3);
  // Signed X: 5 - 60 + 19 = -36 -> bias -12.
  EXPECT_NEAR(j["p1_bias_mm"]["x"]["mean"].as<double>(), -12.0, 1e-3);
  const std::string md = report_markdown(rs, "god", "bookgrasp_eval_bws --scenes 5 --seed 1 --out x");
  EXPECT_NE(md.find("failures (no P1 or wrong book): 2"), std::string::npos) << md;
  EXPECT_NE(md.find("|Y| <= 15 mm): 1 of 5"), std::string::npos) << md;
  EXPECT_NE(md.find("off on some axis: 1"), std::string::npos) << md;
}

}  // namespace
}  // namespace bookgrasp::eval_bws
