// Tests of the GoD planar segmentation on synthetic images whose planes are known analytically.
#include "services/bws_detector/god_segmentation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "services/bws_detector/disparity.h"
#include "services/eval_segmentation/hoover_comparison.h"
#include "synthetic_shelf.h"

namespace bookgrasp::bws {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// P(y, x) = c + a x + b y: a plane in any affine depth-like image (e.g. the disparity of a 3D plane).
cv::Mat affine_image(int w, int h, double a, double b, double c) {
  cv::Mat m(h, w, CV_32F);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) m.at<float>(y, x) = float(c + a * x + b * y);
  return m;
}

// Expected DGoD of a plane with gradient (a, b): atan2(b, a) in (0, 360], 0 if flat.
double expected_dgod(double a, double b) {
  if (a == 0.0 && b == 0.0) return 0.0;
  double deg = std::atan2(b, a) * 180.0 / M_PI;
  if (deg <= 0.0) deg += 360.0;
  return deg;
}

GodParams test_params() {
  GodParams p;
  p.gradient_step = 1;
  p.direction_bins = 16;
  p.flat_mgod_max = 0.0;
  p.window_size = 5;
  p.jump_mgod_min = 0.5;
  p.merge_distance = 0.1;
  p.merge_space = MergeSpace::kImage;
  p.merge_max_angle_deg = 30.0;
  p.merge_angle_min_px = 100;
  p.adjacency_radius_px = 2;
  p.boundary_growth_px = 2;
  p.boundary_growth_distance = 0.25;
  p.min_region_px = 20;
  return p;
}

TEST(GodFeatures, DgodOfKnownPlanesMatchesAtan2) {
  // Gradients in every octant, on the axes and off them.
  const double grads[][2] = {{0.1, 0.0},  {0.1, 0.1},  {0.0, 0.1},   {-0.1, 0.1},  {-0.1, 0.0},   {-0.1, -0.1},
                             {0.0, -0.1}, {0.1, -0.1}, {0.03, 0.07}, {-0.2, 0.05}, {0.2, -0.011}, {0.001, 0.3}};
  for (const auto& g : grads) {
    const cv::Mat img = affine_image(20, 15, g[0], g[1], 50.0);
    const GodFeatures f = compute_god_features(img, 1, 0.0);
    const double want_mag = 2.0 * std::hypot(g[0], g[1]);  // central difference over 2 pixels
    for (int y = 1; y < 14; ++y)
      for (int x = 1; x < 19; ++x) {
        // Eq. 1 in double on the image's own (float) values; the plane's analytic angle differs from
        // it only by float rounding of the pixel values (< 0.01 deg here).
        const double dx = double(img.at<float>(y, x + 1)) - img.at<float>(y, x - 1);
        const double dy = double(img.at<float>(y + 1, x)) - img.at<float>(y - 1, x);
        ASSERT_NEAR(f.dgod.at<float>(y, x), expected_dgod(dx, dy), 1e-3) << "gradient " << g[0] << "," << g[1];
        ASSERT_NEAR(f.dgod.at<float>(y, x), expected_dgod(g[0], g[1]), 0.01);
        ASSERT_NEAR(f.mgod.at<float>(y, x), want_mag, 1e-4);
      }
    // Borders have no central difference.
    EXPECT_TRUE(std::isnan(f.dgod.at<float>(0, 5)));
    EXPECT_TRUE(std::isnan(f.dgod.at<float>(5, 19)));
  }
}

TEST(GodFeatures, AxisDirectionsAreExact) {
  // dy = 0, dx > 0 is the paper's 360 deg, never 0; the other axes are exact too.
  EXPECT_EQ(compute_god_features(affine_image(5, 5, 0.5, 0.0, 10), 1, 0).dgod.at<float>(2, 2), 360.f);
  EXPECT_EQ(compute_god_features(affine_image(5, 5, 0.0, 0.5, 10), 1, 0).dgod.at<float>(2, 2), 90.f);
  EXPECT_EQ(compute_god_features(affine_image(5, 5, -0.5, 0.0, 10), 1, 0).dgod.at<float>(2, 2), 180.f);
  EXPECT_EQ(compute_god_features(affine_image(5, 5, 0.0, -0.5, 10), 1, 0).dgod.at<float>(2, 2), 270.f);
}

TEST(GodFeatures, FlatRegionIsZeroAndDistinctFrom360) {
  // A region parallel to the image plane (constant depth): DGoD 0, MGoD 0 (paper: 0 deg).
  const GodFeatures flat = compute_god_features(affine_image(6, 6, 0, 0, 7.0), 1, 0.0);
  EXPECT_EQ(flat.dgod.at<float>(3, 3), 0.f);
  EXPECT_EQ(flat.mgod.at<float>(3, 3), 0.f);
  // dy = 0, dx > 0: 360, and in the histogram the flat bin is a different bin from direction 360.
  const GodFeatures right = compute_god_features(affine_image(6, 6, 0.2, 0, 7.0), 1, 0.0);
  EXPECT_EQ(right.dgod.at<float>(3, 3), 360.f);
  const cv::Mat bf = god_bins(flat, 16, 10.0), br = god_bins(right, 16, 10.0);
  EXPECT_EQ(bf.at<uint8_t>(3, 3), 16);  // the extra flat bin
  EXPECT_EQ(br.at<uint8_t>(3, 3), 0);   // the direction bin centred on 360
  // A direction just above 0 (dy slightly > 0) shares the 360 bin: the histogram is circular.
  const GodFeatures near0 = compute_god_features(affine_image(6, 6, 0.2, 0.001, 7.0), 1, 0.0);
  EXPECT_GT(near0.dgod.at<float>(3, 3), 0.f);
  EXPECT_LT(near0.dgod.at<float>(3, 3), 1.f);
  EXPECT_EQ(god_bins(near0, 16, 10.0).at<uint8_t>(3, 3), 0);
  // flat_mgod_max > 0 turns small gradients into "flat".
  EXPECT_EQ(compute_god_features(affine_image(6, 6, 0.01, 0.0, 7.0), 1, 0.05).dgod.at<float>(3, 3), 0.f);
}

TEST(GodFeatures, InvalidPixelsGiveNoFeature) {
  cv::Mat img = affine_image(9, 9, 0.1, 0.2, 5.0);
  img.at<float>(4, 4) = kNaN;
  img.at<float>(2, 6) = 0.f;  // <= 0 is invalid too
  const GodFeatures f = compute_god_features(img, 1, 0.0);
  EXPECT_TRUE(std::isnan(f.dgod.at<float>(4, 4)));
  EXPECT_TRUE(std::isnan(f.dgod.at<float>(4, 3)));  // its right neighbour is NaN
  EXPECT_TRUE(std::isnan(f.dgod.at<float>(3, 4)));  // its lower neighbour is NaN
  EXPECT_TRUE(std::isnan(f.dgod.at<float>(2, 5)));
  EXPECT_FALSE(std::isnan(f.dgod.at<float>(6, 6)));
}

TEST(VoteClusters, MajorityOfTheWindowWinsAndMatchesBruteForce) {
  // Random bins; compare the sliding-histogram result with a direct n x n count.
  cv::Mat bins(37, 53, CV_8U);
  cv::RNG rng(7);
  for (int y = 0; y < bins.rows; ++y)
    for (int x = 0; x < bins.cols; ++x) {
      const int r = rng.uniform(0, 10);
      bins.at<uint8_t>(y, x) = r == 9 ? 255 : uint8_t((x / 8 + y / 6 + (r < 3 ? r : 0)) % 5);
    }
  for (int n : {1, 3, 7, 11}) {
    const cv::Mat out = vote_clusters(bins, 5, n);
    for (int y = 0; y < bins.rows; ++y)
      for (int x = 0; x < bins.cols; ++x) {
        if (bins.at<uint8_t>(y, x) == 255) {
          ASSERT_EQ(out.at<uint8_t>(y, x), 255);
          continue;
        }
        int votes[5] = {0, 0, 0, 0, 0};
        for (int yy = std::max(0, y - n / 2); yy <= std::min(bins.rows - 1, y + n / 2); ++yy)
          for (int xx = std::max(0, x - n / 2); xx <= std::min(bins.cols - 1, x + n / 2); ++xx)
            if (bins.at<uint8_t>(yy, xx) < 5) ++votes[bins.at<uint8_t>(yy, xx)];
        int best = 0;
        for (int k = 1; k < 5; ++k)
          if (votes[k] > votes[best]) best = k;
        ASSERT_EQ(out.at<uint8_t>(y, x), best) << "n=" << n << " at " << x << "," << y;
      }
  }
}

TEST(VoteClusters, RemovesIsolatedNoise) {
  cv::Mat bins(20, 20, CV_8U, cv::Scalar(3));
  bins.at<uint8_t>(10, 10) = 7;
  bins.at<uint8_t>(4, 15) = 8;
  const cv::Mat out = vote_clusters(bins, 17, 5);
  EXPECT_EQ(cv::countNonZero(out != 3), 0);
}

// Two planes meeting at a crease (roof): different DGoD, no jump; must come out as two regions
// with the planes' exact parameters.
TEST(SegmentGod, CreaseGivesTwoRegionsWithExactPlanes) {
  cv::Mat img(60, 80, CV_32F);
  for (int y = 0; y < 60; ++y)
    for (int x = 0; x < 80; ++x)
      img.at<float>(y, x) = float(x < 40 ? 20.0 + 0.2 * x + 0.05 * y : 36.2 - 0.2 * x + 0.05 * y);
  const SegmentationResult r = segment_god(img, cv::Mat(), test_params());
  ASSERT_EQ(r.regions.size(), 2u);
  for (const PlaneRegion& reg : r.regions) {
    // Image-space plane v = c + a x + b y has normal ~ (a, b, -1).
    const double a = -reg.normal.x() / reg.normal.z(), b = -reg.normal.y() / reg.normal.z();
    const bool left = reg.centroid.x() < 40;
    EXPECT_NEAR(a, left ? 0.2 : -0.2, 1e-6);
    EXPECT_NEAR(b, 0.05, 1e-6);
    EXPECT_LT(reg.rms_residual, 1e-4);
  }
  // Every pixel is labelled, and the crease column splits them exactly (growth restores the seam).
  EXPECT_EQ(cv::countNonZero(r.labels == 0), 0);
  EXPECT_NE(r.labels.at<int>(30, 39), r.labels.at<int>(30, 40));
  EXPECT_EQ(r.labels.at<int>(30, 0), r.labels.at<int>(30, 39));
}

// Two parallel planes side by side with a depth jump: same DGoD everywhere, so voting alone
// makes one cluster; the MGoD removal of the jump pixels must separate them.
TEST(SegmentGod, ParallelAdjacentPlanesAreSeparatedByMgodRemoval) {
  cv::Mat img(50, 80, CV_32F);
  for (int y = 0; y < 50; ++y)
    for (int x = 0; x < 80; ++x) img.at<float>(y, x) = float(30.0 + 0.1 * y + (x < 40 ? 0.0 : 2.0));
  GodParams p = test_params();
  GodDebug dbg;
  const SegmentationResult r = segment_god(img, cv::Mat(), p, &dbg);
  ASSERT_EQ(r.regions.size(), 2u);
  EXPECT_NE(r.labels.at<int>(25, 39), r.labels.at<int>(25, 40));
  EXPECT_NEAR(std::fabs(r.regions[0].offset - r.regions[1].offset), 2.0 * std::fabs(r.regions[0].normal.z()), 1e-4);
  // Without the removal (jump threshold above the jump's MGoD) the two planes become one initial segment.
  p.jump_mgod_min = 100.0;
  GodDebug dbg2;
  segment_god(img, cv::Mat(), p, &dbg2);
  EXPECT_EQ(dbg2.initial_count, 1);
  EXPECT_EQ(dbg.initial_count, 2);
}

// One plane broken into many initial segments by direction noise must merge back into one;
// a second plane 1.0 away (parallel, across a jump) must not merge at T_dis = 0.75.
TEST(SegmentGod, MergingJoinsFragmentsOfOnePlaneButNotParallelPlanes) {
  cv::Mat img(80, 100, CV_32F);
  cv::RNG rng(3);
  for (int y = 0; y < 80; ++y)
    for (int x = 0; x < 100; ++x)
      img.at<float>(y, x) = float(40.0 + 0.02 * x + 0.01 * y + (x >= 60 ? 1.0 : 0.0) + rng.gaussian(0.01));
  GodParams p = test_params();
  p.window_size = 3;  // little smoothing of directions: many initial fragments
  p.jump_mgod_min = 0.6;
  p.merge_distance = 0.75;
  GodDebug dbg;
  const SegmentationResult r = segment_god(img, cv::Mat(), p, &dbg);
  EXPECT_GT(dbg.initial_count, 10);
  EXPECT_GT(dbg.merges, 8);
  ASSERT_EQ(r.regions.size(), 2u);
  EXPECT_NE(r.labels.at<int>(40, 55), r.labels.at<int>(40, 65));
  // Both regions cover their plane almost entirely.
  for (const PlaneRegion& reg : r.regions) EXPECT_GT(reg.pixel_count, (reg.centroid.x() < 60 ? 60 : 40) * 80 * 0.9);
}

// A steep plane (MGoD 2 > jump_mgod_min) beside a step: god_bins leaves both out; keep_steep_planes gives the
// plane's pixels their direction back (second differences 0) and leaves the step's two columns out (second
// differences of the step's size).
TEST(GodBins, ASteepPlaneIsKeptAndAStepStaysAJumpEdge) {
  cv::Mat img(40, 60, CV_32F);
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 60; ++x) img.at<float>(y, x) = float(x < 30 ? 10.0 + 1.0 * x : 100.0);
  const int B = 16;
  cv::Mat bins = god_bins(compute_god_features(img, 1, 0.0), B, 0.5);
  EXPECT_EQ(bins.at<uint8_t>(20, 15), 255) << "MGoD alone takes the steep plane for a jump edge";
  keep_steep_planes(img, 1, B, 0.5, 0.5, bins);
  for (int x = 1; x < 29; ++x) EXPECT_EQ(bins.at<uint8_t>(20, x), 0) << "x " << x << ": direction 360 deg, bin 0";
  EXPECT_EQ(bins.at<uint8_t>(20, 29), 255);
  EXPECT_EQ(bins.at<uint8_t>(20, 30), 255);
  EXPECT_EQ(bins.at<uint8_t>(20, 45), B) << "the flat part keeps its flat bin";
  EXPECT_EQ(bins.at<uint8_t>(0, 15), 255) << "border pixels have no feature";
  cv::Mat small(10, 10, CV_8U, cv::Scalar(255));
  EXPECT_THROW(keep_steep_planes(img, 1, B, 0.5, 0.5, small), std::invalid_argument);
}

// A surface seen at a grazing angle (disparity rising 1 px per column) beside a frontal one, meeting at a crease:
// with MGoD alone the grazing surface is all jump edge and gets no region; with jump_min_curvature it is one region
// of its own (the crease's second difference keeps the two apart), and a step between parallel planes still
// separates them.
TEST(SegmentGod, TheCurvatureTestKeepsASurfaceAtAGrazingAngle) {
  cv::Mat img(60, 90, CV_32F);
  for (int y = 0; y < 60; ++y)
    for (int x = 0; x < 90; ++x)
      img.at<float>(y, x) = float(x < 50 ? 30.0 + 0.01 * x + 0.02 * y : 30.5 + 1.0 * (x - 50) + 0.02 * y);
  GodParams p = test_params();
  p.jump_mgod_min = 0.6;
  const auto grazing_labels = [&](const SegmentationResult& r) {
    std::map<int, int> n;
    for (int y = 5; y < 55; ++y)
      for (int x = 53; x < 87; ++x) ++n[r.labels.at<int>(y, x)];
    return n;
  };
  const SegmentationResult off = segment_god(img, cv::Mat(), p);
  EXPECT_EQ(grazing_labels(off)[0], 50 * 34) << "MGoD alone: the grazing surface is unlabelled";
  p.jump_min_curvature = 0.6;
  const SegmentationResult on = segment_god(img, cv::Mat(), p);
  const std::map<int, int> n = grazing_labels(on);
  ASSERT_EQ(n.size(), 1u);
  const int grazing = n.begin()->first;
  ASSERT_GT(grazing, 0);
  EXPECT_NE(on.labels.at<int>(30, 20), grazing);
  EXPECT_GT(on.labels.at<int>(30, 20), 0);
  const PlaneRegion& reg = on.regions[size_t(grazing - 1)];
  EXPECT_NEAR(-reg.normal.x() / reg.normal.z(), 1.0, 1e-4);
  cv::Mat steps(50, 80, CV_32F);
  for (int y = 0; y < 50; ++y)
    for (int x = 0; x < 80; ++x) steps.at<float>(y, x) = float(30.0 + 0.1 * y + (x < 40 ? 0.0 : 2.0));
  const SegmentationResult parallel = segment_god(steps, cv::Mat(), p);
  ASSERT_EQ(parallel.regions.size(), 2u);
  EXPECT_NE(parallel.labels.at<int>(25, 39), parallel.labels.at<int>(25, 40));
}

TEST(SegmentGod, MergeSpacePointsUsesTheCallersUnits) {
  // Same crease, merge measured in "points" given as (x, y, 10 * value): distances scale by ~10.
  cv::Mat img = affine_image(40, 30, 0.1, 0.0, 10.0);
  cv::Mat pts(img.size(), CV_32FC3);
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 40; ++x) pts.at<cv::Vec3f>(y, x) = cv::Vec3f(float(x), float(y), 10.f * img.at<float>(y, x));
  GodParams p = test_params();
  p.merge_space = MergeSpace::kPoints;
  const SegmentationResult r = segment_god(img, pts, p);
  ASSERT_EQ(r.regions.size(), 1u);
  EXPECT_NEAR(-r.regions[0].normal.x() / r.regions[0].normal.z(), 1.0, 1e-6);  // fitted on the points
  p.merge_space = MergeSpace::kPoints;
  EXPECT_THROW(segment_god(img, cv::Mat(), p), std::invalid_argument);
}

TEST(SmoothValidValues, KeepsAPlaneAndAJumpAndCutsNoiseByTheWindow) {
  // A plane stays itself away from the border.
  const cv::Mat plane = affine_image(40, 30, 0.2, -0.05, 30.0);
  const cv::Mat sp = smooth_valid_values(plane, 2, 1.0);
  for (int y = 2; y < 28; ++y)
    for (int x = 2; x < 38; ++x) ASSERT_NEAR(sp.at<float>(y, x), plane.at<float>(y, x), 1e-4) << x << "," << y;
  // A jump larger than max_difference stays a jump: each side averages only itself (flat sides: exact).
  cv::Mat step(20, 40, CV_32F);
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 40; ++x) step.at<float>(y, x) = x < 20 ? 10.f : 12.f;
  const cv::Mat ss = smooth_valid_values(step, 3, 1.0);
  EXPECT_EQ(cv::countNonZero(ss != step), 0);
  // Below max_difference the step is averaged: a ramp (this is what the limit is for).
  EXPECT_GT(smooth_valid_values(step, 3, 5.0).at<float>(10, 19), 10.5f);
  // Zero-mean noise drops to about sigma / (2r+1) (two passes of 2r+1 samples: (2r+1)^2 in all).
  cv::Mat noisy = affine_image(200, 200, 0.01, 0.02, 40.0);
  cv::RNG rng(7);
  for (int y = 0; y < 200; ++y)
    for (int x = 0; x < 200; ++x) noisy.at<float>(y, x) += float(rng.gaussian(0.1));
  const cv::Mat sn = smooth_valid_values(noisy, 2, 1.0);
  const cv::Mat truth = affine_image(200, 200, 0.01, 0.02, 40.0);
  double ss_err = 0;
  int n = 0;
  for (int y = 5; y < 195; ++y)
    for (int x = 5; x < 195; ++x, ++n) ss_err += std::pow(sn.at<float>(y, x) - truth.at<float>(y, x), 2);
  EXPECT_NEAR(std::sqrt(ss_err / n), 0.1 / 5.0, 0.004);
  // r = 0 is a copy.
  EXPECT_EQ(cv::countNonZero(smooth_valid_values(noisy, 0, 1.0) != noisy), 0);
}

TEST(SmoothValidValues, InvalidPixelsStayAndAreLeftOut) {
  cv::Mat img(10, 10, CV_32F, cv::Scalar(20.f));
  img.at<float>(5, 5) = kNaN;
  img.at<float>(2, 2) = 0.f;
  img.at<float>(7, 3) = -1.f;
  img.at<float>(4, 5) = 21.f;  // valid, within max_difference of its neighbours
  const cv::Mat s = smooth_valid_values(img, 1, 2.0);
  EXPECT_TRUE(std::isnan(s.at<float>(5, 5)));
  EXPECT_EQ(s.at<float>(2, 2), 0.f);
  EXPECT_EQ(s.at<float>(7, 3), -1.f);
  // Row 4 first: (20 + 21 + 20) / 3 at column 5. Then column 5: rows 3 and 4; row 5 is the NaN, left out.
  EXPECT_NEAR(s.at<float>(4, 5), (20.f + 61.f / 3.f) / 2.f, 1e-4f);
  EXPECT_NEAR(s.at<float>(8, 8), 20.f, 1e-6f);
  for (int y = 0; y < 10; ++y)
    for (int x = 0; x < 10; ++x) {
      const float v = s.at<float>(y, x);
      if (std::isfinite(v) && v > 0.f) {
        ASSERT_GE(v, 20.f) << "an invalid value (0, -1) was averaged in at " << x;
      }
    }
}

TEST(SmoothValidValues, BadArgumentsAreRejectedWithAMessage) {
  const cv::Mat img(5, 5, CV_32F, cv::Scalar(1.f));
  EXPECT_THROW(smooth_valid_values(cv::Mat(5, 5, CV_8U), 1, 1.0), std::invalid_argument);
  EXPECT_THROW(smooth_valid_values(img, -1, 1.0), std::invalid_argument);
  EXPECT_THROW(smooth_valid_values(img, 1, std::nan("")), std::invalid_argument);
  GodParams p = test_params();
  p.smoothing_radius_px = -1;
  EXPECT_THROW(p.validate(), std::invalid_argument);
}

TEST(SegmentGod, BadInputIsRejectedWithAMessage) {
  GodParams p = test_params();
  EXPECT_THROW(segment_god(cv::Mat(10, 10, CV_8U, cv::Scalar(1)), cv::Mat(), p), std::invalid_argument);
  EXPECT_THROW(segment_god(cv::Mat(), cv::Mat(), p), std::invalid_argument);
  EXPECT_THROW(segment_god(affine_image(10, 10, 0, 0, 1), cv::Mat(5, 5, CV_32FC3), p), std::invalid_argument);
  p.window_size = 4;
  EXPECT_THROW(segment_god(affine_image(10, 10, 0, 0, 1), cv::Mat(), p), std::invalid_argument);
  // All-invalid image: no regions, no crash.
  p = test_params();
  const SegmentationResult r = segment_god(cv::Mat(20, 20, CV_32F, cv::Scalar(kNaN)), cv::Mat(), p);
  EXPECT_TRUE(r.regions.empty());
}

// A straightforward GoD (brute-force n x n votes, flood-fill components, pixel-pair adjacency, moments
// with PointMoments::add, the documented merge rule, growth by full scans): the optimised segment_god
// must give exactly the same labels and regions (same arithmetic, so bit for bit).
SegmentationResult reference_god(const cv::Mat& img, const cv::Mat& points, const GodParams& p) {
  const int W = img.cols, H = img.rows, B = p.direction_bins;
  const cv::Mat bins = god_bins(compute_god_features(img, p.gradient_step, p.flat_mgod_max), B, p.jump_mgod_min);
  cv::Mat cls(img.size(), CV_8U, cv::Scalar(255));
  const int r = p.window_size / 2;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      if (bins.at<uint8_t>(y, x) == 255) continue;
      std::vector<int> votes(size_t(B) + 1, 0);
      for (int yy = std::max(0, y - r); yy <= std::min(H - 1, y + r); ++yy)
        for (int xx = std::max(0, x - r); xx <= std::min(W - 1, x + r); ++xx)
          if (bins.at<uint8_t>(yy, xx) != 255) ++votes[bins.at<uint8_t>(yy, xx)];
      cls.at<uint8_t>(y, x) = uint8_t(std::max_element(votes.begin(), votes.end()) - votes.begin());
    }
  cv::Mat lab(img.size(), CV_32S, cv::Scalar(0));
  int count = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      if (cls.at<uint8_t>(y, x) == 255 || lab.at<int>(y, x)) continue;
      lab.at<int>(y, x) = ++count;
      std::vector<cv::Point> stack{{x, y}};
      while (!stack.empty()) {
        const cv::Point q = stack.back();
        stack.pop_back();
        for (const cv::Point d : {cv::Point(1, 0), cv::Point(-1, 0), cv::Point(0, 1), cv::Point(0, -1)}) {
          const cv::Point n = q + d;
          if (n.x < 0 || n.y < 0 || n.x >= W || n.y >= H || lab.at<int>(n) || cls.at<uint8_t>(n) != cls.at<uint8_t>(q))
            continue;
          lab.at<int>(n) = count;
          stack.push_back(n);
        }
      }
    }
  const cv::Mat mp = p.merge_space == MergeSpace::kImage ? image_space_points(img) : points;
  const cv::Mat op = points.empty() ? mp : points;
  std::vector<PointMoments> mom(size_t(count) + 1), omom(size_t(count) + 1);
  const auto ok = [](const cv::Vec3f& v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); };
  std::set<std::pair<int, int>> adj;
  const int R = p.adjacency_radius_px;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const int a = lab.at<int>(y, x);
      if (a == 0) continue;
      const cv::Vec3f m = mp.at<cv::Vec3f>(y, x), o = op.at<cv::Vec3f>(y, x);
      if (ok(m)) mom[size_t(a)].add(Eigen::Vector3d(m[0], m[1], m[2]));
      if (ok(o)) omom[size_t(a)].add(Eigen::Vector3d(o[0], o[1], o[2]));
      for (int yy = std::max(0, y - R); yy <= std::min(H - 1, y + R); ++yy)
        for (int xx = std::max(0, x - R); xx <= std::min(W - 1, x + R); ++xx) {
          const int b = lab.at<int>(yy, xx);
          if (b != 0 && b != a) adj.insert({std::min(a, b), std::max(a, b)});
        }
    }
  std::vector<int> parent(size_t(count) + 1);
  for (int i = 0; i <= count; ++i) parent[size_t(i)] = i;
  const auto find = [&](int a) {
    while (parent[size_t(a)] != a) a = parent[size_t(a)];
    return a;
  };
  const double cos_gate = std::cos(p.merge_max_angle_deg * M_PI / 180.0);
  const auto cost = [&](int a, int b) {
    const int L = mom[size_t(a)].n >= mom[size_t(b)].n ? a : b, S = L == a ? b : a;
    const Plane pl = fit_plane(mom[size_t(L)]);
    if (mom[size_t(S)].n <= 0.0 || !pl.valid) return -1.0;
    const double d = rms_distance(mom[size_t(S)], pl);
    if (!(d < p.merge_distance)) return -1.0;
    const Plane pa = fit_plane(omom[size_t(a)]), pb = fit_plane(omom[size_t(b)]);
    const double gate = p.merge_angle_min_px;
    if (omom[size_t(a)].n >= gate && omom[size_t(b)].n >= gate && pa.valid && pb.valid &&
        std::fabs(pa.normal.dot(pb.normal)) < cos_gate)
      return -1.0;
    return d;
  };
  for (bool merged = true; merged;) {
    std::set<std::pair<int, int>> roots;
    for (const auto& [a, b] : adj)
      if (find(a) != find(b)) roots.insert({std::min(find(a), find(b)), std::max(find(a), find(b))});
    adj = roots;
    std::vector<std::tuple<double, int, int>> cand;
    for (const auto& [a, b] : adj)
      if (cost(a, b) >= 0.0) cand.emplace_back(cost(a, b), a, b);
    std::sort(cand.begin(), cand.end());
    std::set<int> touched;
    merged = false;
    for (const auto& [d, a0, b0] : cand) {
      const int a = find(a0), b = find(b0);
      if (a == b) continue;
      if ((a != a0 || b != b0 || touched.count(a) || touched.count(b)) && cost(a, b) < 0.0) continue;
      const int root = std::min(a, b), other = std::max(a, b);
      parent[size_t(other)] = root;
      mom[size_t(root)].add(mom[size_t(other)]);
      omom[size_t(root)].add(omom[size_t(other)]);
      touched.insert(root);
      merged = true;
    }
  }
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      if (lab.at<int>(y, x)) lab.at<int>(y, x) = find(lab.at<int>(y, x));
  for (int g = 0; g < p.boundary_growth_px; ++g) {
    cv::Mat next = lab.clone();
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const cv::Vec3f m = mp.at<cv::Vec3f>(y, x);
        if (lab.at<int>(y, x) || !ok(m)) continue;
        int best = 0;
        double best_d = p.boundary_growth_distance;
        for (int yy = std::max(0, y - 1); yy <= std::min(H - 1, y + 1); ++yy)
          for (int xx = std::max(0, x - 1); xx <= std::min(W - 1, x + 1); ++xx) {
            const int b = lab.at<int>(yy, xx);
            const Plane pl = b ? fit_plane(mom[size_t(b)]) : Plane();
            if (!pl.valid) continue;
            const double d = std::fabs(pl.normal.dot(Eigen::Vector3d(m[0], m[1], m[2])) - pl.offset);
            if (d < best_d || (d == best_d && best != 0 && b < best)) std::tie(best_d, best) = std::make_tuple(d, b);
          }
        next.at<int>(y, x) = best;
      }
    lab = next;
  }
  return describe_regions(lab, op, p.min_region_px);
}

void expect_same(const SegmentationResult& a, const SegmentationResult& b, const std::string& what) {
  EXPECT_EQ(cv::countNonZero(a.labels != b.labels), 0) << what;
  ASSERT_EQ(a.regions.size(), b.regions.size()) << what;
  for (size_t i = 0; i < a.regions.size(); ++i) {
    const PlaneRegion &u = a.regions[i], &v = b.regions[i];
    EXPECT_TRUE(u.pixel_count == v.pixel_count && u.point_count == v.point_count && u.bbox == v.bbox &&
                u.normal == v.normal && u.offset == v.offset && u.centroid == v.centroid &&
                u.rms_residual == v.rms_residual && u.extent_min == v.extent_min && u.extent_max == v.extent_max)
        << what << ": region " << i + 1;
  }
}

// The optimised segmentation against the reference on StereoBM disparity of the shelf (noisy: thousands
// of initial segments, many merges), in image and in point merge space, with and without debug output.
TEST(SegmentGod, EqualsAStraightforwardReferenceBitForBit) {
  const test::ShelfScene scene = test::make_shelf_scene(1);
  DisparityParams dp;
  dp.block_size = 7;
  const cv::Mat disp = compute_disparity(test::render_boxes(scene.boxes, scene.left, true).intensity,
                                         test::render_boxes(scene.boxes, scene.right, true).intensity, dp);
  const StereoGeometry g{scene.left.fx, scene.left.fy, scene.left.cx, scene.left.cy, scene.baseline_m};
  const cv::Mat roi(disp, cv::Rect(160, 120, 320, 240));  // the books and the boards around them
  const cv::Mat d = roi.clone(), pts = disparity_to_points(d, g);
  GodParams p = test_params();
  p.jump_mgod_min = 0.6;
  p.merge_distance = 0.75;
  p.min_region_px = 30;
  GodDebug dbg;
  const SegmentationResult fast = segment_god(d, pts, p, &dbg);
  EXPECT_GT(dbg.initial_count, 300);
  EXPECT_GT(dbg.merges, 100);
  expect_same(fast, reference_god(d, pts, p), "image space");
  expect_same(segment_god(d, pts, p), fast, "without debug output");
  {
    // The smoothed gradients' input: the debug path (DGoD/MGoD images, then bins) and the pipeline's (bins straight
    // from the image) give the same segmentation, and it is not the unsmoothed one.
    GodParams sp = p;
    sp.smoothing_radius_px = 2;
    sp.smoothing_max_difference = 0.3;
    GodDebug sdbg;
    const SegmentationResult smoothed = segment_god(d, pts, sp, &sdbg);
    expect_same(segment_god(d, pts, sp), smoothed, "smoothed, without debug output");
    EXPECT_LT(sdbg.initial_count, dbg.initial_count);
  }
  p.adjacency_radius_px = 1;
  p.window_size = 3;
  p.boundary_growth_px = 3;
  expect_same(segment_god(d, cv::Mat(), p), reference_god(d, cv::Mat(), p), "no points, R = 1");
  p.merge_space = MergeSpace::kPoints;
  p.merge_distance = 0.01;
  expect_same(segment_god(d, pts, p), reference_god(d, pts, p), "point space");
}

// The synthetic shelf (exact disparity): GoD's segments against the rendered face ids (Hoover).
TEST(SegmentGod, ShelfSceneSegmentsAgainstGroundTruthFaces) {
  const test::ShelfScene scene = test::make_shelf_scene(11);
  const test::RenderOutput ren = test::render_boxes(scene.boxes, scene.left, false);
  const cv::Mat disp = test::exact_disparity(ren.depth, scene.left.fx, scene.baseline_m);
  GodParams p = test_params();
  p.window_size = 5;
  p.jump_mgod_min = 0.6;
  p.merge_distance = 0.75;
  p.min_region_px = 30;
  const SegmentationResult r = segment_god(disp, cv::Mat(), p);
  // Ground truth: faces with at least 200 pixels (book side faces seen edge-on are slivers of
  // 50-250 px; thin board edges of ~1.8 cm are within T_dis = 0.75 px of the board they border and
  // merge with it by design, so the overall rate is well below 1; the book fronts are what matter).
  cv::Mat gt = ren.face_id.clone();
  std::map<int, int> size;
  for (int y = 0; y < gt.rows; ++y)
    for (int x = 0; x < gt.cols; ++x) ++size[gt.at<int>(y, x)];
  for (int y = 0; y < gt.rows; ++y)
    for (int x = 0; x < gt.cols; ++x)
      if (size[gt.at<int>(y, x)] < 200) gt.at<int>(y, x) = 0;
  const eval_segmentation::HooverResult s = eval_segmentation::hoover_compare(gt, r.labels, 0.8);
  std::printf(
      "GoD on exact shelf disparity, T=0.8: %d GT regions, correct %d, over %d, under %d, missed %d, noise %d\n",
      s.num_gt(), s.correct, s.over, s.under, s.missed, s.noise);
  EXPECT_GE(double(s.correct) / s.num_gt(), 0.6);
  // Every book front (face -x of every book box) is a correct detection on its own at T = 0.8.
  for (int b = scene.first_book; b < scene.first_book + scene.num_books; ++b) {
    const int face = b * 6 + test::kFaceMinusX + 1;
    if (size[face] < 200) continue;
    std::map<int, int> overlap, machine_size;
    for (int y = 0; y < gt.rows; ++y)
      for (int x = 0; x < gt.cols; ++x) {
        if (gt.at<int>(y, x) <= 0) continue;
        ++machine_size[r.labels.at<int>(y, x)];
        if (gt.at<int>(y, x) == face) ++overlap[r.labels.at<int>(y, x)];
      }
    bool correct = false;
    for (const auto& [l, o] : overlap)
      if (l > 0 && o >= 0.8 * size[face] && o >= 0.8 * machine_size[l]) correct = true;
    EXPECT_TRUE(correct) << "front of book box " << b << " (" << size[face] << " px)";
  }
}

}  // namespace
}  // namespace bookgrasp::bws
