#include "services/arm_driver/joint_trajectory.h"

#include <gtest/gtest.h>

#include <cmath>

namespace bookgrasp {
namespace {

ArmLimits limits2() {
  ArmLimits l;
  l.joint_names = {"a", "b"};
  l.lower = Eigen::Vector2d(-1, -1);
  l.upper = Eigen::Vector2d(1, 1);
  l.max_velocity = Eigen::Vector2d(1, 1);
  l.max_acceleration = Eigen::Vector2d(2, 2);
  l.workspace_min = Eigen::Vector3d(-1, -1, -1);
  l.workspace_max = Eigen::Vector3d(1, 1, 1);
  l.start_tolerance = 0.01;
  return l;
}

// TCP model for the tests: the point (q0, q1, 0).
Eigen::Vector3d tcp(const Eigen::VectorXd& q) { return Eigen::Vector3d(q[0], q[1], 0); }

JointTrajectory line(double q_end, double duration, int n = 11) {
  JointTrajectory t;
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / (n - 1);
    t.times.push_back(s * duration);
    t.positions.push_back(Eigen::Vector2d(s * q_end, -s * q_end));
    t.velocities.push_back(Eigen::Vector2d(q_end / duration, -q_end / duration));
  }
  t.velocities.front().setZero();
  t.velocities.back().setZero();
  return t;
}

TEST(JointTrajectory, HermiteReproducesACubicExactly) {
  // q(t) = 0.1 + 0.2 t - 0.3 t^2 + 0.05 t^3, waypoints at t = 0, 1, 2 with exact positions and velocities.
  auto q = [](double t) { return 0.1 + 0.2 * t - 0.3 * t * t + 0.05 * t * t * t; };
  auto v = [](double t) { return 0.2 - 0.6 * t + 0.15 * t * t; };
  JointTrajectory tr;
  for (double t : {0.0, 1.0, 2.0}) {
    tr.times.push_back(t);
    tr.positions.push_back(Eigen::VectorXd::Constant(1, q(t)));
    tr.velocities.push_back(Eigen::VectorXd::Constant(1, v(t)));
  }
  for (double t : {0.0, 0.3, 0.99, 1.0, 1.7, 1.95}) {
    Eigen::VectorXd qq, vv;
    sample_trajectory(tr, t, &qq, &vv);
    EXPECT_NEAR(qq[0], q(t), 1e-12) << t;
    EXPECT_NEAR(vv[0], v(t), 1e-12) << t;
  }
  Eigen::VectorXd qq, vv;
  sample_trajectory(tr, 5.0, &qq, &vv);
  EXPECT_NEAR(qq[0], q(2.0), 1e-12);
  EXPECT_EQ(vv[0], 0.0) << "at rest after the end";
}

TEST(JointTrajectory, ValidTrajectoryAccepted) {
  EXPECT_EQ(validate_trajectory(line(0.5, 2.0), Eigen::Vector2d::Zero(), limits2(), tcp), "");
}

std::string why(const JointTrajectory& t, Eigen::VectorXd current = Eigen::Vector2d::Zero()) {
  return validate_trajectory(t, current, limits2(), tcp);
}

TEST(JointTrajectory, EveryLimitViolationIsRefusedWithAReason) {
  auto t = line(0.5, 2.0);
  t.positions[5][1] = 1.2;
  EXPECT_NE(why(t).find("joint b position 1.2000 rad outside [-1.0000, 1.0000]"), std::string::npos) << why(t);

  t = line(0.5, 2.0);
  t.velocities[3][0] = 1.5;
  EXPECT_NE(why(t).find("joint a velocity 1.500 rad/s > limit 1.000"), std::string::npos) << why(t);

  t = line(0.9, 0.5);  // 1.8 rad/s on average (no per-waypoint velocities: only the mean can catch it)
  t.velocities.clear();
  EXPECT_NE(why(t).find("on average > limit"), std::string::npos) << why(t);

  t = line(0.5, 2.0);
  t.accelerations.assign(t.positions.size(), Eigen::Vector2d(0, 0));
  t.accelerations[2][1] = -2.5;
  EXPECT_NE(why(t).find("joint b acceleration 2.500"), std::string::npos) << why(t);

  t = line(0.5, 2.0);  // velocity steps of 0.25 rad/s within 0.2 s = 1.25 rad/s^2: fine; make it 0.05 s
  for (auto& x : t.times) x *= 0.1;
  for (auto& v : t.velocities) v *= 0.0;
  EXPECT_NE(why(t).find("limit"), std::string::npos) << why(t);

  t = line(0.5, 2.0);
  t.positions[4][0] = NAN;
  EXPECT_NE(why(t).find("not finite"), std::string::npos);

  t = line(0.5, 2.0);
  t.positions[0] = Eigen::Vector3d(0, 0, 0);
  EXPECT_NE(why(t).find("3 joint values, the arm has 2"), std::string::npos) << why(t);

  t = line(0.5, 2.0);
  t.times[3] = t.times[2];
  EXPECT_NE(why(t).find("increase strictly"), std::string::npos);

  EXPECT_NE(why(line(0.5, 2.0), Eigen::Vector2d(0.05, 0)).find("does not start at the current state"),
            std::string::npos);

  t = line(0.5, 2.0);
  t.joint_names = {"b", "a"};
  EXPECT_NE(why(t).find("joint names"), std::string::npos);

  ArmLimits small = limits2();
  small.workspace_max = Eigen::Vector3d(0.3, 1, 1);
  EXPECT_NE(validate_trajectory(line(0.5, 2.0), Eigen::Vector2d::Zero(), small, tcp).find("leaves the workspace"),
            std::string::npos);

  EXPECT_NE(why(JointTrajectory{}).find("no waypoints"), std::string::npos);
}

}  // namespace
}  // namespace bookgrasp
