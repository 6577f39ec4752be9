// Tests of the BwH core on synthetic hand images (shadows, stamps, covers) with known true corners.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

#include "common/image_conversion.h"
#include "services/bwh_detector/book_detection_hand.h"
#include "synthetic_hand_image.h"

namespace bookgrasp {
namespace {

BookDetectionParams params() {
  const Config root = Config::load_file(std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/bwh_detector.yaml");
  return BookDetectionParams::from_config(root.child("books"));
}

void maybe_dump(const std::string& name, const cv::Mat& rgb, const test::SynthTruth& t, const BookDetection& d) {
  const char* dir = std::getenv("BOOKGRASP_DEBUG_IMAGES");
  if (!dir) return;
  cv::Mat out = rgb.clone();
  for (const auto& c : d.candidates) {
    cv::rectangle(out, c.bbox, c.accepted ? cv::Scalar(0, 200, 0) : cv::Scalar(255, 0, 0), 1);
    if (c.accepted) cv::putText(out, std::to_string(c.id), c.bbox.tl() + cv::Point(3, 14), cv::FONT_HERSHEY_PLAIN, 1.0, cv::Scalar(0, 120, 0));
  }
  cv::circle(out, t.r, 6, cv::Scalar(0, 255, 0), 1);
  if (d.found) {
    const auto& best = d.candidates[static_cast<size_t>(d.ranking[0])];
    cv::drawMarker(out, best.corner_r, cv::Scalar(255, 0, 255), cv::MARKER_CROSS, 14, 1);
  }
  write_png(std::string(dir) + "/bwh_" + name + ".png", out);
  for (const auto& c : d.candidates) {
    std::printf("  %s cand %d bbox %d,%d %dx%d w %.1f h %.1f fill %.2f merged %d R (%.1f, %.1f) %s\n", name.c_str(), c.id,
                c.bbox.x, c.bbox.y, c.bbox.width, c.bbox.height, c.width_px, c.height_px, c.fill_ratio, c.num_merged,
                c.corner_r.x, c.corner_r.y, c.reject_reason.c_str());
  }
}

// Checks the right-most book: R within 3 px, slope within 1.5 deg, width within 6 px
// (the outward search for the left cover edge can reach the neighbour's cover).
// Returns true if R is within 3 px.
bool expect_right_most(const test::SynthScene& scene, const std::string& name, bool strict = true) {
  test::SynthTruth truth;
  const cv::Mat img = test::render_scene(scene, &truth);
  const BookDetection d = detect_books_hand(img, params());
  maybe_dump(name, img, truth, d);
  if (!strict) {
    if (!d.found) return false;
    const BookCandidate& b = d.candidates[static_cast<size_t>(d.ranking[0])];
    const double e = std::hypot(b.corner_r.x - truth.r.x, b.corner_r.y - truth.r.y);
    std::printf("  %s: R error %.2f px\n", name.c_str(), e);
    return e < 3.0;
  }
  EXPECT_TRUE(d.found) << name << ": " << d.failure_reason;
  if (!d.found) return false;
  const BookCandidate& best = d.candidates[static_cast<size_t>(d.ranking[0])];
  EXPECT_LT(std::hypot(best.corner_r.x - truth.r.x, best.corner_r.y - truth.r.y), 3.0)
      << name << ": R detected (" << best.corner_r.x << ", " << best.corner_r.y << ") true (" << truth.r.x << ", "
      << truth.r.y << ")";
  EXPECT_NEAR(best.slope_rad, truth.slope_rad, 1.5 * CV_PI / 180) << name;
  EXPECT_NEAR(best.width_px, truth.width_px, 6.0) << name;
  EXPECT_TRUE(best.refined) << name;
  // The next region from the right is the second book from the right.
  if (d.ranking.size() > 1 && truth.quads.size() > 1) {
    const auto& second = d.candidates[static_cast<size_t>(d.ranking[1])];
    const cv::Point2d r2 = truth.quads[truth.quads.size() - 2][2];
    EXPECT_LT(std::hypot(second.corner_r.x - r2.x, second.corner_r.y - r2.y), 6.0)
        << name << ": second-ranked corner (" << second.corner_r.x << ", " << second.corner_r.y << ") true " << r2;
  }
  return std::hypot(best.corner_r.x - truth.r.x, best.corner_r.y - truth.r.y) < 3.0;
}

TEST(BookDetectionHand, RightMostBookAndCornerWithin3px) {
  expect_right_most(test::default_scene(), "default");
}

TEST(BookDetectionHand, ShadowAcrossThePageEdges) {
  test::SynthScene s = test::default_scene();
  // A sharp cast shadow crossing every book, and uneven light.
  s.shadows.push_back({{{0, 230}, {640, 170}, {640, 260}, {0, 320}}, 0.5, 1.0});
  s.light_gradient = 0.35;
  expect_right_most(s, "shadow_band");
}

TEST(BookDetectionHand, DiagonalShadowOverTheCorner) {
  test::SynthScene s = test::default_scene();
  s.shadows.push_back({{{200, -10}, {650, -10}, {650, 200}, {200, 420}}, 0.55, 1.5});
  expect_right_most(s, "shadow_corner");
}

TEST(BookDetectionHand, StampsOnThePageEdges) {
  test::SynthScene s = test::default_scene();
  s.stamps.push_back({4, 0.55, 0.5, 45});   // wider than the right-most book: splits it in two
  s.stamps.push_back({4, 0.85, 0.85, 14});  // touches its right cover
  s.stamps.push_back({2, 0.7, 0.4, 22});
  expect_right_most(s, "stamps");
}

TEST(BookDetectionHand, ThinRightMostBookWithShadowAndStamp) {
  test::SynthScene s = test::default_scene();
  s.books.back().width_px = 32;
  s.books.back().cover_px = 3;
  s.stamps.push_back({4, 0.6, 0.5, 20});
  s.shadows.push_back({{{0, 260}, {640, 200}, {640, 480}, {0, 480}}, 0.6, 1.0});
  expect_right_most(s, "thin");
}

// A sweep of random scenes: the share with R within 3 px is measured and
// must stay at or above 75 % (this is a rate, not every scene: see docs/HAND_CAMERA.md).
TEST(BookDetectionHand, RandomScenesRate) {
  cv::RNG rng(77);
  int good = 0;
  const int total = 40;
  for (int i = 0; i < total; ++i) {
    test::SynthScene s = test::default_scene();
    s.seed = 500 + static_cast<uint64_t>(i);
    s.first_book_x = rng.uniform(-120.0, 40.0);
    s.stripe_y = rng.uniform(260.0, 360.0);
    s.stripe_angle_deg = rng.uniform(-3.0, 3.0);
    const double lean = rng.uniform(-4.0, 4.0);
    for (auto& b : s.books) {
      b.lean_deg = lean;
      b.height_px = rng.uniform(340.0, 460.0);
      b.width_px = rng.uniform(30.0, 110.0);
      b.cover_px = rng.uniform(2.0, 6.0);
    }
    s.light_gradient = rng.uniform(0.0, 0.4);
    s.noise_sigma = rng.uniform(1.0, 3.5);
    if (i % 2 == 0) {
      const double y0 = rng.uniform(150.0, 300.0), y1 = rng.uniform(150.0, 300.0);
      s.shadows.push_back({{{0, y0}, {640, y1}, {640, y1 + 70}, {0, y0 + 70}}, rng.uniform(0.45, 0.7), 1.0});
    }
    if (i % 3 == 0) s.stamps.push_back({4, rng.uniform(0.5, 0.8), rng.uniform(0.3, 0.7), rng.uniform(12.0, 30.0)});
    good += expect_right_most(s, "random" + std::to_string(i), false) ? 1 : 0;
  }
  std::printf("random scenes with R within 3 px: %d of %d\n", good, total);
  EXPECT_GE(good, total * 3 / 4);  // measured 31 of 40 when written
}

TEST(BookDetectionHand, EveryCandidateCarriesAReason) {
  test::SynthTruth truth;
  const BookDetection d = detect_books_hand(test::render_scene(test::default_scene(), &truth), params());
  ASSERT_TRUE(d.stripe.found);
  int rejected = 0;
  for (const auto& c : d.candidates) {
    EXPECT_EQ(c.accepted, c.reject_reason.empty()) << "candidate " << c.id;
    rejected += c.accepted ? 0 : 1;
  }
  EXPECT_GT(rejected, 0);  // the rear board regions at least
  EXPECT_EQ(d.ranking.size(), 5u);  // five books, left one cut by the border is still a book
}

TEST(BookDetectionHand, NoBooksGivesNotFoundWithAReason) {
  test::SynthScene s = test::default_scene();
  s.first_book_x = -900;
  test::SynthTruth truth;
  const BookDetection d = detect_books_hand(test::render_scene(s, &truth), params());
  EXPECT_FALSE(d.found);
  EXPECT_FALSE(d.failure_reason.empty());
}

TEST(BookDetectionHand, BadInputThrows) {
  EXPECT_THROW(detect_books_hand(cv::Mat(), params()), std::invalid_argument);
  EXPECT_THROW(detect_books_hand(cv::Mat(10, 10, CV_16UC1), params()), std::invalid_argument);
}

}  // namespace
}  // namespace bookgrasp
