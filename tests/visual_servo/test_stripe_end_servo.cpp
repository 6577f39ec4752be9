// PBVS along the stripe against a plant with a book row hiding the stripe:
// from station A left of the books it must pass the books, ignore the end of
// the stripe segment left of them (and the side panel), and converge with the
// TCP straight in front of the TRUE end (the right-most book's right edge).
#include <gtest/gtest.h>

#include <random>

#include "services/visual_servo/stripe_end_servo.h"
#include "servo_plant.h"

namespace bookgrasp {
namespace {

StripeEndServoParams params() {
  StripeEndServoParams p;
  p.gain = 1.2;
  p.max_linear_speed = 0.06;
  p.search_speed = 0.1;
  p.search_direction = +1;
  p.require_occlusion = true;
  p.converged_x_m = 0.0015;
  p.converged_y_m = 0.0015;
  p.converged_frames = 3;
  p.max_search_distance_m = 1.0;
  return p;
}

struct RunResult {
  bool converged = false, failed = false;
  int iterations = 0;
  Eigen::Isometry3d tcp = Eigen::Isometry3d::Identity();
};

RunResult run(const test::StripeScene& scene, Eigen::Isometry3d tcp, double standoff, const StripeEndServoParams& p) {
  const HandEyeGeometry g = test::project_geometry();
  StripeEndServo servo(g, p);
  const Eigen::Vector3d start = tcp.translation();
  GripperTwist pending = GripperTwist::Zero();
  RunResult r;
  for (int i = 0; i < 1500; ++i) {
    const StripeServoStep s = servo.step(scene.observe(g, tcp), standoff, (tcp.translation() - start).norm());
    r.iterations = i + 1;
    if (s.converged || s.failed) {
      r.converged = s.converged;
      r.failed = s.failed;
      break;
    }
    tcp = test::integrate(tcp, pending, 1.0 / 30);
    pending = s.twist;
  }
  r.tcp = tcp;
  return r;
}

TEST(StripeEndServo, FromStationAPastTheBooksToTheTrueEnd) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> right(-0.05, 0.30), width(0.08, 0.45), off(-0.03, 0.03), depth(0.12, 0.2);
  for (int trial = 0; trial < 30; ++trial) {
    test::StripeScene scene;
    scene.books_right = right(rng);
    scene.books_left = std::max(scene.panel_left + 0.02, scene.books_right - width(rng));
    scene.books_z = scene.board_z - 0.36 - depth(rng) * 0.1;
    const double standoff = scene.board_z;  // TCP at W z = 0
    Eigen::Isometry3d a = Eigen::Isometry3d::Identity();
    a.translation() = Eigen::Vector3d(scene.stripe_x + off(rng), -0.32, 0.0);  // station A, left of the books
    const RunResult r = run(scene, a, standoff, params());
    ASSERT_TRUE(r.converged) << "trial " << trial << " books [" << scene.books_left << ", " << scene.books_right << "]";
    EXPECT_NEAR(r.tcp.translation().y(), scene.books_right, 1.5e-3) << trial;  // PS.y = the true end
    EXPECT_NEAR(r.tcp.translation().x(), scene.stripe_x, 1.5e-3) << trial;     // PS.x = stripe height
    EXPECT_NEAR(r.tcp.translation().z(), 0.0, 1e-9) << trial;                  // fixed depth
  }
}

TEST(StripeEndServo, StartingRightOfTheEndSearchingLeft) {
  test::StripeScene scene;
  StripeEndServoParams p = params();
  p.search_direction = -1;
  p.require_occlusion = false;
  Eigen::Isometry3d a = Eigen::Isometry3d::Identity();
  a.translation() = Eigen::Vector3d(0.01, 0.38, 0.0);
  const RunResult r = run(scene, a, scene.board_z, p);
  ASSERT_TRUE(r.converged);
  EXPECT_NEAR(r.tcp.translation().y(), scene.books_right, 1.5e-3);
}

TEST(StripeEndServo, StartingOverTheBooksOrRightOfThemWithoutOcclusionRule) {
  // The coordinator's station A: on the right part of the stripe, maybe in front of the books.
  for (double a_y : {0.0, 0.12, 0.3}) {
    test::StripeScene scene;
    scene.books_left = -0.35;
    scene.books_right = 0.15;
    StripeEndServoParams p = params();
    p.require_occlusion = false;
    Eigen::Isometry3d a = Eigen::Isometry3d::Identity();
    a.translation() = Eigen::Vector3d(-0.01, a_y, 0.0);
    const RunResult r = run(scene, a, scene.board_z, p);
    ASSERT_TRUE(r.converged) << a_y;
    EXPECT_NEAR(r.tcp.translation().y(), scene.books_right, 1.5e-3) << a_y;
    EXPECT_NEAR(r.tcp.translation().x(), scene.stripe_x, 1.5e-3) << a_y;
  }
}

TEST(StripeEndServo, GivesUpAfterTheMaximumSearchDistance) {
  test::StripeScene scene;
  scene.books_left = -0.4;
  scene.books_right = 0.4;  // books everywhere: the stripe is never seen
  StripeEndServoParams p = params();
  p.max_search_distance_m = 0.3;
  const RunResult r = run(scene, Eigen::Isometry3d::Identity(), scene.board_z, p);
  EXPECT_TRUE(r.failed);
  EXPECT_FALSE(r.converged);
  EXPECT_NEAR(r.tcp.translation().y(), 0.3, 0.02);
}

TEST(StripeEndServo, AnEndBeforeTheOcclusionIsNotAccepted) {
  const HandEyeGeometry g = test::project_geometry();
  StripeEndServo servo(g, params());
  StripeObservation o;  // a stripe across the target column with its left end inside: the panel end
  o.found = o.end_found = true;
  o.end_px = {100, 300};
  o.line_start_px = {100, 300};
  o.line_end_px = {639, 300};
  StripeServoStep s = servo.step(o, 0.5, 0.0);
  EXPECT_EQ(s.phase, StripePhase::kSearch);
  EXPECT_GT(s.twist(1), 0.0);
  o.end_px = o.line_start_px = {500, 300};  // now the target column is hidden, end right of it
  s = servo.step(o, 0.5, 0.05);
  EXPECT_EQ(s.phase, StripePhase::kTrack);
  EXPECT_TRUE(servo.occlusion_seen());
  EXPECT_GT(s.error_px.x(), 0.0);
}

TEST(StripeEndServo, AnEndThatVanishesWhileTrackingSendsTheSearchOn) {
  // An end seen through a gap between books (right of the target after the occlusion) is tracked,
  // then disappears: after track_lost_frames observations without an end the search goes on.
  const HandEyeGeometry g = test::project_geometry();
  StripeEndServoParams p = params();
  p.track_lost_frames = 3;
  StripeEndServo servo(g, p);
  StripeObservation hidden;  // stripe hidden at the target column: occlusion seen
  StripeServoStep s = servo.step(hidden, 0.5, 0.0);
  ASSERT_TRUE(servo.occlusion_seen());
  StripeObservation gap;
  gap.found = gap.end_found = true;
  gap.end_px = gap.line_start_px = {420, 300};
  gap.line_end_px = {470, 300};
  s = servo.step(gap, 0.5, 0.01);
  ASSERT_EQ(s.phase, StripePhase::kTrack);
  for (int i = 0; i < 2; ++i) {
    s = servo.step(hidden, 0.5, 0.02);
    EXPECT_EQ(s.phase, StripePhase::kTrack) << i;
    EXPECT_FALSE(s.measured) << i;  // the session holds, then reports FEATURE_LOST if it stays so
  }
  s = servo.step(hidden, 0.5, 0.03);
  EXPECT_EQ(s.phase, StripePhase::kSearch);
  EXPECT_TRUE(s.measured);
  EXPECT_GT(s.twist(1), 0.0);  // on in the search direction
  EXPECT_NE(s.note.find("searching again"), std::string::npos) << s.note;

  // With track_lost_frames 0 the end stays lost (the session's FEATURE_LOST).
  p.track_lost_frames = 0;
  StripeEndServo strict(g, p);
  strict.step(hidden, 0.5, 0.0);
  ASSERT_EQ(strict.step(gap, 0.5, 0.01).phase, StripePhase::kTrack);
  for (int i = 0; i < 10; ++i) {
    s = strict.step(hidden, 0.5, 0.02);
    EXPECT_EQ(s.phase, StripePhase::kTrack);
    EXPECT_FALSE(s.measured);
  }
}

TEST(StripeEndServo, WithOcclusionRuleShortSegmentsThroughGapsAreNotAccepted) {
  const HandEyeGeometry g = test::project_geometry();
  StripeEndServoParams p = params();
  p.occlusion_min_segment_px = 40;
  StripeEndServo servo(g, p);
  servo.step(StripeObservation{}, 0.5, 0.0);  // hidden: occlusion seen
  StripeObservation gap;
  gap.found = gap.end_found = true;
  gap.end_px = gap.line_start_px = {420, 300};
  gap.line_end_px = {445, 300};  // 25 px: the stripe seen between two books
  EXPECT_EQ(servo.step(gap, 0.5, 0.01).phase, StripePhase::kSearch);
  gap.line_end_px = {470, 300};  // 50 px
  EXPECT_EQ(servo.step(gap, 0.5, 0.02).phase, StripePhase::kTrack);
}

TEST(StripeEndServo, MinimumTrackSpeedOutsideTheToleranceOnly) {
  const HandEyeGeometry g = test::project_geometry();
  StripeEndServoParams p = params();
  p.require_occlusion = false;
  p.min_track_speed = 0.004;
  StripeEndServo servo(g, p);
  const Eigen::Vector2d target = g.target_pixel(0.5);
  StripeObservation o;
  o.found = o.end_found = true;
  o.line_start_px = o.end_px = target + Eigen::Vector2d(2.0, 0.0);  // ~2.3 mm right at 0.55 m: outside 1.5 mm
  o.line_end_px = {639, target.y()};
  StripeServoStep s = servo.step(o, 0.5, 0.0);
  ASSERT_EQ(s.phase, StripePhase::kTrack);
  ASSERT_GT(std::abs(s.error_m.y()), p.converged_y_m);
  EXPECT_NEAR(s.twist(1), 0.004, 1e-12);                            // the P law alone gives 1.2 * 2.3 mm/s
  EXPECT_NEAR(s.twist(0), 0.0, 1e-6);                               // X within its tolerance: no minimum
  o.line_start_px = o.end_px = target + Eigen::Vector2d(0.5, 0.0);  // inside the tolerance: P law
  s = servo.step(o, 0.5, 0.0);
  EXPECT_NEAR(s.twist(1), p.gain * s.error_m.y(), 1e-12);
}

}  // namespace
}  // namespace bookgrasp
