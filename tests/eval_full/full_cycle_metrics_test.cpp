// The evaluation's arithmetic (services/eval_full/full_cycle_metrics.h) on hand-made scene outcomes whose
// figures are worked out by hand in the comments.
#include <gtest/gtest.h>

#include "services/eval_full/full_cycle_metrics.h"
#include "tests/eval_full/hand_made_scenes.h"

using namespace bookgrasp;
using namespace bookgrasp::test_scenes;

TEST(FullCycleMetrics, StatsOfASample) {
  const Stats s = stats_of({4, 1, 3, 2});
  EXPECT_EQ(s.n, 4);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.max, 4);
  EXPECT_DOUBLE_EQ(s.min, 1);
  EXPECT_EQ(stats_of({}).n, 0);
}

TEST(FullCycleMetrics, AccumulatesRatesAndErrors) {
  EvalMetrics m;
  accumulate(done_scene(7), 0, MetricTolerances{}, &m);
  EXPECT_EQ(m.scenes, 1);
  EXPECT_EQ(m.books_targeted, 2);
  EXPECT_EQ(m.books_moved, 2);
  EXPECT_EQ(m.grasp_attempts, 3);
  EXPECT_EQ(m.grasp_successes, 2);
  EXPECT_EQ(m.holder_releases, 2);
  EXPECT_EQ(m.holder_placed, 2);
  EXPECT_EQ(m.holder_standing, 2);
  EXPECT_EQ(m.decisions, 2);  // the decision without P1 is not an agreement sample
  EXPECT_EQ(m.decisions_agreeing, 1);
  EXPECT_EQ(m.widths, 2);
  EXPECT_EQ(m.widths_within, 1);
  ASSERT_EQ(m.width_error_mm.size(), 2u);
  EXPECT_NEAR(m.width_error_mm[0], 3.0, 1e-9);
  EXPECT_NEAR(m.width_error_mm[1], 15.0, 1e-9);
  ASSERT_EQ(m.p1_error_mm[0].size(), 2u);
  EXPECT_NEAR(m.p1_error_mm[0][0], 4.0, 1e-9);
  EXPECT_NEAR(m.p1_error_mm[2][0], 3.0, 1e-9);
  // GP (signed, against the true corner) for every decision with truth, with a P1 or not.
  ASSERT_EQ(m.gp_error_mm[1].size(), 2u);
  EXPECT_NEAR(m.gp_error_mm[0][0], -4.0, 1e-9);
  EXPECT_NEAR(m.gp_error_mm[1][1], 20.0, 1e-9);
  ASSERT_EQ(m.gp_base_error_mm[2].size(), 2u);
  EXPECT_NEAR(m.gp_base_error_mm[0][0], 6.0, 1e-9);
  EXPECT_NEAR(m.gp_base_error_mm[2][1], -20.0, 1e-9);
  ASSERT_EQ(m.cycle_s.size(), 2u);
  EXPECT_DOUBLE_EQ(m.cycle_s[1], 120);
  // A retried grasp is a failure mode of its own, listed with the seed.
  ASSERT_EQ(m.failures.size(), 1u);
  EXPECT_EQ(m.failures[0].first, 7u);
  EXPECT_NE(m.failures[0].second.find("GRASP_RETRIED"), std::string::npos);
}

TEST(FullCycleMetrics, AMovedBookCountsOnlyIfTheTruthHasItOnTheLowerShelf) {
  // The coordinator moved two books; the truth has the second in front of the cart (fallen off the lower shelf).
  SceneOutcome o = done_scene(4);
  o.result.end = "BOOKS";
  o.result.final_truth.books[1].place = "other";
  EXPECT_EQ(books_on_lower_shelf(o.result), 1);
  EXPECT_EQ(final_place(o.result, o.result.books[1]), "other");
  EXPECT_EQ(failure_reason(o.result, 2), "BOOK_NOT_ON_LOWER_SHELF at the end: the book is other");
  EvalMetrics m;
  accumulate(o, 2, MetricTolerances{}, &m);
  EXPECT_EQ(m.books_moved, 1);
  ASSERT_EQ(m.failures.size(), 1u);
  EXPECT_EQ(m.failures[0].second, "BOOK_NOT_ON_LOWER_SHELF at the end: the book is other");
}

TEST(FullCycleMetrics, ABookKnockedFlatOnTheLowerShelfIsMovedButNotUpright) {
  // Both books on the lower shelf by the truth; the first lies on its side (90 deg about X), the second leans 10 deg.
  SceneOutcome o = done_scene(5);
  auto turn = [](book_truth_t* b, double deg) {
    b->pose.orientation[0] = std::cos(deg * M_PI / 360);
    b->pose.orientation[1] = std::sin(deg * M_PI / 360);
  };
  turn(&o.result.final_truth.books[0], 90);
  turn(&o.result.final_truth.books[1], 10);
  EXPECT_NEAR(final_tilt_deg(o.result, o.result.books[0]), 90, 1e-9);
  EXPECT_NEAR(final_tilt_deg(o.result, o.result.books[1]), 10, 1e-9);
  EXPECT_EQ(failure_reason(o.result, 0).rfind("BOOK_NOT_UPRIGHT_ON_LOWER_SHELF at the end", 0), 0u)
      << failure_reason(o.result, 0);
  EvalMetrics m;
  accumulate(o, 0, MetricTolerances{}, &m);
  EXPECT_EQ(m.books_moved, 2) << "on the lower shelf, whatever its pose";
  EXPECT_EQ(m.books_upright_checked, 2);
  EXPECT_EQ(m.books_upright_on_lower_shelf, 1);
  // Both leaning 10 deg: no failure for it.
  turn(&o.result.final_truth.books[0], 10);
  EXPECT_EQ(failure_reason(o.result, 0).find("UPRIGHT"), std::string::npos) << failure_reason(o.result, 0);
}

TEST(FullCycleMetrics, AHandedOverBookIsCountedApartAndNamedOnlyWhenNothingElseFailed) {
  // The first book was too tall for the lower shelf: the librarian took it (truth: "other"); the second was moved.
  SceneOutcome o = done_scene(5);
  o.result.final_truth.books[0].place = "other";
  o.result.books[0].handed_over = true;
  o.result.grasp_attempts = o.result.grasp_successes = 2;
  EXPECT_EQ(books_on_lower_shelf(o.result), 1);
  // Too tall, or back on the holder because the lower shelf could not take it: named so and counted apart.
  for (const bool unplaceable : {false, true}) {
    SceneOutcome u = o;
    u.result.books[0].handed_over_unplaceable = unplaceable;
    EXPECT_EQ(failure_reason(u.result, 0),
              unplaceable ? "HANDED_OVER: the lower shelf could not take a book; it went back to the holder for the "
                            "librarian"
                          : "HANDED_OVER: a book too tall for the lower shelf was left on the holder for the librarian");
    EvalMetrics m;
    accumulate(u, 0, MetricTolerances{}, &m);
    EXPECT_EQ(m.books_moved, 1);
    EXPECT_EQ(m.books_handed_over, 1);
    EXPECT_EQ(m.books_handed_over_unplaceable, unplaceable ? 1 : 0);
    const std::string json = metrics_json(m, "cmd");
    EXPECT_NE(json.find("\"books_handed_over\": 1"), std::string::npos);
    EXPECT_NE(json.find(std::string("\"books_handed_over_unplaceable\": ") + (unplaceable ? "1" : "0")),
              std::string::npos);
  }
  // A book that fell is still named first.
  o.result.final_truth.books[1].place = "other";
  EXPECT_EQ(failure_reason(o.result, 0), "BOOK_NOT_ON_LOWER_SHELF at the end: the book is other");
}

// A book the lower shelf could not take goes back onto the holder: two retreats from the holder, both with the book
// standing (the harness's scene count is 3 for the two books). The rate counts books, as its denominator does: 2 of
// 2, not 3 of 2 (seeds 5000-5099 at stop 34 read 1.0101).
TEST(FullCycleMetrics, ABookBackOnTheHolderCountsOnceInTheStandingRate) {
  SceneOutcome o = done_scene(5);
  o.result.books[0].handed_over = o.result.books[0].handed_over_unplaceable = true;
  o.result.final_truth.books[0].place = "other";
  o.result.holder_releases = 3;
  o.result.holder_placed = 3;
  o.result.holder_standing = 3;
  ASSERT_EQ(o.result.books.size(), 3u);  // the third record is a close on nothing: never on the holder
  ASSERT_EQ(o.result.books[0].standing_on_holder, 1);
  ASSERT_EQ(o.result.books[1].standing_on_holder, 1);
  ASSERT_EQ(o.result.books[2].standing_on_holder, -1);
  EvalMetrics m;
  accumulate(o, 0, MetricTolerances{}, &m);
  EXPECT_EQ(m.holder_retreats, 2);
  EXPECT_EQ(m.holder_standing, 2);
  EXPECT_NE(metrics_json(m, "cmd").find("\"holder_standing_rate\": 1,"), std::string::npos) << metrics_json(m, "cmd");
  // A book lying on the holder after its last retreat is not standing.
  o.result.books[0].standing_on_holder = 0;
  EvalMetrics m2;
  accumulate(o, 0, MetricTolerances{}, &m2);
  EXPECT_EQ(m2.holder_standing, 1);
}

TEST(FullCycleMetrics, FailureReasons) {
  FullCycleResult r;
  r.end = "ERROR";
  r.message = "scene file x does not exist";
  EXPECT_EQ(failure_reason(r, 1), "ERROR: scene file x does not exist");
  r.end = "BUDGET";
  r.trace = {"  1.00 TASK_STATUS PARK -> SERVO_STRIPE (book 0) x", "  2.00 GRASP_POINT NEED_PS"};
  EXPECT_EQ(failure_reason(r, 1), "BUDGET: stuck in SERVO_STRIPE");
  r.end = "ABORTED";
  r.message =
      "aborted in SERVO_STRIPE: book 0: 3 attempts failed (retries.max_attempts_per_book), last: stripe servo "
      "ended TIMEOUT: no convergence within 30.00 s (message time) after 289 iterations";
  EXPECT_EQ(failure_reason(r, 1), "ABORTED in SERVO_STRIPE: stripe servo ended TIMEOUT: no convergence");
  r.end = "DONE";
  r.message.clear();
  BookRecord first, second;
  first.truth_id = 0;
  second.truth_id = 1;
  r.books = {first, second};
  r.final_truth.books = {truth_book("lower_shelf", 0), truth_book("other", 1)};
  EXPECT_EQ(failure_reason(r, 0), "DONE with 1 book(s) neither on a shelf");
  r.final_truth.books = {truth_book("lower_shelf", 0), truth_book("lower_shelf", 1)};
  EXPECT_EQ(failure_reason(r, 0), "");
  // A book the coordinator released on the holder that the truth does not place there names the scene's
  // failure, before the abort it leads to (the grasp from the holder closing on nothing).
  r.end = "ABORTED";
  r.message = "aborted in MOVE_TO_HOLDER_PRE_GRASP: book 0: last: plan failed";
  r.final_truth.books = {truth_book("other", 0), truth_book("upper_shelf", 1)};
  BookRecord lost;
  lost.truth_id = 0;
  lost.grasp_attempts = lost.grasp_successes = 1;
  lost.place_after_holder_release = "other";
  r.books = {lost};
  EXPECT_EQ(failure_reason(r, 1), "BOOK_NOT_ON_HOLDER after RELEASE_ON_HOLDER: the book is other");
  r.books[0].grasp_successes = 0;  // the plates closed on something, the book stayed on the shelf
  r.books[0].place_after_holder_release = "upper_shelf";
  EXPECT_EQ(failure_reason(r, 1),
            "BOOK_NOT_ON_HOLDER after RELEASE_ON_HOLDER: the book is upper_shelf (it was not in the plates after "
            "EXTRACT)");
  r.books[0].grasp_successes = 1;
  r.books[0].place_after_holder_release = "holder";
  r.books[0].standing_on_holder = 0;  // on the holder, but lying on its base after the gripper left
  EXPECT_EQ(failure_reason(r, 1), "BOOK_NOT_STANDING_ON_HOLDER after RETREAT_FROM_HOLDER");
  r.books[0].standing_on_holder = 1;
  EXPECT_EQ(failure_reason(r, 1), "ABORTED in MOVE_TO_HOLDER_PRE_GRASP: plan failed");
}

// The right-most book fell over before the first close (far_cart 5247, 5456): the harness passed it over and the
// right-most standing book was the target. A scene where that went well names RIGHTMOST_NOT_STANDING (a shortfall
// like HANDED_OVER, counted in books_passed_over_not_standing); one where the target's grasp then failed names that.
TEST(FullCycleMetrics, ARightMostBookPassedOverIsCountedAndNamedLast) {
  FullCycleResult r;
  r.end = "BOOKS";
  r.books_moved = 1;
  r.final_truth.books = {truth_book("upper_shelf", 0), truth_book("lower_shelf", 2)};
  BookRecord taken;
  taken.truth_id = 2;
  taken.passed_over_not_standing = {0};
  taken.grasp_attempts = taken.grasp_successes = 1;
  taken.place_after_holder_release = "holder";
  taken.moved = true;
  r.books = {taken};
  r.grasp_attempts = r.grasp_successes = 1;
  const std::string passed_over =
      "RIGHTMOST_NOT_STANDING: the right-most book leaned more than 10 deg (fallen, or leaning on the side panel); the "
      "right-most standing book was the target";
  EXPECT_EQ(failure_reason(r, 1), passed_over);
  EvalMetrics m;
  accumulate(SceneOutcome{5247, r}, 1, MetricTolerances{}, &m);
  EXPECT_EQ(m.books_passed_over_not_standing, 1);
  EXPECT_EQ(m.grasp_successes, 1);
  EXPECT_EQ(m.books_moved, 1);
  EXPECT_NE(metrics_json(m, "test").find("\"books_passed_over_not_standing\": 1,"), std::string::npos);
  // Far_cart 5498: another standing book was grasped than the right-most standing one; what failed is named.
  r.books[0].grasp_successes = 0;
  r.grasp_successes = 0;
  r.books[0].place_after_holder_release = "upper_shelf";
  r.final_truth.books[1].place = "upper_shelf";
  EXPECT_EQ(failure_reason(r, 1),
            "BOOK_NOT_ON_HOLDER after RELEASE_ON_HOLDER: the book is upper_shelf (it was not in the plates after "
            "EXTRACT)");
  r.books[0].passed_over_not_standing.clear();  // without a passed-over book, a scene that went well names nothing
  r.books[0].grasp_successes = r.grasp_successes = 1;
  r.books[0].place_after_holder_release = "holder";
  r.final_truth.books[1].place = "lower_shelf";
  EXPECT_EQ(failure_reason(r, 1), "");
}

TEST(FullCycleMetrics, AGraspThatTookAnotherBookAlongIsADoubleLift) {
  // Book 0's grasp took book 2 out of the shelf with it: the grasp is no success, the scene's failure is named
  // DOUBLE_LIFT before anything that follows from it, and book 2 (never targeted) is off the upper shelf.
  SceneOutcome o = done_scene(7);
  FullCycleResult& r = o.result;
  r.books.pop_back();  // books 0 and 1 only
  r.grasp_attempts = 2;
  r.grasp_successes = 1;  // the harness counted book 0's grasp as failed
  r.books[0].grasp_successes = 0;
  r.books[0].carried_along = {2};
  r.final_truth.books.push_back(truth_book("lower_shelf", 2));
  EXPECT_EQ(untargeted_books_off_the_upper_shelf(r), std::vector<int>{2});
  EXPECT_EQ(failure_reason(r, 0), "DOUBLE_LIFT: a grasp took 1 other book(s) out of the shelf with the target");
  EvalMetrics m;
  accumulate(o, 0, MetricTolerances{}, &m);
  EXPECT_EQ(m.books_carried_along, 1);
  EXPECT_EQ(m.untargeted_books_off_the_upper_shelf, 1);
  EXPECT_DOUBLE_EQ(static_cast<double>(m.grasp_successes) / m.grasp_attempts, 0.5);
  EXPECT_EQ(m.widths, 1);  // book 0's plate distance spanned two books: not a width measurement
  const std::string json = metrics_json(m, "cmd");
  EXPECT_NE(json.find("\"books_carried_along\": 1"), std::string::npos);
  EXPECT_NE(json.find("\"untargeted_books_off_the_upper_shelf\": 1"), std::string::npos);

  // Without the lift, a book the task never took that left the upper shelf (pushed or knocked off) is named too,
  // in a first-book run as well as in a whole-shelf one.
  r.books[0].carried_along.clear();
  r.books[0].grasp_successes = 1;
  r.grasp_successes = 2;
  r.final_truth.books[2].place = "other";
  r.end = "BOOKS";  // a first-book run: it stopped after its book
  EXPECT_EQ(failure_reason(r, 1),
            "OTHER_BOOK_OFF_THE_UPPER_SHELF at the end: 1 book(s) the task never took left the upper shelf");
  r.final_truth.books[2].place = "upper_shelf";
  EXPECT_EQ(failure_reason(r, 1), "");
}

TEST(FullCycleMetrics, PlateClosesAreSortedByWhatBecameOfThem) {
  // The figures behind grasp.more_than_the_book_m: plates minus the measured fore-edge, per outcome, in mm.
  SceneOutcome o = done_scene(5);
  o.result.closes = {{0.0256, 0.0250, "held_alone"}, {0.0310, 0.0250, "double_lift"}, {0.0201, 0.0200, "not_held"},
                     {0.0470, 0.0250, "backed_out"}, {0.0150, 0.0160, "held_alone"},  {0.0300, 0.0200, ""}};
  EvalMetrics m;
  accumulate(o, 0, MetricTolerances{}, &m);
  ASSERT_EQ(m.plates_over_fore_edge_mm[0].size(), 2u);
  EXPECT_NEAR(m.plates_over_fore_edge_mm[0][0], 0.6, 1e-9);
  EXPECT_NEAR(m.plates_over_fore_edge_mm[0][1], -1.0, 1e-9);
  ASSERT_EQ(m.plates_over_fore_edge_mm[1].size(), 1u);
  EXPECT_NEAR(m.plates_over_fore_edge_mm[1][0], 6.0, 1e-9);
  ASSERT_EQ(m.plates_over_fore_edge_mm[2].size(), 1u);
  ASSERT_EQ(m.plates_over_fore_edge_mm[3].size(), 1u);
  EXPECT_NEAR(m.plates_over_fore_edge_mm[3][0], 22.0, 1e-9);  // the unfinished close ("") is in none
  const std::string j = metrics_json(m, "cmd");
  EXPECT_NE(j.find("\"plates_over_fore_edge_mm\": {\"held_alone\": {\"min\": -1, \"n\": 2"), std::string::npos) << j;
  EXPECT_NE(j.find("\"double_lift\": {\"min\": 6, \"n\": 1"), std::string::npos) << j;
}

TEST(FullCycleMetrics, JsonCarriesTheRequiredKeys) {
  EvalMetrics m;
  accumulate(done_scene(3), 0, MetricTolerances{}, &m);
  const std::string j = metrics_json(m, "bookgrasp_eval_full --scenes 1 --seed 3 --out x");
  for (const char* key :
       {"\"scenes\": 1", "\"grasp_attempts\": 3", "\"grasp_success_rate\": 0.666667", "\"books_moved_rate\": 1",
        "\"p1_p2_agreement_rate\": 0.5", "\"width_within_1cm_rate\": 0.5", "\"width_error_mm\": {\"n\": 2, \"mean\": 9",
        "\"max\": 15", "\"cycle_s\": {\"n\": 2, \"mean\": 110, \"median\": 110", "\"failures\": [",
        "{\"seed\": 3, \"reason\": \"GRASP_RETRIED", "\"holder_releases\": 2", "\"holder_placed_rate\": 1",
        "\"holder_standing_rate\": 1"})
    EXPECT_NE(j.find(key), std::string::npos) << key << " missing in\n" << j;
}

TEST(FullCycleMetrics, StripeEndsAreComparedInXAndYWithThePapersTolerances) {
  // PS - true end per converged stripe servo, signed, in mm; within = |X| <= 15 mm and |Y| <= 10 mm (paper Fig. 14).
  // PS's Z is the servo's standoff (0.46 m in front of the board here), not compared.
  SceneOutcome o = done_scene(6);
  const Eigen::Vector3d end(0.30, 0.12, 0.40);
  o.result.stripes = {{0, end + Eigen::Vector3d(0.004, -0.003, -0.46), end},   // within
                      {0, end + Eigen::Vector3d(0.016, 0.000, -0.46), end},    // X out (16 > 15)
                      {1, end + Eigen::Vector3d(-0.002, 0.011, -0.46), end}};  // Y out (11 > 10)
  EvalMetrics m;
  accumulate(o, 0, MetricTolerances{}, &m);
  EXPECT_EQ(m.stripes, 3);
  EXPECT_EQ(m.stripes_within, 1);
  ASSERT_EQ(m.stripe_error_mm[0].size(), 3u);
  EXPECT_NEAR(m.stripe_error_mm[0][0], 4.0, 1e-9);
  EXPECT_NEAR(m.stripe_error_mm[1][0], -3.0, 1e-9);
  EXPECT_NEAR(m.stripe_error_mm[0][1], 16.0, 1e-9);
  EXPECT_NEAR(m.stripe_error_mm[1][2], 11.0, 1e-9);
  const std::string j = metrics_json(m, "cmd");
  EXPECT_NE(j.find("\"stripes_measured\": 3"), std::string::npos) << j;
  EXPECT_NE(j.find("\"stripe_within_tolerance_rate\": 0.333333"), std::string::npos) << j;
  EXPECT_NE(j.find("\"stripe_error_mm\": {\"x\": {\"min\": -2, \"n\": 3"), std::string::npos) << j;
  EXPECT_NE(j.find("\"y\": {\"min\": -3, \"n\": 3, \"mean\": 2.66667"), std::string::npos) << j;
}

TEST(FullCycleMetrics, DisagreementsAreNamedByWhereP1LayAgainstTheTrueCorner) {
  // Tolerances 15 mm Y, 20 mm X. The true corner at (300, 100, 0) mm; P2 on it unless said.
  const Eigen::Vector3d corner(0.300, 0.100, 0.0);
  auto decision = [&](const Eigen::Vector3d& p1, const Eigen::Vector3d& p2) {
    GraspDecisionRecord d;
    d.p1_present = true;
    d.truth_known = true;
    d.p1_true_grasp = corner;
    d.p1_grasp = p1;
    d.p2_grasp = p2;
    d.gp_grasp = p2;
    return d;
  };
  const MetricTolerances tol;
  EXPECT_EQ(disagreement_mode(decision(corner + Eigen::Vector3d(0.019, 0.014, 0), corner), tol), -1);  // agree
  EXPECT_EQ(disagreement_mode(decision(corner + Eigen::Vector3d(0.0, -0.030, 0), corner), tol), 0);    // Y
  EXPECT_EQ(disagreement_mode(decision(corner + Eigen::Vector3d(0.055, -0.005, 0), corner), tol), 1);  // climb
  EXPECT_EQ(disagreement_mode(decision(corner + Eigen::Vector3d(-0.075, 0.0, 0), corner), tol), 2);    // too low
  // P1 10 mm above the corner, P2 25 mm below it: P1 is near, P2 is off.
  EXPECT_EQ(
      disagreement_mode(decision(corner + Eigen::Vector3d(0.010, 0, 0), corner + Eigen::Vector3d(-0.025, 0, 0)), tol),
      3);
  GraspDecisionRecord no_truth = decision(corner + Eigen::Vector3d(0.055, 0, 0), corner);
  no_truth.truth_known = false;
  EXPECT_EQ(disagreement_mode(no_truth, tol), -1);

  SceneOutcome o = done_scene(8);
  o.result.decisions = {decision(corner + Eigen::Vector3d(0.055, -0.005, 0), corner),
                        decision(corner + Eigen::Vector3d(0.060, 0.0, 0), corner),
                        decision(corner + Eigen::Vector3d(-0.075, 0.0, 0), corner), decision(corner, corner)};
  EvalMetrics m;
  accumulate(o, 0, tol, &m);
  EXPECT_EQ(m.decisions, 4);
  EXPECT_EQ(m.decisions_agreeing, 1);
  EXPECT_EQ(m.p1_p2_disagreements[0], 0);
  EXPECT_EQ(m.p1_p2_disagreements[1], 2);
  EXPECT_EQ(m.p1_p2_disagreements[2], 1);
  EXPECT_EQ(m.p1_p2_disagreements[3], 0);
  EXPECT_NE(metrics_json(m, "c").find("\"p1_p2_disagreement_modes\": {\"p1_off_in_y\": 0, \"p1_above_corner\": 2, "
                                      "\"p1_below_corner\": 1, \"p2_off_p1_near_corner\": 0}"),
            std::string::npos);
}

TEST(FullCycleMetrics, TheScenesShortOfTheAimsAreListedByKindWithTheirSeeds) {
  // done_scene: 3 grasp attempts, 2 held; one width 15 mm off; one decision whose P1 is 4 mm from the true corner and
  // whose P2 is 20 mm off in Y. Seed 6 also has a stripe end 16 mm off in X. Seed 5 is made clean.
  SceneOutcome clean = done_scene(5);
  clean.result.grasp_attempts = 2;
  clean.result.books[1].measured_width_m = 0.021;
  clean.result.decisions.erase(clean.result.decisions.begin() + 1);
  SceneOutcome stripe_off = done_scene(6);
  const Eigen::Vector3d end(0.30, 0.12, 0.40);
  stripe_off.result.stripes = {{0, end + Eigen::Vector3d(0.016, 0.0, -0.46), end},
                               {1, end + Eigen::Vector3d(0.0, 0.011, -0.46), end}};
  EvalMetrics m;
  for (const SceneOutcome& o : {done_scene(9), clean, stripe_off, done_scene(7)})
    accumulate(o, 0, MetricTolerances{}, &m);
  const std::vector<uint64_t> three = {6, 7, 9};
  EXPECT_EQ(m.shortfall_seeds.size(), 4u);
  EXPECT_EQ(m.shortfall_seeds["grasp_not_held_alone"], three);
  EXPECT_EQ(m.shortfall_seeds["width_off_by_more_than_1cm"], three);
  EXPECT_EQ(m.shortfall_seeds["p1_p2_p2_off_p1_near_corner"], three);
  // Two stripe ends off in one scene: the seed once.
  EXPECT_EQ(m.shortfall_seeds["stripe_end_outside_tolerance"], std::vector<uint64_t>{6});
  const std::map<std::string, int> counts = shortfall_counts(m);
  EXPECT_EQ(counts.at("grasp_not_held_alone"), 3);
  EXPECT_EQ(counts.at("stripe_end_outside_tolerance"), 2);
  EXPECT_EQ(counts.count("p1_p2_unclassified"), 0u);
  EXPECT_NE(metrics_json(m, "c").find("\"shortfall_seeds\": {\"grasp_not_held_alone\": [6, 7, 9], "), std::string::npos)
      << metrics_json(m, "c");
}
