// Hoover et al. 1996 comparison on hand-made label images; every expected count is worked out below.
#include "services/bws_detector/hoover_metric.h"

#include <gtest/gtest.h>

namespace bookgrasp::bws {
namespace {

cv::Mat labels(std::initializer_list<std::initializer_list<int>> rows) {
  cv::Mat m(int(rows.size()), int(rows.begin()->size()), CV_32S);
  int y = 0;
  for (const auto& r : rows) {
    int x = 0;
    for (int v : r) m.at<int>(y, x++) = v;
    ++y;
  }
  return m;
}

TEST(Hoover, IdenticalSegmentationsAreAllCorrect) {
  const cv::Mat gt = labels({{1, 1, 2, 2}, {1, 1, 2, 2}, {3, 3, 3, 3}});
  // Machine labels are other numbers for the same regions: correct needs no equal label values.
  const cv::Mat ms = labels({{5, 5, 9, 9}, {5, 5, 9, 9}, {7, 7, 7, 7}});
  const HooverScore s = hoover_compare(gt, ms, 0.8);
  EXPECT_EQ(s.gt_regions, 3);
  EXPECT_EQ(s.machine_regions, 3);
  EXPECT_EQ(s.correct, 3);
  EXPECT_EQ(s.over + s.under + s.missed + s.noise, 0);
}

// GT (4 x 6):            machine:
//   1 1 1 2 2 2            1 1 1 4 4 4
//   1 1 1 2 2 2            1 1 1 4 4 4
//   1 1 1 2 2 2            2 2 2 4 4 4
//   1 1 1 3 3 3            2 2 2 4 4 4
// GT sizes: P1 = 12, P2 = 9, P3 = 3. Machine sizes: P1 = 6, P2 = 6, P4 = 12.
// Overlaps: O(1,m1) = 6, O(1,m2) = 6, O(2,m4) = 9, O(3,m4) = 3.
// T = 0.8:
//  correct: GT1 with m1: 6 >= 0.8*12? no. GT2 with m4: 9 >= 0.8*9 yes, 9 >= 0.8*12 = 9.6? no. GT3 with m4: 3 >= 9.6? no.
//  over: GT1 into m1, m2: 6 >= 0.8*6 both, 12 >= 0.8*12 -> over-segmentation (1 instance).
//  under: m4 covers GT2 (9 >= 7.2) and GT3 (3 >= 2.4), 12 >= 0.8*12 -> under-segmentation (1 instance, 2 GT regions).
//  missed 0, noise 0.
TEST(Hoover, OverAndUnderSegmentationWorkedByHand) {
  const cv::Mat gt = labels({{1, 1, 1, 2, 2, 2}, {1, 1, 1, 2, 2, 2}, {1, 1, 1, 2, 2, 2}, {1, 1, 1, 3, 3, 3}});
  const cv::Mat ms = labels({{1, 1, 1, 4, 4, 4}, {1, 1, 1, 4, 4, 4}, {2, 2, 2, 4, 4, 4}, {2, 2, 2, 4, 4, 4}});
  const HooverScore s = hoover_compare(gt, ms, 0.8);
  EXPECT_EQ(s.correct, 0);
  EXPECT_EQ(s.over, 1);
  EXPECT_EQ(s.under, 1);
  EXPECT_EQ(s.under_gt_regions, 2);
  EXPECT_EQ(s.missed, 0);
  EXPECT_EQ(s.noise, 0);
}

// GT (2 x 10): region 1 = columns 0..4, region 2 = columns 5..9 (P = 10 each).
// machine: columns 0..3 -> 1 (8 px), column 4..6 -> 2 (6 px), columns 7..9 -> 0 (unlabeled).
// Overlaps: O(1,m1) = 8, O(1,m2) = 2, O(2,m2) = 4.
// T = 0.8: correct GT1/m1: 8 >= 8 and 8 >= 6.4 -> correct. GT2/m2: 4 >= 8? no.
//   over GT2: m2 has 4 >= 0.8*6 = 4.8? no -> no part. under m2: GT2 4 >= 8? no. -> GT2 missed, m2 noise.
// T = 0.6: correct GT1/m1 (8 >= 6, 8 >= 4.8). GT2/m2: 4 >= 6? no -> missed; m2 noise.
TEST(Hoover, MissedAndNoiseWorkedByHand) {
  const cv::Mat gt = labels({{1, 1, 1, 1, 1, 2, 2, 2, 2, 2}, {1, 1, 1, 1, 1, 2, 2, 2, 2, 2}});
  const cv::Mat ms = labels({{1, 1, 1, 1, 2, 2, 2, 0, 0, 0}, {1, 1, 1, 1, 2, 2, 2, 0, 0, 0}});
  for (double T : {0.8, 0.6}) {
    const HooverScore s = hoover_compare(gt, ms, T);
    EXPECT_EQ(s.correct, 1) << T;
    EXPECT_EQ(s.over, 0) << T;
    EXPECT_EQ(s.under, 0) << T;
    EXPECT_EQ(s.missed, 1) << T;
    EXPECT_EQ(s.noise, 1) << T;
  }
}

// The tolerance decides: GT region 1 (10 px) found by machine region 1 covering 8 of its pixels plus
// 1 pixel of GT region 2 (P_n = 9). O = 8. T = 0.8: 8 >= 8 and 8 >= 7.2 -> correct. T = 0.9: 8 >= 9? no.
//   Over at 0.9: only one machine part -> no. -> missed at 0.9, and machine 1 is noise.
// GT 2 (10 px) = machine 2 (9 px, O = 9) + the pixel lost to machine 1: T = 0.8 and 0.9: 9 >= 9, 9 >= 8.1 -> correct.
TEST(Hoover, ToleranceChangesTheVerdict) {
  const cv::Mat gt = labels({{1, 1, 1, 1, 1, 2, 2, 2, 2, 2}, {1, 1, 1, 1, 1, 2, 2, 2, 2, 2}});
  const cv::Mat ms = labels({{1, 1, 1, 1, 0, 1, 2, 2, 2, 2}, {1, 1, 1, 1, 0, 2, 2, 2, 2, 2}});
  HooverScore s = hoover_compare(gt, ms, 0.8);
  EXPECT_EQ(s.correct, 2);
  s = hoover_compare(gt, ms, 0.9);
  EXPECT_EQ(s.correct, 1);
  EXPECT_EQ(s.missed, 1);
  EXPECT_EQ(s.noise, 1);
}

// GT label 0 (unknown) pixels are ignored: a machine region lying mostly on unknown pixels is judged
// only on the known ones. GT: 1 1 0 0 / 1 1 0 0 (P1 = 4). Machine: all 5 (on known pixels P5 = 4).
// O = 4 >= 0.8*4 both ways -> correct, no noise.
TEST(Hoover, UnknownGroundTruthPixelsAreIgnored) {
  const cv::Mat gt = labels({{1, 1, 0, 0}, {1, 1, 0, 0}});
  const cv::Mat ms = labels({{5, 5, 5, 5}, {5, 5, 5, 5}});
  const HooverScore s = hoover_compare(gt, ms, 0.8);
  EXPECT_EQ(s.correct, 1);
  EXPECT_EQ(s.noise, 0);
}

TEST(Hoover, BadInputThrows) {
  const cv::Mat a(3, 3, CV_32S, cv::Scalar(1));
  EXPECT_THROW(hoover_compare(a, cv::Mat(3, 4, CV_32S, cv::Scalar(1)), 0.8), std::invalid_argument);
  EXPECT_THROW(hoover_compare(a, cv::Mat(3, 3, CV_8U, cv::Scalar(1)), 0.8), std::invalid_argument);
  EXPECT_THROW(hoover_compare(a, a, 0.5), std::invalid_argument);
  EXPECT_THROW(hoover_compare(a, a, 1.1), std::invalid_argument);
}

}  // namespace
}  // namespace bookgrasp::bws
