// The whole library cycle composed in one process (services/eval_full/full_cycle_harness.h): sim_world,
// cameras, detectors, visual servo, arbiter, planner, arm driver and the coordinator on memq://, driven by
// message time. Checked against the simulation's ground truth (SIM_GROUND_TRUTH `place` of every book),
// never against the components' own outputs.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <string>

#include "common/pose_conversion.h"
#include "services/eval_full/full_cycle_harness.h"

using namespace bookgrasp;

namespace {

// Seed 1 of config/services/sim_world.yaml's scene (far_cart.yaml): its first book goes through the whole cycle
// (other seeds fail in ways docs/EVALUATION.md counts; seed 2, used until the stereo-ranged markers, now has BwH take
// the taller left neighbour's corner).
constexpr uint64_t kSeed = 1;
constexpr double kBookBudgetS = 300;  // simulation time for one book's whole cycle

FullCycleOptions options(const std::string& name) {
  FullCycleOptions o;
  o.source_dir = BOOKGRASP_SOURCE_DIR;
  o.seed = kSeed;
  const std::string dir = std::string(BOOKGRASP_BINARY_DIR) + "/test_output/full_cycle/" + name;
  std::filesystem::remove_all(dir);
  o.progress_file = dir + "/progress.yaml";
  o.snapshot_dir = dir + "/snapshots";
  o.user_done_after_s = 1.0;
  o.stereo_rate_hz = 2.0;  // BwS needs one frame with the arm parked; fewer frames keep the test short
  return o;
}

std::map<std::string, int> places(const ground_truth_t& g) {
  std::map<std::string, int> n;
  for (const auto& b : g.books) ++n[b.place];
  return n;
}

std::string describe(const FullCycleResult& r) {
  std::string s = "end " + r.end + ", moved " + std::to_string(r.books_moved) + ", message: " + r.message + "\n";
  const size_t from = r.trace.size() > 40 ? r.trace.size() - 40 : 0;
  for (size_t i = from; i < r.trace.size(); ++i) s += r.trace[i] + "\n";
  return s;
}

const book_truth_t* find_book(const ground_truth_t& g, int id) {
  for (const auto& b : g.books)
    if (b.id == id) return &b;
  return nullptr;
}

int rightmost_id(const ground_truth_t& g) {
  for (const auto& b : g.books)
    if (b.rightmost && b.place == "upper_shelf") return b.id;
  return -1;
}

}  // namespace

// The first book goes from the upper shelf to the holder, and after the user's "done" to the lower shelf;
// every other book stays on the upper shelf.
TEST(FullCycle, FirstBookToHolderAndLowerShelf) {
  FullCycleHarness h(options("first_book"));
  const ground_truth_t start = h.result().final_truth;
  const int first = rightmost_id(start);
  ASSERT_GE(first, 0) << "the scene has no book on the upper shelf";
  const int n_upper = places(start)["upper_shelf"];
  ASSERT_GT(n_upper, 1);

  // Until the book stands on the holder and the coordinator waits for the user.
  const std::string end1 = h.run_until(kBookBudgetS, 0, [&] { return h.status().state == "WAIT_USER"; });
  ASSERT_EQ(end1, "STOP") << describe(h.result());
  h.step();
  const ground_truth_t on_holder = h.result().final_truth;
  const book_truth_t* b = find_book(on_holder, first);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(b->place, "holder") << "the right-most book should stand on the holder while the user works";

  // The demo's own "done", then back to the lower shelf.
  const std::string end2 = h.run_until(kBookBudgetS, 1);
  const FullCycleResult r = h.result();
  ASSERT_TRUE(end2 == "BOOKS" || end2 == "DONE") << describe(r);
  b = find_book(r.final_truth, first);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(b->place, "lower_shelf");
  const auto n = places(r.final_truth);
  EXPECT_EQ(n.at("lower_shelf"), 1) << "exactly the first book is on the lower shelf";
  EXPECT_EQ(n.count("upper_shelf") ? n.at("upper_shelf") : 0, n_upper - 1) << "every other book is still upstairs";
  EXPECT_EQ(static_cast<int>(r.final_truth.books.size()), n_upper) << "books lost from the ground truth";
  EXPECT_GE(r.grasp_successes, 1);
  ASSERT_FALSE(r.books.empty());
  EXPECT_EQ(r.books[0].truth_id, first);
  EXPECT_TRUE(r.books[0].passed_over_not_standing.empty()) << "the first book stood until its close";
  ASSERT_GE(r.books[0].measured_width_m, 0) << "the arbiter reported no book width";
  EXPECT_NEAR(r.books[0].measured_width_m, r.books[0].true_width_m, 0.01) << "book width from the plates";
  // The first book's PS is the stripe servo's (BSwH): within the paper's positioning tolerance of the true stripe end.
  ASSERT_FALSE(r.stripes.empty()) << "no stripe servo converged in the first book's cycle";
  const Eigen::Vector3d ps_error = r.stripes.front().ps_true_grasp - r.stripes.front().end_true_grasp;
  EXPECT_LE(std::abs(ps_error.x()), 0.015) << "PS - true stripe end in X (up), m";
  EXPECT_LE(std::abs(ps_error.y()), 0.010) << "PS - true stripe end in Y (right), m";
}

// Far_cart seed 5247: the right-most book's left neighbour leans onto it and both fall flat within the first second,
// before the arm moves (sim_world alone, the arm at rest: 15 deg at 0.5 s, 90 at 1.0 s). The harness passes both over
// (BookRecord::passed_over_not_standing) and the right-most standing book, found here from the truth before the close,
// is the target; the cycle's first close holds that book alone.
TEST(FullCycle, RightMostBooksThatFellArePassedOverAndTheRightMostStandingOneIsGrasped) {
  FullCycleOptions o = options("fallen_rightmost");
  o.seed = 5247;
  FullCycleHarness h(o);
  ASSERT_EQ(h.run_until(kBookBudgetS, 0, [&] { return h.status().state == "CLOSE_GRIPPER"; }), "STOP")
      << describe(h.result());
  const ground_truth_t before_close = h.result().final_truth;
  const Eigen::Isometry3d cart_inv = pose_to_isometry(before_close.cart).inverse();
  int standing = -1, fallen = 0;
  double right_y = 1e9;  // the cart frame's Y grows to the left
  for (const auto& b : before_close.books) {
    if (b.place != "upper_shelf") continue;
    if (pose_to_isometry(b.pose).linear().col(2).z() < std::cos(10 * M_PI / 180)) {
      ++fallen;
      continue;
    }
    const double y = (cart_inv * Eigen::Vector3d(b.p1_base[0], b.p1_base[1], b.p1_base[2])).y();
    if (y < right_y) {
      right_y = y;
      standing = b.id;
    }
  }
  ASSERT_EQ(fallen, 2) << "books 0 and 1 lie flat";
  const std::string end = h.run_until(kBookBudgetS, 0, [&] {
    const auto& s = h.status().state;
    return s != "CLOSE_GRIPPER" && s != "EXTRACT";
  });
  ASSERT_EQ(end, "STOP") << describe(h.result());
  const FullCycleResult r = h.result();
  ASSERT_FALSE(r.books.empty());
  EXPECT_EQ(r.books[0].passed_over_not_standing.size(), 2u) << describe(r);
  EXPECT_EQ(r.books[0].truth_id, standing);
  EXPECT_EQ(r.grasp_attempts, 1);
  EXPECT_EQ(r.grasp_successes, 1) << "the right-most standing book held alone after EXTRACT\n" << describe(r);
  // The stripe end is compared with the right-most standing book's edge, not with the fallen book's.
  ASSERT_FALSE(r.stripes.empty());
  const Eigen::Vector3d ps_error = r.stripes.front().ps_true_grasp - r.stripes.front().end_true_grasp;
  EXPECT_LE(std::abs(ps_error.x()), 0.015) << "PS - the standing book's stripe end in X (up), m";
  EXPECT_LE(std::abs(ps_error.y()), 0.010) << "PS - the standing book's stripe end in Y (right), m";
}

// Far_cart seeds whose right-most book stands near the right side panel (its right side 33 and 56 mm from it): from
// the stripe servo's position A the stripe right of the book must be in view, or the servo takes the stripe seen
// through a gap between books for its end (with A at grasp Y 0.30: PS 58 and 41 mm left of the true end, 5076's
// grasp lost; docs/EVALUATION.md, stop 43). Only the first book's stripe servo runs, until BwH is sent off.
TEST(FullCycle, TheStripeServoFindsTheEndBesideABookNearTheRightSidePanel) {
  for (const uint64_t seed : {5076u, 5352u}) {
    SCOPED_TRACE("far_cart seed " + std::to_string(seed));
    FullCycleOptions o = options("stripe_near_panel_" + std::to_string(seed));
    o.seed = seed;
    FullCycleHarness h(o);
    // The coordinator passes WAIT_PS_CHECK within one step: stop when BwH's start is under way.
    const std::string end = h.run_until(60, 0, [&] { return h.status().state == "MOVE_TO_BWH_START"; });
    ASSERT_EQ(end, "STOP") << describe(h.result());
    const FullCycleResult r = h.result();
    ASSERT_FALSE(r.stripes.empty()) << "no stripe servo converged\n" << describe(r);
    const Eigen::Vector3d ps_error = r.stripes.front().ps_true_grasp - r.stripes.front().end_true_grasp;
    EXPECT_LE(std::abs(ps_error.x()), 0.015) << "PS - true stripe end in X (up), m";
    EXPECT_LE(std::abs(ps_error.y()), 0.010) << "PS - true stripe end in Y (right), m";
  }
}

// The coordinator is destroyed with the book on the holder and rebuilt from its progress file: the new one
// resumes and puts the book on the lower shelf; no book is lost or moved twice.
TEST(FullCycle, RestartMidCycleResumes) {
  FullCycleHarness h(options("restart"));
  const ground_truth_t start = h.result().final_truth;
  const int first = rightmost_id(start);
  ASSERT_GE(first, 0);
  const int n_upper = places(start)["upper_shelf"];

  const std::string end1 = h.run_until(kBookBudgetS, 0, [&] { return h.status().state == "PARK_FOR_USER"; });
  ASSERT_EQ(end1, "STOP") << describe(h.result());
  h.restart_coordinator();
  const std::string end2 = h.run_until(kBookBudgetS, 1);
  const FullCycleResult r = h.result();
  ASSERT_TRUE(end2 == "BOOKS" || end2 == "DONE") << describe(r);
  EXPECT_EQ(r.books_moved, 1) << "the resumed coordinator counts the book once";
  const book_truth_t* b = find_book(r.final_truth, first);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(b->place, "lower_shelf");
  const auto n = places(r.final_truth);
  EXPECT_EQ(n.at("lower_shelf"), 1);
  EXPECT_EQ(n.count("upper_shelf") ? n.at("upper_shelf") : 0, n_upper - 1);
  for (const auto& [place, count] : n)
    EXPECT_TRUE(place == "upper_shelf" || place == "lower_shelf") << count << " book(s) ended up in " << place;
}
