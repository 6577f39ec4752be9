// Hoover et al. 1996 comparison on small hand-made label images; every expected answer is worked out
// by hand in the comment above its test (P = region size, O(g, m) = overlap of GT g and machine m).
#include "services/eval_segmentation/hoover_comparison.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

namespace bookgrasp::eval_segmentation {
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

// Same partition, other label values: every region is a correct detection at any T, even T = 1.
TEST(HooverComparison, IdenticalPartitionIsAllCorrect) {
  const cv::Mat gt = labels({{1, 1, 2, 2}, {1, 1, 2, 2}, {3, 3, 3, 3}});
  const cv::Mat ms = labels({{5, 5, 9, 9}, {5, 5, 9, 9}, {7, 7, 7, 7}});
  for (double T : {0.51, 0.8, 1.0}) {
    const HooverResult r = hoover_compare(gt, ms, T);
    EXPECT_EQ(r.num_gt(), 3);
    EXPECT_EQ(r.num_ms(), 3);
    EXPECT_EQ(r.correct, 3) << T;
    EXPECT_EQ(r.over + r.under + r.missed + r.noise, 0) << T;
    EXPECT_EQ(r.gt_class_of(2), HooverClass::kCorrect);
    EXPECT_EQ(r.ms_class_of(9), HooverClass::kCorrect);
  }
}

// GT: one region 1 (8 px). MS: left half 1 (4 px), right half 2 (4 px).
// Correct: O(1,m1) = 4 >= 0.8 * 8 = 6.4? no (same for m2).
// Over: O(1,m1) = 4 >= 0.8 * 4 and O(1,m2) = 4 >= 0.8 * 4; 4 + 4 = 8 >= 6.4 -> over-segmentation.
TEST(HooverComparison, OverSegmentation) {
  const cv::Mat gt = labels({{1, 1, 1, 1}, {1, 1, 1, 1}});
  const cv::Mat ms = labels({{1, 1, 2, 2}, {1, 1, 2, 2}});
  const HooverResult r = hoover_compare(gt, ms, 0.8);
  EXPECT_EQ(r.correct, 0);
  EXPECT_EQ(r.over, 1);
  EXPECT_EQ(r.over_ms_regions, 2);
  EXPECT_EQ(r.under + r.missed + r.noise, 0);
  EXPECT_EQ(r.gt_class_of(1), HooverClass::kOver);
  EXPECT_EQ(r.ms_class_of(1), HooverClass::kOver);
  EXPECT_EQ(r.ms_class_of(2), HooverClass::kOver);
}

// The same images with the roles swapped: GT 1, 2 (4 px each) both inside MS region 1 (8 px):
// O(g1,m1) = 4 >= 0.8 * 4, O(g2,m1) = 4 >= 3.2, sum 8 >= 0.8 * 8 -> one under-segmentation of 2 GT regions.
TEST(HooverComparison, UnderSegmentation) {
  const cv::Mat gt = labels({{1, 1, 2, 2}, {1, 1, 2, 2}});
  const cv::Mat ms = labels({{1, 1, 1, 1}, {1, 1, 1, 1}});
  const HooverResult r = hoover_compare(gt, ms, 0.8);
  EXPECT_EQ(r.correct, 0);
  EXPECT_EQ(r.under, 1);
  EXPECT_EQ(r.under_gt_regions, 2);
  EXPECT_EQ(r.over + r.missed + r.noise, 0);
  EXPECT_EQ(r.gt_class_of(1), HooverClass::kUnder);
  EXPECT_EQ(r.gt_class_of(2), HooverClass::kUnder);
  EXPECT_EQ(r.ms_class_of(1), HooverClass::kUnder);
}

// 1 x 10. GT: 1 = cols 0-4 (5 px), 2 = cols 5-9 (5 px). MS: 1 = cols 0-2 (3), 2 = cols 3-6 (4), 3 = cols 7-9 (3).
// Overlaps: O(g1,m1) = 3, O(g1,m2) = 2, O(g2,m2) = 2, O(g2,m3) = 3.
// T = 0.8: correct g1/m1 needs 3 >= 4: no; g2/m3 likewise. Over g1: pieces with O >= 0.8 P_n: m1 (3 >= 2.4)
//   only (m2: 2 >= 3.2 no) -> one piece, not over; g2 likewise. Under m2: 2 >= 0.8 * 5 no.
//   -> 2 missed, 3 noise.
// T = 0.6: g1/m1: 3 >= 0.6 * 5 = 3 and 3 >= 1.8 -> correct; g2/m3 correct; m2 noise.
TEST(HooverComparison, MissedAndNoiseTurnCorrectAtLowerTolerance) {
  const cv::Mat gt = labels({{1, 1, 1, 1, 1, 2, 2, 2, 2, 2}});
  const cv::Mat ms = labels({{1, 1, 1, 2, 2, 2, 2, 3, 3, 3}});
  const HooverResult a = hoover_compare(gt, ms, 0.8);
  EXPECT_EQ(a.correct + a.over + a.under, 0);
  EXPECT_EQ(a.missed, 2);
  EXPECT_EQ(a.noise, 3);
  EXPECT_EQ(a.gt_class_of(1), HooverClass::kMissed);
  EXPECT_EQ(a.ms_class_of(2), HooverClass::kNoise);
  const HooverResult b = hoover_compare(gt, ms, 0.6);
  EXPECT_EQ(b.correct, 2);
  EXPECT_EQ(b.missed, 0);
  EXPECT_EQ(b.noise, 1);
  EXPECT_EQ(b.ms_class_of(2), HooverClass::kNoise);
}

// 1 x 20. GT: 1 = cols 0-9 (10 px), 2 = cols 10-19 (10 px).
// MS: 0 (none) cols 0-1, 5 = cols 2-11 (10 px: 8 in g1, 2 in g2), 6 = cols 12-19 (8 px, all in g2).
// T = 0.8: g1/m5: 8 >= 0.8 * 10 = 8 and 8 >= 8 -> correct (exactly at the boundary);
//          g2/m6: 8 >= 8 and 8 >= 6.4 -> correct.
// T = 0.81: g1/m5: 8 >= 8.1 no. Over g1: m5 8 >= 8.1 no -> no piece. Under m5: g1 8 >= 8.1 no.
//          g2/m6: 8 >= 8.1 no; over g2: m6 is a piece (8 >= 6.48) but alone; under m6: 8 >= 8.1 no.
//          -> 2 missed, 2 noise.
TEST(HooverComparison, ToleranceBoundaryIsInclusive) {
  cv::Mat gt(1, 20, CV_32S), ms(1, 20, CV_32S);
  for (int x = 0; x < 20; ++x) {
    gt.at<int>(0, x) = x < 10 ? 1 : 2;
    ms.at<int>(0, x) = x < 2 ? 0 : (x < 12 ? 5 : 6);
  }
  const HooverResult a = hoover_compare(gt, ms, 0.8);
  EXPECT_EQ(a.correct, 2);
  EXPECT_EQ(a.missed + a.noise, 0);
  const HooverResult b = hoover_compare(gt, ms, 0.81);
  EXPECT_EQ(b.correct + b.over + b.under, 0);
  EXPECT_EQ(b.missed, 2);
  EXPECT_EQ(b.noise, 2);
}

// Over and under in one image (4 x 6):
//   GT            MS
//   1 1 1 2 2 2   1 1 1 4 4 4
//   1 1 1 2 2 2   1 1 1 4 4 4
//   1 1 1 2 2 2   2 2 2 4 4 4
//   1 1 1 3 3 3   2 2 2 4 4 4
// P: g1 12, g2 9, g3 3; m1 6, m2 6, m4 12. O(g1,m1) = 6, O(g1,m2) = 6, O(g2,m4) = 9, O(g3,m4) = 3.
// T = 0.8: correct: g2/m4 needs 9 >= 9.6: no; none. Over g1 {m1, m2}: 6 >= 4.8 each, 12 >= 9.6 -> over.
// Under m4 {g2, g3}: 9 >= 7.2, 3 >= 2.4, 12 >= 9.6 -> under (2 GT regions). Nothing missed, no noise.
TEST(HooverComparison, OverAndUnderTogether) {
  const cv::Mat gt = labels({{1, 1, 1, 2, 2, 2}, {1, 1, 1, 2, 2, 2}, {1, 1, 1, 2, 2, 2}, {1, 1, 1, 3, 3, 3}});
  const cv::Mat ms = labels({{1, 1, 1, 4, 4, 4}, {1, 1, 1, 4, 4, 4}, {2, 2, 2, 4, 4, 4}, {2, 2, 2, 4, 4, 4}});
  const HooverResult r = hoover_compare(gt, ms, 0.8);
  EXPECT_EQ(r.correct, 0);
  EXPECT_EQ(r.over, 1);
  EXPECT_EQ(r.under, 1);
  EXPECT_EQ(r.under_gt_regions, 2);
  EXPECT_EQ(r.missed + r.noise, 0);
}

// 1 x 10, GT region 1 everywhere. MS: 1 = cols 0-8 (9 px), 2 = col 9 (1 px).
// Correct g1/m1: 9 >= 8 and 9 >= 7.2. {m1, m2} would also be an over-segmentation (9 >= 7.2, 1 >= 0.8,
// sum 10 >= 8): correct detection wins, m2 is noise.
TEST(HooverComparison, CorrectDetectionWinsOverOverSegmentation) {
  const cv::Mat gt = labels({{1, 1, 1, 1, 1, 1, 1, 1, 1, 1}});
  const cv::Mat ms = labels({{1, 1, 1, 1, 1, 1, 1, 1, 1, 2}});
  const HooverResult r = hoover_compare(gt, ms, 0.8);
  EXPECT_EQ(r.correct, 1);
  EXPECT_EQ(r.over, 0);
  EXPECT_EQ(r.noise, 1);
  EXPECT_EQ(r.ms_class_of(2), HooverClass::kNoise);
}

// GT-unlabelled pixels (0) are scored on neither side: MS region 3 covers g1 (4 px) and 4 unlabelled
// pixels; only its 4 scored pixels count, P_n = 4, so g1/m3 is correct even at T = 1.
// g2 (2 px) gets no MS pixel: missed. MS region 9 lies only on unlabelled pixels: not a region at all.
TEST(HooverComparison, UnlabelledGroundTruthPixelsAreNotScored) {
  const cv::Mat gt = labels({{1, 1, 0, 0, 2}, {1, 1, 0, 0, 2}});
  const cv::Mat ms = labels({{3, 3, 3, 9, 0}, {3, 3, 3, 9, 0}});
  const HooverResult r = hoover_compare(gt, ms, 1.0);
  EXPECT_EQ(r.num_gt(), 2);
  EXPECT_EQ(r.num_ms(), 1);
  EXPECT_EQ(r.ms_sizes[0], 4);
  EXPECT_EQ(r.correct, 1);
  EXPECT_EQ(r.missed, 1);
  EXPECT_EQ(r.noise, 0);
  EXPECT_EQ(r.gt_class_of(2), HooverClass::kMissed);
  EXPECT_THROW(r.ms_class_of(9), std::out_of_range);
}

// The "no region" label is a parameter: with -1 as no region, label 0 is an ordinary region.
TEST(HooverComparison, NoRegionLabelIsAParameter) {
  const cv::Mat gt = labels({{0, 0, -1, 1, 1}});
  const cv::Mat ms = labels({{4, 4, 4, 0, 0}});
  const HooverResult r = hoover_compare(gt, ms, 0.9, -1);
  // g0 (2 px) / m4 (2 scored px): correct; g1 (2 px) / m0 (2 px): correct.
  EXPECT_EQ(r.num_gt(), 2);
  EXPECT_EQ(r.correct, 2);
  // With 0 as no region: g-1 (1 px) and g1 (2 px) are regions; m4 has 1 scored px (on g-1): correct.
  // g1's pixels are unlabelled in the MS -> missed.
  const HooverResult s = hoover_compare(gt, ms, 0.9, 0);
  EXPECT_EQ(s.num_gt(), 2);
  EXPECT_EQ(s.correct, 1);
  EXPECT_EQ(s.missed, 1);
}

TEST(HooverComparison, EmptyImagesHaveNoRegions) {
  const HooverResult a = hoover_compare(cv::Mat(), cv::Mat(), 0.8);
  EXPECT_EQ(a.num_gt() + a.num_ms() + a.correct + a.missed + a.noise, 0);
  const cv::Mat zeros = cv::Mat::zeros(3, 4, CV_32S);
  const HooverResult b = hoover_compare(zeros, zeros, 0.8);
  EXPECT_EQ(b.num_gt() + b.num_ms(), 0);
  // GT regions against an all-unlabelled MS: all missed.
  const HooverResult c = hoover_compare(labels({{1, 2}, {1, 2}}), cv::Mat::zeros(2, 2, CV_32S), 0.8);
  EXPECT_EQ(c.missed, 2);
  EXPECT_EQ(c.num_ms(), 0);
  HooverTotals t;
  t.add(b);
  EXPECT_EQ(t.correct_fraction(), 0.0);
  EXPECT_EQ(t.noise_fraction(), 0.0);
}

TEST(HooverComparison, BadInputGivesAClearError) {
  const cv::Mat a = cv::Mat::zeros(2, 3, CV_32S), b = cv::Mat::zeros(3, 2, CV_32S);
  try {
    hoover_compare(a, b, 0.8);
    FAIL() << "size mismatch accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("3x2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("2x3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(hoover_compare(a, cv::Mat::zeros(2, 3, CV_8U), 0.8), std::invalid_argument);
  EXPECT_THROW(hoover_compare(a, a, 0.5), std::invalid_argument);
  EXPECT_THROW(hoover_compare(a, a, 1.01), std::invalid_argument);
  EXPECT_THROW(hoover_compare(a, a, std::nan("")), std::invalid_argument);
  EXPECT_NO_THROW(hoover_compare(a, a, 1.0));
}

// Totals over two comparisons: OverSegmentation's (1 GT: over; 2 MS) and MissedAndNoise at 0.8 (2 GT missed; 3 MS
// noise) -> 3 GT regions: over 1/3, missed 2/3, correct 0; 5 MS regions, noise 3/5.
TEST(HooverComparison, TotalsGiveFractions) {
  HooverTotals t;
  t.add(hoover_compare(labels({{1, 1, 1, 1}}), labels({{1, 1, 2, 2}}), 0.8));
  t.add(hoover_compare(labels({{1, 1, 1, 1, 1, 2, 2, 2, 2, 2}}), labels({{1, 1, 1, 2, 2, 2, 2, 3, 3, 3}}), 0.8));
  EXPECT_EQ(t.gt_regions, 3);
  EXPECT_EQ(t.ms_regions, 5);
  EXPECT_DOUBLE_EQ(t.over_fraction(), 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(t.missed_fraction(), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(t.correct_fraction(), 0.0);
  EXPECT_DOUBLE_EQ(t.under_fraction(), 0.0);
  EXPECT_DOUBLE_EQ(t.noise_fraction(), 3.0 / 5.0);
}

}  // namespace
}  // namespace bookgrasp::eval_segmentation
