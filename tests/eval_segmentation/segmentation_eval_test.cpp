// The segmentation comparison: the true-depth disparity source, tolerances, GoD on a rendered scene
// against the simulator's ground truth, and the bookgrasp_eval_segmentation tool end to end.
#include "services/eval_segmentation/segmentation_eval.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "services/bws_detector/disparity.h"

namespace bookgrasp::eval_segmentation {
namespace {

const std::string kSrc = BOOKGRASP_SOURCE_DIR;

TEST(SegmentationEval, TrueDisparityIsFocalTimesBaselineOverDepth) {
  cv::Mat z = (cv::Mat_<float>(1, 4) << 1.0f, 2.0f, std::nanf(""), 0.0f);
  const cv::Mat d = true_disparity(z, 600.0, 0.1, 0.0, 0.0, 7);
  EXPECT_FLOAT_EQ(d.at<float>(0, 0), 60.0f);
  EXPECT_FLOAT_EQ(d.at<float>(0, 1), 30.0f);
  EXPECT_TRUE(std::isnan(d.at<float>(0, 2)));
  EXPECT_TRUE(std::isnan(d.at<float>(0, 3)));
  // 1/16 px rounding: 600 * 0.1 / 1.7 = 35.294... -> 35.3125.
  const cv::Mat q = true_disparity(cv::Mat(1, 1, CV_32F, cv::Scalar(1.7f)), 600.0, 0.1, 0.0, 1.0 / 16, 7);
  EXPECT_FLOAT_EQ(q.at<float>(0, 0), 35.3125f);
  EXPECT_THROW(true_disparity(z, 0.0, 0.1, 0.0, 0.0, 1), std::invalid_argument);
  EXPECT_THROW(true_disparity(cv::Mat(1, 1, CV_64F), 600, 0.1, 0.0, 0.0, 1), std::invalid_argument);
}

TEST(SegmentationEval, TrueDisparityNoiseHasTheAskedSpreadAndIsSeeded) {
  const cv::Mat z(200, 200, CV_32F, cv::Scalar(2.0f));
  const cv::Mat a = true_disparity(z, 600.0, 0.1, 0.2, 0.0, 5), b = true_disparity(z, 600.0, 0.1, 0.2, 0.0, 5);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  cv::Scalar mean, sd;
  cv::meanStdDev(a, mean, sd);
  EXPECT_NEAR(mean[0], 30.0, 0.01);
  EXPECT_NEAR(sd[0], 0.2, 0.01);
  EXPECT_GT(cv::norm(a, true_disparity(z, 600.0, 0.1, 0.2, 0.0, 6), cv::NORM_INF), 0.0);
}

TEST(SegmentationEval, GroundTruthCategories) {
  GtRegion r;
  r.owner = 3;
  r.name = "book_3_pages:+z";
  EXPECT_EQ(gt_category_of(r), kBookFront);
  r.name = "book_3:+y";
  EXPECT_EQ(gt_category_of(r), kBookOther);
  r.owner = -2;
  r.name = "cart_rear_board:-x";
  EXPECT_EQ(gt_category_of(r), kOtherPlanar);
  r.planar = false;
  r.name = "evalseg_ball:sphere";
  EXPECT_EQ(gt_category_of(r), kCurved);
  EXPECT_STREQ(gt_category_name(kBookFront), "book_front");
}

TEST(SegmentationEval, ToleranceKeysAndTheHalfCase) {
  EXPECT_EQ(tolerance_key(0.5), "T0.5");
  EXPECT_EQ(tolerance_key(0.8), "T0.8");
  EXPECT_GT(effective_tolerance(0.5), 0.5);
  EXPECT_LT(effective_tolerance(0.5), 0.50001);
  EXPECT_EQ(effective_tolerance(0.9), 0.9);
}

// GoD (bws_detector's configuration) on the exact-depth range image of seed 3: the right-most book's front,
// a ground-truth region from the simulator's geometry, is a correct detection at T = 0.8. This holds in 4 of
// seeds 1-30 only (GoD merges coplanar neighbouring fore-edges: under-segmentation, docs/BWS.md); seed 3 is
// one of them, so this guards that behaviour, it is not a rate.
TEST(SegmentationEval, GodDetectsTheRightmostFrontOnSeed3) {
  RangeSceneOptions o;
  o.scene_file = kSrc + "/config/scenes/default.yaml";
  o.seed = 3;
  const RangeScene s = render_range_scene(o);
  EvalConfig c = EvalConfig::from_files(kSrc + "/config/services/bws_detector.yaml",
                                        kSrc + "/config/services/bws_detector_pcl.yaml");
  c.stereo = false;
  c.true_noise_px = 0.0;
  c.tolerances = {0.8};
  const SceneEval e = evaluate_scene(s, 3, c);
  const int front = s.rightmost_front_label();
  ASSERT_GT(front, 0);
  ASSERT_EQ(e.runs.front().name, "god");
  EXPECT_EQ(e.runs.front().hoover.at(0).gt_class_of(front), HooverClass::kCorrect);
}

// Correct detections at T = 0.8 of two GoD configurations on the tool's true source with its 0.1 px of noise, seeds
// 40-42 (neither the tuning seeds 101-110 nor the reported 1-30), against the simulator's surfaces.
struct CorrectAt08 {
  int gt_regions = 0, first = 0, second = 0;
};
CorrectAt08 correct_at_08_on_seeds_40_to_42(const bws::BwsParams& first, const bws::BwsParams& second) {
  CorrectAt08 n;
  for (uint64_t seed = 40; seed <= 42; ++seed) {
    RangeSceneOptions o;
    o.scene_file = kSrc + "/config/scenes/default.yaml";
    o.seed = seed;
    o.curved_objects = true;
    o.left_margin_px = first.disparity.num_disparities;
    const RangeScene s = render_range_scene(o);
    const cv::Mat d = true_disparity(s.depth, s.left_camera.fx, s.baseline_m, 0.1, 1.0 / 16, seed);
    const bws::StereoGeometry g{s.left_camera.fx, s.left_camera.fy, s.left_camera.cx, s.left_camera.cy, s.baseline_m};
    const cv::Mat pts = bws::disparity_to_points(d, g);
    n.gt_regions += int(s.regions.size());
    n.first += hoover_compare(s.gt_labels, bws::segment(d, pts, first).labels, 0.8).correct;
    n.second += hoover_compare(s.gt_labels, bws::segment(d, pts, second).labels, 0.8).correct;
  }
  return n;
}

// GoD with the shipped parameters, whose gradients come from a smoothed disparity (god.smoothing_radius_px), against
// the same GoD without the smoothing (the paper's). The smoothing finds more surfaces (docs/BWS.md "Smoothed
// gradients": 41.1 -> 50.6 % over seeds 1-30).
TEST(SegmentationEval, SmoothedGradientsFindMoreSurfacesUnderDisparityNoise) {
  EvalConfig c = EvalConfig::from_files(kSrc + "/config/services/bws_detector.yaml",
                                        kSrc + "/config/services/bws_detector_pcl.yaml");
  ASSERT_GT(c.god.god.smoothing_radius_px, 0) << "the shipped GoD no longer smooths: this test compares nothing";
  bws::BwsParams raw = c.god;
  raw.god.smoothing_radius_px = 0;
  const CorrectAt08 n = correct_at_08_on_seeds_40_to_42(c.god, raw);
  std::printf("seeds 40-42, %d GT regions, correct at T = 0.8: smoothed %d, unsmoothed %d\n", n.gt_regions, n.first,
              n.second);
  EXPECT_GT(n.first, n.second);
}

// GoD with the curvature test of its jump edges (god.jump_min_curvature 0.6, the tool's god_steep) against the
// shipped GoD (0: MGoD alone, the paper's): surfaces seen at a grazing angle (book covers, the cart's side panels)
// have MGoD above jump_mgod_min on every pixel and were left out as jump edges; kept, more surfaces are found
// (docs/BWS.md "Steep planes": 50.6 -> 58.2 % over seeds 1-30).
TEST(SegmentationEval, TheCurvatureTestOfJumpEdgesFindsMoreSurfaces) {
  EvalConfig c = EvalConfig::from_files(kSrc + "/config/services/bws_detector.yaml",
                                        kSrc + "/config/services/bws_detector_pcl.yaml");
  ASSERT_EQ(c.god.god.jump_min_curvature, 0.0) << "the detector now ships the curvature test: compare other settings";
  bws::BwsParams steep = c.god;
  steep.god.jump_min_curvature = 0.6;
  const CorrectAt08 n = correct_at_08_on_seeds_40_to_42(steep, c.god);
  std::printf("seeds 40-42, %d GT regions, correct at T = 0.8: with the curvature test %d, MGoD alone %d\n",
              n.gt_regions, n.first, n.second);
  EXPECT_GT(n.first, n.second);
}

// The tool on 1 scene: metrics.json has methods.<name>.T<tol>.{correct,over,under,missed,noise}, every
// fraction in [0, 1], the GT-side fractions add up to 1 (rounding: 4 decimals), correct detections do
// not increase with T; report.md and the scene picture exist.
TEST(SegmentationEval, ToolWritesConsistentMetrics) {
  const std::string out = (std::filesystem::temp_directory_path() / "bookgrasp_eval_segmentation_test").string();
  std::filesystem::remove_all(out);
  const std::string tool =
      std::string(BOOKGRASP_BINARY_DIR) + "/services/eval_segmentation/bookgrasp_eval_segmentation";
  const std::string cmd = tool + " --out " + out + " --scenes 1 --seed 4 --pictures 1 2>/dev/null >/dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const YAML::Node m = YAML::LoadFile(out + "/metrics.json");
  EXPECT_EQ(m["scenes"].as<int>(), 1);
  EXPECT_GT(m["gt_regions"].as<int>(), 10);
  EXPECT_GE(m["curved_gt_regions"].as<int>(), 1);
  const char* methods[] = {"god",        "god_steep",        "pcl",        "jump",        "rg",
                           "god_stereo", "god_steep_stereo", "pcl_stereo", "jump_stereo", "rg_stereo"};
  const char* tols[] = {"T0.5", "T0.6", "T0.7", "T0.8", "T0.9"};
  for (const char* name : methods) {
    ASSERT_TRUE(m["methods"][name]) << name;
    double prev_correct = 2.0;
    for (const char* t : tols) {
      const YAML::Node r = m["methods"][name][t];
      ASSERT_TRUE(r) << name << " " << t;
      double sum = 0;
      for (const char* k : {"correct", "over", "under", "missed"}) {
        const double v = r[k].as<double>();
        EXPECT_GE(v, 0.0) << name << t << k;
        EXPECT_LE(v, 1.0) << name << t << k;
        sum += v;
      }
      EXPECT_NEAR(sum, 1.0, 5e-4) << name << " " << t;
      EXPECT_GE(r["noise"].as<double>(), 0.0);
      EXPECT_LE(r["noise"].as<double>(), 1.0);
      EXPECT_LE(r["correct"].as<double>(), prev_correct + 1e-9) << name << " " << t;
      prev_correct = r["correct"].as<double>();
      const YAML::Node n = r["counts"];
      EXPECT_EQ(n["correct"].as<int>() + n["over"].as<int>() + n["under_gt_regions"].as<int>() + n["missed"].as<int>(),
                n["gt_regions"].as<int>());
    }
    // The categories partition the GT regions; their correct detections add up to the T = 0.8 count.
    long long regions = 0, correct = 0;
    for (const auto& kv : m["methods"][name]["correct_by_category_T0.8"]) {
      regions += kv.second["gt_regions"].as<long long>();
      correct += kv.second["correct"].as<long long>();
    }
    EXPECT_EQ(regions, m["gt_regions"].as<long long>()) << name;
    EXPECT_EQ(correct, m["methods"][name]["T0.8"]["counts"]["correct"].as<long long>()) << name;
  }
  std::ifstream report(out + "/report.md");
  std::stringstream text;
  text << report.rdbuf();
  EXPECT_NE(text.str().find("| 0.8 |"), std::string::npos);
  EXPECT_NE(text.str().find("73"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(out + "/scene_4.png"));
  // Bad arguments: a clear refusal, not a crash.
  EXPECT_NE(std::system((tool + " --scenes 0 --out " + out + " 2>/dev/null").c_str()), 0);
  EXPECT_NE(std::system((tool + " --steep-curvature -1 --out " + out + " 2>/dev/null").c_str()), 0);
  EXPECT_NE(std::system((tool + " --steep-curvature nan --out " + out + " 2>/dev/null").c_str()), 0);
  EXPECT_NE(std::system((tool + " --scenes 1 2>/dev/null").c_str()), 0);
}

}  // namespace
}  // namespace bookgrasp::eval_segmentation
