// The hand evaluation's metrics, JSON and report on outcomes with known errors.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>
#include <opencv2/imgcodecs.hpp>

#include "services/eval_hand/hand_eval_metrics.h"

namespace bookgrasp {
namespace {

HandTaskOutcome converged(double ex, double ey, double ez = 0, double slope = 0, int it = 10) {
  HandTaskOutcome t;
  t.run = true;
  t.converged = true;
  t.state = "CONVERGED";
  t.error_x_m = ex;
  t.error_y_m = ey;
  t.error_z_m = ez;
  t.slope_error_deg = slope;
  t.iterations = it;
  t.time_s = 1.5;
  return t;
}

HandSceneOutcome scene(uint64_t seed, HandTaskOutcome stripe, HandTaskOutcome corner) {
  HandSceneOutcome o;
  o.seed = seed;
  o.stripe = stripe;
  o.corner = corner;
  o.bwh_ms = {4.0, 6.0};
  o.bswh_ms = {1.0, 3.0};
  o.markers_ms = {7.0};
  o.wall_s = 30;
  return o;
}

TEST(HandStats, MeanMedianMaxP95) {
  const HandStats s = hand_stats({4, 1, 3, 2});
  EXPECT_EQ(s.n, 4);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.max, 4);
  EXPECT_DOUBLE_EQ(s.min, 1);
  EXPECT_EQ(hand_stats({}).n, 0);
}

TEST(HandEvalMetrics, RatesFailuresAndJsonStructure) {
  HandEvalMetrics m;
  const HandTolerances tol;
  accumulate(scene(1, converged(0.002, -0.004), converged(0.003, 0.001, 0.0005, 1.0, 20)), tol, &m);
  // Stripe outside the 1 cm Y tolerance; corner slope 4 deg (outside 3 deg, not a failure of P2).
  accumulate(scene(2, converged(-0.001, 0.012), converged(-0.001, -0.002, -0.001, -4.0, 30)), tol, &m);
  HandTaskOutcome lost;
  lost.run = true;
  lost.state = "FEATURE_LOST";
  lost.message = "BSwH: black stripe not visible";
  accumulate(scene(3, lost, converged(0.025, 0.0)), tol, &m);  // P2 X outside 2 cm
  EXPECT_EQ(m.scenes, 3);
  EXPECT_EQ(m.stripe_runs, 3);
  EXPECT_EQ(m.stripe_converged, 2);
  EXPECT_EQ(m.stripe_within, 1);
  EXPECT_EQ(m.corner_within, 2);
  EXPECT_EQ(m.slope_within, 2);
  EXPECT_EQ(m.failed_scenes, 2);
  ASSERT_EQ(m.failures.size(), 3u);
  EXPECT_EQ(m.failures[0].seed, 2u);
  EXPECT_EQ(m.failures[1].seed, 3u);
  EXPECT_NE(m.failures[1].reason.find("FEATURE_LOST"), std::string::npos);

  const YAML::Node j = YAML::Load(hand_metrics_json(m, "bookgrasp_eval_hand --scenes 3 --seed 1 --out x"));
  EXPECT_EQ(j["scenes"].as<int>(), 3);
  EXPECT_EQ(j["failures"].size(), 3u);
  EXPECT_EQ(j["failures"][0]["seed"].as<int>(), 2);
  EXPECT_NEAR(j["stripe_error_mm"]["x"]["mean"].as<double>(), 1.5, 1e-9);
  EXPECT_NEAR(j["stripe_error_mm"]["y"]["max"].as<double>(), 12.0, 1e-9);
  EXPECT_NEAR(j["stripe_within_tolerance_rate"].as<double>(), 1.0 / 3.0, 1e-5);
  EXPECT_NEAR(j["p2_error_mm"]["x"]["max"].as<double>(), 25.0, 1e-9);
  EXPECT_NEAR(j["p2_error_mm"]["y"]["mean"].as<double>(), 1.0, 1e-9);
  EXPECT_NEAR(j["p2_error_mm"]["z"]["max"].as<double>(), 1.0, 1e-9);
  EXPECT_NEAR(j["slope_error_deg"]["mean"].as<double>(), 5.0 / 3.0, 1e-5);
  EXPECT_NEAR(j["slope_error_deg"]["max"].as<double>(), 4.0, 1e-9);
  EXPECT_NEAR(j["servo_iterations"]["median"].as<double>(), 10.0, 1e-9);  // 10, 10, 20, 30, 10
  EXPECT_NEAR(j["ms_per_frame"]["bwh"]["median"].as<double>(), 5.0, 1e-9);
  EXPECT_NEAR(j["ms_per_frame"]["bswh"]["median"].as<double>(), 2.0, 1e-9);
  EXPECT_NEAR(j["ms_per_frame"]["markers"]["median"].as<double>(), 7.0, 1e-9);
}

TEST(HandEvalMetrics, ReportAndPlotsAreWritten) {
  const std::string dir = ::testing::TempDir() + "/hand_eval_report";
  std::filesystem::create_directories(dir);
  std::vector<HandSceneOutcome> v;
  HandEvalMetrics m;
  for (int i = 0; i < 25; ++i) {
    v.push_back(scene(static_cast<uint64_t>(i), converged(0.001 * std::sin(i), 0.002 * std::cos(i)),
                      converged(0.003 * std::cos(i), 0.001 * i / 10.0, 0.0, 0.2 * i - 2)));
    accumulate(v.back(), HandTolerances{}, &m);
  }
  write_hand_report(dir, m, v, HandTolerances{}, "cmd");
  for (const char* f : {"figure13_p2_error.png", "figure14_stripe_end.png", "slope_error.png"}) {
    const cv::Mat img = cv::imread(dir + "/" + f);
    ASSERT_FALSE(img.empty()) << f;
    EXPECT_GE(img.cols, 400) << f;
  }
  std::ifstream r(dir + "/report.md");
  std::stringstream ss;
  ss << r.rdbuf();
  EXPECT_NE(ss.str().find("stripe end within 1.5 cm X / 1 cm Y | 25 of 25"), std::string::npos) << ss.str();
}

TEST(HandEvalMetrics, UnwritableDirectoryThrows) {
  HandEvalMetrics m;
  EXPECT_THROW(write_hand_report("/nonexistent/dir/for/sure", m, {}, HandTolerances{}, "cmd"), std::runtime_error);
}

}  // namespace
}  // namespace bookgrasp
