// Trapezoidal time parameterisation: durations computed by hand, limits
// checked by finite differences of the sampled positions.
#include "services/planner/time_parameterization.h"

#include <cmath>

#include <gtest/gtest.h>

namespace bookgrasp {
namespace {

Eigen::VectorXd v2(double a, double b) { return (Eigen::VectorXd(2) << a, b).finished(); }

TEST(TimeParameterization, TrapezoidDurationByHand) {
  // 1 rad at v = 1 rad/s, a = 2 rad/s^2: 0.5 s up (0.25 rad), 0.5 s cruise (0.5 rad), 0.5 s down.
  const TimedTrajectory t = parameterize_trapezoidal({v2(0, 0), v2(1, 0)}, v2(1, 1), v2(2, 2), 0.01);
  EXPECT_NEAR(t.duration_s, 1.5, 1e-9);
  EXPECT_NEAR(t.points.back().time_s, 1.5, 1e-9);
  EXPECT_NEAR(t.points.back().position[0], 1.0, 1e-12);
  // Halfway in time the joint is halfway and at full speed.
  for (const auto& p : t.points) {
    if (std::abs(p.time_s - 0.75) < 1e-9) {
      EXPECT_NEAR(p.position[0], 0.5, 1e-9);
      EXPECT_NEAR(p.velocity[0], 1.0, 1e-9);
    }
  }
}

TEST(TimeParameterization, TriangleWhenTheSpeedIsNeverReached) {
  // 0.25 rad at a = 2: peak speed sqrt(a * d) = 0.7071 < 1, T = 2 * sqrt(d / a) = 0.7071 s.
  const TimedTrajectory t = parameterize_trapezoidal({v2(0, 0), v2(0.25, 0)}, v2(1, 1), v2(2, 2), 0.01);
  EXPECT_NEAR(t.duration_s, 2 * std::sqrt(0.25 / 2), 1e-9);
  double vmax = 0;
  for (const auto& p : t.points) vmax = std::max(vmax, std::abs(p.velocity[0]));
  EXPECT_NEAR(vmax, std::sqrt(0.5), 0.02);
}

TEST(TimeParameterization, JointsAreSynchronisedAndTheSlowestSetsThePace) {
  // Joint 0 moves 1 rad, joint 1 moves 0.5 rad with a limit of 0.25 rad/s: joint 1 is the slow one.
  const TimedTrajectory t = parameterize_trapezoidal({v2(0, 0), v2(1, 0.5)}, v2(1, 0.25), v2(2, 2), 0.01);
  for (const auto& p : t.points) {
    // Straight line in joint space: joint 1 = joint 0 / 2 at every sample.
    EXPECT_NEAR(p.position[1], 0.5 * p.position[0], 1e-12);
    EXPECT_LE(std::abs(p.velocity[1]), 0.25 + 1e-9);
  }
  // Path parameter s in [0, 1]: peak s' = min(1 / 1, 0.25 / 0.5) = 0.5 (joint 1), s'' = min(2 / 1, 2 / 0.5) = 2
  // (joint 0): T = 1 / 0.5 + 0.5 / 2 = 2.25 s.
  EXPECT_NEAR(t.duration_s, 2.25, 1e-9);
}

TEST(TimeParameterization, LimitsHoldByFiniteDifferencesAndWaypointsAreHit) {
  std::vector<Eigen::VectorXd> wp;
  Eigen::VectorXd a(3), b(3), c(3), d(3);
  a << 0, 0, 0;
  b << 0.8, -0.3, 0.1;
  c << 0.8, 0.9, -1.2;
  d << -0.4, 0.2, 0.0;
  wp = {a, b, c, d};
  const Eigen::VectorXd vmax = (Eigen::VectorXd(3) << 1.0, 0.7, 1.5).finished();
  const Eigen::VectorXd amax = (Eigen::VectorXd(3) << 2.0, 1.0, 3.0).finished();
  const double dt = 0.001;
  const TimedTrajectory t = parameterize_trapezoidal(wp, vmax, amax, dt);
  EXPECT_TRUE(t.points.front().position.isApprox(a));
  EXPECT_TRUE(t.points.back().position.isApprox(d));
  EXPECT_NEAR(t.points.back().velocity.norm(), 0.0, 1e-12);
  size_t hit = 0;
  for (const auto& p : t.points)
    for (const auto& w : wp)
      if ((p.position - w).norm() < 1e-12 && p.velocity.norm() < 1e-12) ++hit;
  EXPECT_GE(hit, wp.size());  // at rest on every waypoint
  for (size_t i = 1; i < t.points.size(); ++i) {
    const double h = t.points[i].time_s - t.points[i - 1].time_s;
    ASSERT_GT(h, 0.0);
    const Eigen::VectorXd v = (t.points[i].position - t.points[i - 1].position) / h;
    for (int j = 0; j < 3; ++j) {
      EXPECT_LE(std::abs(v[j]), vmax[j] * (1 + 1e-6)) << "velocity of joint " << j << " at t=" << t.points[i].time_s;
      EXPECT_LE(std::abs(t.points[i].velocity[j]), vmax[j] * (1 + 1e-9));
      EXPECT_LE(std::abs(t.points[i].acceleration[j]), amax[j] * (1 + 1e-9));
    }
    if (i >= 2 && std::abs(h - dt) < 1e-9 && std::abs(t.points[i - 1].time_s - t.points[i - 2].time_s - dt) < 1e-9) {
      const Eigen::VectorXd v_prev = (t.points[i - 1].position - t.points[i - 2].position) / dt;
      const Eigen::VectorXd acc = (v - v_prev) / dt;
      for (int j = 0; j < 3; ++j) EXPECT_LE(std::abs(acc[j]), amax[j] * 1.01) << "acceleration of joint " << j;
    }
  }
}

TEST(TimeParameterization, SinglePointAndRepeatedPoints) {
  const TimedTrajectory one = parameterize_trapezoidal({v2(1, 2)}, v2(1, 1), v2(1, 1), 0.01);
  ASSERT_EQ(one.points.size(), 1u);
  EXPECT_EQ(one.duration_s, 0.0);
  const TimedTrajectory rep = parameterize_trapezoidal({v2(0, 0), v2(0, 0), v2(1, 0)}, v2(1, 1), v2(2, 2), 0.01);
  EXPECT_NEAR(rep.duration_s, 1.5, 1e-9);
}

TEST(TimeParameterization, BadInputsThrow) {
  EXPECT_THROW(parameterize_trapezoidal({}, v2(1, 1), v2(1, 1), 0.01), std::invalid_argument);
  EXPECT_THROW(parameterize_trapezoidal({v2(0, 0)}, v2(1, 0), v2(1, 1), 0.01), std::invalid_argument);
  EXPECT_THROW(parameterize_trapezoidal({v2(0, 0)}, v2(1, 1), v2(1, 1), 0.0), std::invalid_argument);
  EXPECT_THROW(parameterize_trapezoidal({Eigen::VectorXd::Zero(3)}, v2(1, 1), v2(1, 1), 0.01), std::invalid_argument);
}

TEST(TimeParameterization, SamplesStayApartInWholeMicroseconds) {
  // A triangle of T = 2 sqrt(d / a) = 0.1 s + 0.3 us (a = 1, d = (0.05 + 1.5e-7)^2): the grid sample at 0.1 s lies
  // 0.3 us before the segment's end. Trajectory messages carry microseconds, so both became utime 100000 and the arm
  // driver refused the command. The sample is dropped; the end is kept exactly.
  const double d = std::pow(0.05 + 1.5e-7, 2);
  const TimedTrajectory t = parameterize_trapezoidal({v2(0, 0), v2(d, 0), v2(d, 0.01)}, v2(10, 10), v2(1, 1), 0.01);
  EXPECT_NEAR(t.points.back().position[0], d, 1e-15);
  EXPECT_NEAR(t.points.back().position[1], 0.01, 1e-15);
  for (size_t k = 1; k < t.points.size(); ++k)
    EXPECT_GT(std::llround(t.points[k].time_s * 1e6), std::llround(t.points[k - 1].time_s * 1e6))
        << "samples " << k - 1 << " and " << k << " at " << t.points[k - 1].time_s << " and " << t.points[k].time_s;
  // A step of 1e-11 rad (a planner's "repeated" waypoint that is not quite one) adds no sample of its own.
  const TimedTrajectory tiny = parameterize_trapezoidal({v2(0, 0), v2(1e-11, 0)}, v2(1, 1), v2(2, 2), 0.01);
  ASSERT_EQ(tiny.points.size(), 1u);
  EXPECT_EQ(tiny.points.back().position[0], 1e-11);
}

}  // namespace
}  // namespace bookgrasp
