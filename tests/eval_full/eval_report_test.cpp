// report.md and rates.png of the full-cycle evaluation (services/eval_full/eval_report.h) on hand-set metrics: the
// bars' heights are worked out from the plot's layout (640 x 400, left margin 60, bottom 80, top 40, five slots).
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "services/eval_full/eval_report.h"

using namespace bookgrasp;

namespace {

EvalMetrics half_upright() {
  EvalMetrics m;
  m.scenes = 2;
  m.grasp_attempts = 4;
  m.grasp_successes = 4;
  m.books_targeted = 4;
  m.books_moved = 4;
  m.books_upright_checked = 4;
  m.books_upright_on_lower_shelf = 2;
  return m;
}

// Plot rows: the bars stand on y = 400 - 80 = 320 and 100 % is 400 - 40 - 80 = 280 px tall. The fifth slot
// ("upright") starts at x = 60 + 4 * (640 - 60 - 20) / 5 = 508; its blue bar at 508 + 112 / 8 = 522, 37 px wide.
cv::Vec3b pixel_in_upright_bar(const cv::Mat& img, int height_px) {
  return img.at<cv::Vec3b>(320 - height_px, 530);
}

/// DIR/report.md's text.
std::string report_text(const std::string& dir) {
  std::ifstream md(dir + "/report.md");
  std::stringstream ss;
  ss << md.rdbuf();
  return ss.str();
}

}  // namespace

TEST(EvalReport, TheRatesChartHasAnUprightBarOfTheUprightShare) {
  const std::string dir = testing::TempDir() + "/eval_report_upright";
  ASSERT_EQ(std::system(("mkdir -p " + dir).c_str()), 0);
  write_report(dir, half_upright(), "test", 0);
  const cv::Mat img = cv::imread(dir + "/rates.png");
  ASSERT_EQ(img.cols, 640);
  ASSERT_EQ(img.rows, 400);
  const cv::Vec3b blue(180, 120, 40), white(255, 255, 255);
  // 2 of 4 upright: a bar 140 px tall.
  EXPECT_EQ(pixel_in_upright_bar(img, 10), blue);
  EXPECT_EQ(pixel_in_upright_bar(img, 130), blue);
  EXPECT_EQ(pixel_in_upright_bar(img, 160), white);
  const std::string report = report_text(dir);
  EXPECT_NE(report.find("standing upright on the lower shelf"), std::string::npos);
}

TEST(EvalReport, NoUprightBarWhenNoSceneCheckedIt) {
  const std::string dir = testing::TempDir() + "/eval_report_unchecked";
  ASSERT_EQ(std::system(("mkdir -p " + dir).c_str()), 0);
  EvalMetrics m = half_upright();
  m.books_upright_checked = 0;
  m.books_upright_on_lower_shelf = 0;
  write_report(dir, m, "test", 0);
  const cv::Mat img = cv::imread(dir + "/rates.png");
  ASSERT_FALSE(img.empty());
  EXPECT_EQ(pixel_in_upright_bar(img, 10), cv::Vec3b(255, 255, 255));
}

TEST(EvalReport, TheStripeEndHasItsFigureAndRow) {
  const std::string dir = testing::TempDir() + "/eval_report_stripe";
  ASSERT_EQ(std::system(("mkdir -p " + dir).c_str()), 0);
  EvalMetrics m = half_upright();
  m.stripes = 2;
  m.stripes_within = 1;
  m.stripe_error_mm[0] = {4.0, 16.0};
  m.stripe_error_mm[1] = {-3.0, 2.0};
  write_report(dir, m, "test", 0);
  EXPECT_FALSE(cv::imread(dir + "/figure14_stripe_end.png").empty());
  const std::string report = report_text(dir);
  EXPECT_NE(report.find("| stripe end PS within 15 mm X and 10 mm Y of the truth | 50.0 % (1/2)"), std::string::npos)
      << report;
  EXPECT_NE(report.find("| stripe end error X / Y mean, min / max | 10.0 (4.0 / 16.0) / -0.5 (-3.0 / 2.0) mm"),
            std::string::npos)
      << report;
  EXPECT_NE(report.find("![stripe end](figure14_stripe_end.png)"), std::string::npos);
}

TEST(EvalReport, TheDisagreementsAreCountedByMode) {
  const std::string dir = testing::TempDir() + "/eval_report_disagree";
  ASSERT_EQ(std::system(("mkdir -p " + dir).c_str()), 0);
  EvalMetrics m = half_upright();
  m.decisions = 10;
  m.decisions_agreeing = 4;
  m.p1_p2_disagreements[0] = 1;
  m.p1_p2_disagreements[1] = 2;
  m.p1_p2_disagreements[2] = 3;
  write_report(dir, m, "test", 0);
  const std::string report = report_text(dir);
  EXPECT_NE(report.find("P2 off (P1 near the corner) | 1 / 2 / 3 / 0 |"), std::string::npos) << report;
}

TEST(EvalReport, TheBooksPassedOverHaveTheirRow) {
  const std::string dir = testing::TempDir() + "/eval_report_passed_over";
  ASSERT_EQ(std::system(("mkdir -p " + dir).c_str()), 0);
  EvalMetrics m = half_upright();
  m.books_passed_over_not_standing = 3;
  write_report(dir, m, "test", 0);
  const std::string report = report_text(dir);
  EXPECT_NE(report.find("passed over for the right-most standing book | 3 |"), std::string::npos) << report;
}

TEST(EvalReport, TheScenesShortOfTheAimsAreListedWithTheirSeeds) {
  const std::string dir = testing::TempDir() + "/eval_report_shortfalls";
  ASSERT_EQ(std::system(("mkdir -p " + dir).c_str()), 0);
  EvalMetrics m = half_upright();
  m.shortfall_seeds["p1_p2_p1_below_corner"] = {5006, 5027};
  write_report(dir, m, "test", 0);
  std::string report = report_text(dir);
  EXPECT_NE(report.find("## Short of the aims, by seed"), std::string::npos) << report;
  EXPECT_NE(report.find("- p1_p2_p1_below_corner (2): 5006 5027\n"), std::string::npos) << report;
  write_report(dir, half_upright(), "test", 0);
  report = report_text(dir);
  EXPECT_NE(report.find("by seed (scenes; re-run one alone with `--scenes 1 --seed <seed>`)\n\nNone.\n"),
            std::string::npos)
      << report;
}
