// ServoSession timing and outcomes in message time: feature lost, hold, heartbeat,
// timeout, start checks, cancel, stale/mismatched measurements, converged pose at capture.
#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <utility>

#include "services/visual_servo/servo_session.h"
#include "servo_plant.h"

namespace bookgrasp {
namespace {

constexpr int64_t kT0 = 1'000'000'000;

ServoSessionParams session_params() {
  ServoSessionParams p;
  p.feature_lost_timeout_s = 0.6;
  p.stale_feature_s = 0.25;
  p.command_period_s = 0.05;
  p.default_timeout_s = 20;
  p.max_start_error_m = 0.03;
  p.default_corner_standoff_m = 0.2;
  p.default_stripe_standoff_m = 0.5;
  p.pose_history_s = 1.0;
  return p;
}

struct Fixture : ::testing::Test {
  HandEyeGeometry geo = test::project_geometry();
  ServoSession session{geo, session_params(), BookCornerServoParams{}, StripeEndServoParams{}};
  std::vector<ServoCommand> commands;
  std::vector<ServoReport> reports;

  void take(const SessionOutput& o) {
    commands.insert(commands.end(), o.commands.begin(), o.commands.end());
    reports.insert(reports.end(), o.reports.begin(), o.reports.end());
  }
  static Eigen::Isometry3d pose_x(double x) {
    Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
    p.translation().x() = x;
    return p;
  }
  void arm(int64_t t, double x = 0, ArmCondition c = ArmCondition::kExecuting, const std::string& m = "") {
    take(session.on_arm_state(t, pose_x(x), c, m));
  }
  void start_corner(int64_t t, double timeout_s = 0) {
    ServoRequest r;
    r.utime = t;
    r.request_id = 7;
    r.mode = ServoMode::kBookCorner;
    r.timeout_s = timeout_s;
    take(session.on_request(r));
  }
  BookObservation book(int64_t t, bool found, Eigen::Vector2d px = {400, 300}) {
    BookObservation o;
    o.utime = t;
    o.found = found;
    o.failure_reason = found ? "" : "no region passes the book criteria";
    o.r_px = px;
    return o;
  }
  const ServoReport& last_report() const { return reports.back(); }
};

TEST_F(Fixture, FeatureLostStopsTheArmAndSaysWhy) {
  arm(kT0);
  start_corner(kT0);
  ASSERT_EQ(last_report().state, ServoState::kRunning);
  int64_t t = kT0;
  int64_t last_good = 0;
  for (int i = 1; i <= 200; ++i) {  // arm states at 100 Hz, images at 10 Hz, lost after 0.3 s
    t = kT0 + i * 10'000;
    arm(t);
    if (i % 10 == 0) {
      const bool found = t <= kT0 + 300'000;
      if (found) last_good = t;
      take(session.on_book(book(t, found)));
    }
    if (!session.running()) break;
  }
  ASSERT_FALSE(session.running());
  EXPECT_EQ(last_report().state, ServoState::kFeatureLost);
  EXPECT_NE(last_report().message.find("no region passes the book criteria"), std::string::npos)
      << last_report().message;
  EXPECT_TRUE(commands.back().stop);
  // Stopped just after feature_lost_timeout_s of message time.
  EXPECT_GT(t - last_good, 600'000);
  EXPECT_LE(t - last_good, 610'000);
  // While stale (> 0.25 s) the commands were zero velocity.
  bool zero_seen = false;
  for (const auto& c : commands)
    if (!c.stop && c.utime > last_good + 250'000) {
      EXPECT_EQ(c.twist.norm(), 0.0);
      zero_seen = true;
    }
  EXPECT_TRUE(zero_seen);
}

TEST_F(Fixture, PipelineLatencyIsNotALostFeature) {
  // Separate processes: each measurement arrives 0.7 s (more than feature_lost_timeout_s) after its
  // image was taken, every 0.1 s. The servo keeps running and moving; lost and stale are judged by
  // arrival. Only when measurements stop arriving does it stop, 0.6 s after the last one arrived.
  arm(kT0);
  start_corner(kT0);
  int64_t t = kT0, last_arrival = 0;
  for (int i = 1; i <= 400; ++i) {
    t = kT0 + i * 10'000;
    arm(t);
    const int64_t captured = t - 700'000;
    if (i % 10 == 0 && captured >= kT0 && i <= 250) {
      take(session.on_book(book(captured, true)));
      last_arrival = t;
    }
    if (i == 240) {
      ASSERT_TRUE(session.running()) << last_report().message;
      EXPECT_GT(commands.back().twist.norm(), 0.0) << "holding despite fresh arrivals";
    }
    if (!session.running()) break;
  }
  ASSERT_FALSE(session.running());
  EXPECT_EQ(last_report().state, ServoState::kFeatureLost);
  EXPECT_GT(t - last_arrival, 600'000);
  EXPECT_LE(t - last_arrival, 610'000);
}

TEST_F(Fixture, NoMeasurementAfterTheStartIsLostAfterTheTimeoutPlusThePoseHistory) {
  arm(kT0);
  start_corner(kT0);
  int64_t t = kT0;
  for (int i = 1; i <= 300 && session.running(); ++i) {
    t = kT0 + i * 10'000;
    arm(t);
  }
  ASSERT_FALSE(session.running());
  EXPECT_EQ(last_report().state, ServoState::kFeatureLost);
  EXPECT_NE(last_report().message.find("no feature measurement of an image taken after the start"), std::string::npos)
      << last_report().message;
  EXPECT_GT(t - kT0, 1'600'000);  // 0.6 s + pose_history_s 1.0 s
  EXPECT_LE(t - kT0, 1'610'000);
}

TEST_F(Fixture, CommandsRepeatAtLeastEveryCommandPeriod) {
  arm(kT0);
  start_corner(kT0);
  for (int i = 1; i <= 100; ++i) {
    const int64_t t = kT0 + i * 10'000;
    arm(t);
    if (i % 10 == 0) take(session.on_book(book(t, true)));
  }
  ASSERT_TRUE(session.running());
  ASSERT_GT(commands.size(), 15u);
  for (size_t i = 1; i < commands.size(); ++i) EXPECT_LE(commands[i].utime - commands[i - 1].utime, 50'000);
  EXPECT_GT(commands.back().twist.norm(), 0.0);  // R is off target: moving
}

TEST_F(Fixture, TimeoutInMessageTime) {
  arm(kT0);
  start_corner(kT0, 1.0);
  int64_t t = kT0;
  for (int i = 1; i <= 300 && session.running(); ++i) {
    t = kT0 + i * 10'000;
    arm(t);
    if (i % 5 == 0) take(session.on_book(book(t, true)));
  }
  EXPECT_EQ(last_report().state, ServoState::kTimeout);
  EXPECT_EQ(t, kT0 + 1'000'000);
  EXPECT_TRUE(commands.back().stop);
}

TEST_F(Fixture, StartChecks) {
  ServoRequest r;
  r.request_id = 1;
  r.mode = ServoMode::kStripeEnd;
  take(session.on_request(r));
  EXPECT_EQ(last_report().state, ServoState::kFailed);
  EXPECT_NE(last_report().message.find("ARM_STATE"), std::string::npos);

  arm(kT0, 0.0);
  r.start_pose = pose_x(0.1);
  take(session.on_request(r));
  EXPECT_EQ(last_report().state, ServoState::kFailed);
  EXPECT_NE(last_report().message.find("start_pose"), std::string::npos);
  EXPECT_FALSE(session.running());

  r.start_pose = pose_x(0.02);
  take(session.on_request(r));
  EXPECT_EQ(last_report().state, ServoState::kRunning);
}

TEST_F(Fixture, CancelAndReplace) {
  arm(kT0);
  start_corner(kT0);
  start_corner(kT0 + 10);  // replaces: the first is reported cancelled
  ASSERT_GE(reports.size(), 3u);
  EXPECT_EQ(reports[reports.size() - 2].state, ServoState::kCancelled);
  ServoRequest c;
  c.mode = ServoMode::kCancel;
  c.request_id = 9;
  take(session.on_request(c));
  EXPECT_EQ(last_report().state, ServoState::kCancelled);
  EXPECT_TRUE(commands.back().stop);
  EXPECT_FALSE(session.running());
}

TEST_F(Fixture, IgnoresImagesBeforeTheStartAndOtherRanks) {
  arm(kT0 + 100'000);
  start_corner(kT0 + 100'000);
  take(session.on_book(book(kT0 + 50'000, true)));  // taken before the request
  BookObservation other = book(kT0 + 110'000, true);
  other.rank_from_right = 1;  // answers another rank
  take(session.on_book(other));
  EXPECT_EQ(last_report().iterations, 0);
  take(session.on_book(book(kT0 + 120'000, true)));
  EXPECT_EQ(last_report().iterations, 1);
}

TEST_F(Fixture, ConvergedPoseIsThePoseAtCapture) {
  arm(kT0, 0.0);
  start_corner(kT0);
  const Eigen::Vector2d target = geo.target_pixel(0.2);
  for (int i = 1; i <= 30 && session.running(); ++i) {
    const int64_t t = kT0 + i * 10'000;
    arm(t, 0.001 * i);                                                      // the arm reports a moving TCP
    if (i % 10 == 0) take(session.on_book(book(t - 5'000, true, target)));  // image 5 ms old
  }
  ASSERT_EQ(last_report().state, ServoState::kConverged);
  ASSERT_TRUE(last_report().converged_pose.has_value());
  // Captured at kT0 + 295 ms: the last arm state at or before that is i = 29.
  EXPECT_NEAR(last_report().converged_pose->translation().x(), 0.029, 1e-12);
  EXPECT_TRUE(commands.back().stop);
}

TEST_F(Fixture, ArmDriverStopFailsTheTask) {
  arm(kT0, 0, ArmCondition::kIdle);
  start_corner(kT0);
  take(session.on_book(book(kT0 + 10'000, true)));
  arm(kT0 + 20'000, 0, ArmCondition::kExecuting);
  arm(kT0 + 30'000, 0, ArmCondition::kStopped, "workspace limit: TCP z 1.31 > 1.30");
  EXPECT_EQ(last_report().state, ServoState::kFailed);
  EXPECT_NE(last_report().message.find("workspace limit"), std::string::npos);
}

/// Closes `session` (its task started by `request`) on a kinematic arm from `tcp`: an arm state every 10 ms with
/// the TCP following the last command, an image every 0.1 s (`capture(t, tcp)` gives what the detector saw) reaching
/// the session through `deliver(capture_time, observation)` `latency_s` after it was taken (the deployed camera ->
/// detector pipeline on a loaded machine), for at most `ticks` arm states. Returns the last report and the TCP.
template <typename Capture, typename Deliver>
std::pair<ServoReport, Eigen::Isometry3d> run_with_late_images(ServoSession& session, Eigen::Isometry3d tcp,
                                                               const ServoRequest& request, double latency_s, int ticks,
                                                               Capture capture, Deliver deliver) {
  std::vector<ServoReport> reports;
  GripperTwist twist = GripperTwist::Zero();
  auto take = [&](const SessionOutput& o) {
    for (const auto& c : o.commands) twist = c.stop ? GripperTwist::Zero() : c.twist;
    reports.insert(reports.end(), o.reports.begin(), o.reports.end());
  };
  take(session.on_arm_state(kT0, tcp, ArmCondition::kIdle, ""));
  take(session.on_request(request));
  using Observation = decltype(capture(int64_t{0}, tcp));
  std::deque<std::pair<int64_t, Observation>> in_flight;  // (capture time, what the detector saw)
  const int64_t latency_us = static_cast<int64_t>(latency_s * 1e6);
  for (int i = 1; i <= ticks && session.running(); ++i) {
    const int64_t t = kT0 + i * 10'000;
    tcp = test::integrate(tcp, twist, 0.01);
    take(session.on_arm_state(t, tcp, ArmCondition::kExecuting, ""));
    if (i % 10 == 0) in_flight.emplace_back(t, capture(t, tcp));
    while (!in_flight.empty() && in_flight.front().first + latency_us <= t) {
      take(deliver(in_flight.front().first, in_flight.front().second));
      in_flight.pop_front();
    }
  }
  return {reports.back(), tcp};
}

/// The stripe servo with images `latency_s` late (run_with_late_images). Returns the final report and the TCP.
std::pair<ServoReport, Eigen::Isometry3d> run_late_stripe(double latency_s, bool compensate) {
  const HandEyeGeometry geo = test::project_geometry();
  StripeEndServoParams sp;
  sp.gain = 1.2;
  sp.max_linear_speed = 0.06;
  sp.search_direction = -1;
  sp.require_occlusion = false;
  sp.min_track_speed = 0.004;
  sp.compensate_capture_delay = compensate;
  ServoSession session{geo, session_params(), BookCornerServoParams{}, sp};
  // The true end at Y = books_right = 0.15. The visible end is where the books' edge hides the stripe, so it moves
  // with the camera: books 0.30 deep in front of the board 0.50 away move it (0.5 / 0.3 =) 1.7 times as fast as the
  // camera, about as the cart's 0.15-0.25 m deep books do at the coordinator's 0.43 m standoff.
  test::StripeScene scene;
  scene.books_z = 0.30;
  Eigen::Isometry3d tcp = Eigen::Isometry3d::Identity();
  tcp.translation() = Eigen::Vector3d(0.01, 0.30, 0.0);  // 15 cm right of the end: its left end is in view
  ServoRequest r;
  r.utime = kT0;
  r.request_id = 9;
  r.mode = ServoMode::kStripeEnd;
  r.standoff_m = scene.board_z;
  r.timeout_s = 30;
  return run_with_late_images(
      session, tcp, r, latency_s, 3100, [&](int64_t, const Eigen::Isometry3d& at) { return scene.observe(geo, at); },
      [&](int64_t t, const StripeObservation& o) { return session.on_stripe(t, o, ""); });
}

TEST(StripeServoLatency, ImagesASecondLateStillConvergeOnTheTrueEnd) {
  // Without the motion since capture subtracted, the loop swings past the end and back until its timeout (as the
  // deployed stripe servo did, +-100 px around the end); with it, it converges as with fresh images.
  for (const double latency : {0.0, 0.7, 1.0}) {
    const auto [report, tcp] = run_late_stripe(latency, true);
    ASSERT_EQ(report.state, ServoState::kConverged) << "latency " << latency << ": " << report.message;
    ASSERT_TRUE(report.converged_pose.has_value());
    EXPECT_NEAR(report.converged_pose->translation().y(), 0.15, 1.5e-3) << "latency " << latency;
    EXPECT_NEAR(report.converged_pose->translation().x(), 0.0, 1.5e-3) << "latency " << latency;
  }
  const auto [uncompensated, tcp] = run_late_stripe(1.0, false);
  EXPECT_NE(uncompensated.state, ServoState::kConverged) << "the test plant no longer shows the overshoot";
}

/// The corner servo with images `latency_s` late (run_with_late_images); the corner 4 cm up and 3 cm right of the
/// start and `corner_z` ahead of it (the servo assumes 0.22 m), its top edge rolled 3 degrees. Returns the final
/// report.
/// With `other_corner_views` > 0 BwH first takes other books' corners for R, that many views in all, in turns among
/// three 12 mm wide fore-edges left of the target (as far_cart seed 5345's did on the way up).
ServoReport run_late_corner(double latency_s, bool compensate, double corner_z = 0.22, double target_above_m = 0.0,
                            Eigen::Isometry3d* final_tcp = nullptr, bool bwh_gives_width = true,
                            double neighbour_offset_m = 0.0, double neighbour_width_m = 0.0,
                            int other_corner_views = 0) {
  const HandEyeGeometry geo = test::project_geometry();
  BookCornerServoParams cp;
  cp.target_above_tcp_m = target_above_m;
  cp.gain = 2.0;
  cp.slope_gain = 2.0;
  cp.max_linear_speed = 0.06;
  cp.max_angular_speed = 0.3;
  cp.converged_px = 2.0;
  cp.converged_slope_rad = 1.5 * M_PI / 180.0;
  cp.compensate_capture_delay = compensate;
  ServoSession session{geo, session_params(), cp, StripeEndServoParams{}};
  test::CornerScene scene;
  scene.corner = Eigen::Vector3d(0.04, 0.03, corner_z);
  scene.roll_rad = 3.0 * M_PI / 180.0;
  scene.neighbour_offset_m = neighbour_offset_m;
  scene.neighbour_width_m = neighbour_width_m;
  ServoRequest r;
  r.utime = kT0;
  r.request_id = 11;
  r.mode = ServoMode::kBookCorner;
  r.standoff_m = 0.22;
  r.timeout_s = 20;
  std::vector<test::CornerScene> others(3, scene);
  others[0].corner += Eigen::Vector3d(-0.02, -0.035, 0.01);
  others[1].corner += Eigen::Vector3d(-0.04, -0.06, 0.0);
  others[2].corner += Eigen::Vector3d(0.0, -0.08, -0.01);
  for (auto& other : others) other.width_m = 0.012;
  int captures = 0;
  const auto capture = [&](int64_t t, const Eigen::Isometry3d& at) {
    BookObservation o;
    o.utime = t;
    const int c = captures++;
    const test::CornerScene& seen = c < other_corner_views ? others[size_t(c % 3)] : scene;
    o.found = seen.observe(geo, at, &o.r_px, &o.slope_rad, bwh_gives_width ? &o.width_px : nullptr);
    if (o.found) scene.observe_neighbour(geo, at, &o.neighbour_offset_px, &o.neighbour_width_px);
    return o;
  };
  const auto [report, tcp] =
      run_with_late_images(session, Eigen::Isometry3d::Identity(), r, latency_s, 2100, capture,
                           [&](int64_t, const BookObservation& o) { return session.on_book(o); });
  if (final_tcp) *final_tcp = tcp;
  return report;
}

TEST(CornerServoLatency, ImagesASecondLateStillConvergeOnTheTrueCorner) {
  for (const double latency : {0.0, 0.7, 1.0}) {
    const ServoReport report = run_late_corner(latency, true);
    ASSERT_EQ(report.state, ServoState::kConverged) << "latency " << latency << ": " << report.message;
    ASSERT_TRUE(report.converged_pose.has_value());
    // The TCP axis through the corner (the target pixel is R straight ahead at the standoff).
    EXPECT_NEAR(report.converged_pose->translation().x(), 0.04, 1.5e-3) << "latency " << latency;
    EXPECT_NEAR(report.converged_pose->translation().y(), 0.03, 1.5e-3) << "latency " << latency;
  }
  EXPECT_NE(run_late_corner(1.0, false).state, ServoState::kConverged) << "the plant no longer shows the overshoot";
}

// Not in the paper: with book_corner.target_above_tcp_m the servo ends with the TCP that far below R (the camera,
// 6 cm above the TCP, then sees R higher in its image), and P2 is that pose raised to R.
TEST(CornerServoTargetAbove, TheTcpEndsBelowRAndP2IsAtR) {
  for (const double above : {0.02, -0.01}) {
    SCOPED_TRACE("target_above_tcp_m " + std::to_string(above));
    Eigen::Isometry3d tcp = Eigen::Isometry3d::Identity();
    const ServoReport report = run_late_corner(0.0, true, 0.22, above, &tcp);
    ASSERT_EQ(report.state, ServoState::kConverged) << report.message;
    ASSERT_TRUE(report.converged_pose.has_value());
    const Eigen::Vector3d r_in_tcp = tcp.inverse() * Eigen::Vector3d(0.04, 0.03, 0.22);
    EXPECT_NEAR(r_in_tcp.x(), above, 1.5e-3);  // the arm: `above` below R along its (rolled) x
    EXPECT_NEAR(r_in_tcp.y(), 0.0, 1.5e-3);
    EXPECT_NEAR(report.converged_pose->translation().x(), 0.04, 1.5e-3);  // P2: at R
    EXPECT_NEAR(report.converged_pose->translation().y(), 0.03, 1.5e-3);
    EXPECT_NEAR(report.converged_pose->translation().z(), tcp.translation().z(), 1e-9);  // the standoff kept
    EXPECT_TRUE(report.converged_pose->linear().isApprox(tcp.linear(), 1e-3));
    EXPECT_NE(report.message.find("P2 is the TCP raised by"), std::string::npos) << report.message;
  }
  // R's target pixel is higher in the image (smaller v) for a target above the TCP.
  const HandEyeGeometry geo = test::project_geometry();
  EXPECT_LT(geo.target_pixel(0.09, 0.02).y(), geo.target_pixel(0.09).y() - 20.0);
}

// Not in the paper: the converged report carries R located from the servo's views; it is right where the assumed
// standoff is not (a front 6 cm deeper than assumed puts the converged TCP ~2 cm low, the camera being 6 cm above it).
TEST(NextForeEdge, TheAcceptedCandidateNearestLeftOfRIsTheNeighbour) {
  BookObservation o;
  o.r_px = Eigen::Vector2d(400, 200);
  // R's own candidate (400), one rejected nearer (380), the neighbour (372, 25 px), one further left (330), one right
  // of R (450).
  set_next_fore_edge({{400, 40, true}, {380, 10, false}, {372, 25, true}, {330, 30, true}, {450, 20, true}}, &o);
  EXPECT_DOUBLE_EQ(o.neighbour_offset_px, 28);
  EXPECT_DOUBLE_EQ(o.neighbour_width_px, 25);
  // None left of R, or none accepted, or a width that is no width: nothing measured.
  for (const auto& cands : {std::vector<ForeEdgeCandidate>{{400, 40, true}, {450, 20, true}},
                            std::vector<ForeEdgeCandidate>{{372, 25, false}},
                            std::vector<ForeEdgeCandidate>{{372, double(NAN), true}, {360, 0, true}}}) {
    BookObservation none;
    none.r_px = o.r_px;
    set_next_fore_edge(cands, &none);
    EXPECT_EQ(none.neighbour_offset_px, 0);
    EXPECT_EQ(none.neighbour_width_px, 0);
  }
}

TEST(CornerServoTriangulation, TheConvergedReportLocatesRAtItsTrueDepth) {
  for (const double corner_z : {0.22, 0.28, 0.16}) {
    for (const double latency : {0.0, 0.7}) {
      SCOPED_TRACE("corner z " + std::to_string(corner_z) + ", latency " + std::to_string(latency));
      const ServoReport report = run_late_corner(latency, true, corner_z);
      ASSERT_EQ(report.state, ServoState::kConverged) << report.message;
      ASSERT_TRUE(report.corner.has_value()) << report.message;
      EXPECT_LT((report.corner->point - Eigen::Vector3d(0.04, 0.03, corner_z)).norm(), 2e-3)
          << report.corner->point.transpose();
      EXPECT_GT(report.corner->baseline_m, 0.04);  // the servo moved 5 cm
      EXPECT_LT(report.corner->rms_px, 0.5);
      EXPECT_NE(report.message.find("R triangulated"), std::string::npos) << report.message;
      // The fore-edge's width (the scene's top edge, 3 cm) from BwH's widths at R's triangulated depth: right where
      // the assumed standoff is not.
      EXPECT_NEAR(report.front_width_m, 0.03, 1e-3) << report.message;
      EXPECT_NE(report.message.find("fore-edge 30."), std::string::npos) << report.message;
    }
  }
  // Without BwH widths there is no width (0), and the message gives none.
  const ServoReport no_width = run_late_corner(0.0, true, 0.22, 0.0, nullptr, false);
  ASSERT_EQ(no_width.state, ServoState::kConverged) << no_width.message;
  EXPECT_EQ(no_width.front_width_m, 0.0);
  EXPECT_EQ(no_width.message.find("fore-edge"), std::string::npos) << no_width.message;
  EXPECT_EQ(no_width.neighbour_width_m, 0.0);
  // The next fore-edge (a 2 mm gap, 18 mm wide) measured the same way, at R's depth: where the assumed standoff
  // (0.22 m) is not, too.
  for (const double corner_z : {0.22, 0.28}) {
    const ServoReport next = run_late_corner(0.0, true, corner_z, 0.0, nullptr, true, 0.032, 0.018);
    ASSERT_EQ(next.state, ServoState::kConverged) << next.message;
    EXPECT_NEAR(next.neighbour_offset_m, 0.032, 1e-3) << next.message;
    EXPECT_NEAR(next.neighbour_width_m, 0.018, 1e-3) << next.message;
    EXPECT_NE(next.message.find("the next fore-edge 32."), std::string::npos) << next.message;
  }
  // BwH took other books' (12 mm) corners for R in the first 24 views, more views than the target's: the width comes
  // from the views that saw R at the triangulated corner (it was 17.6 mm for a 30.4 mm book on far_cart seed 5345,
  // whose open left plate then pushed the book in).
  const ServoReport detour = run_late_corner(0.0, true, 0.22, 0.0, nullptr, true, 0.0, 0.0, 24);
  ASSERT_EQ(detour.state, ServoState::kConverged) << detour.message;
  ASSERT_TRUE(detour.corner.has_value()) << detour.message;
  EXPECT_LT((detour.corner->point - Eigen::Vector3d(0.04, 0.03, 0.22)).norm(), 2e-3);
  EXPECT_LT(detour.corner->agreeing.size(), 24u) << "the test needs the other corners' views to be the majority";
  EXPECT_NEAR(detour.front_width_m, 0.03, 1e-3) << detour.message;
  // The assumed depth's error shows in the converged pose's X, not in the triangulated corner.
  const ServoReport deep = run_late_corner(0.0, true, 0.28);
  EXPECT_GT(std::abs(deep.converged_pose->translation().x() - 0.04), 0.01);
}

}  // namespace
}  // namespace bookgrasp
