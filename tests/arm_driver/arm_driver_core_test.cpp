#include "services/arm_driver/arm_driver_core.h"

#include <gtest/gtest.h>

#include <cmath>

namespace bookgrasp {
namespace {

ArmDriverCore make_core(double nullspace_gain = 0.0, const Eigen::VectorXd& preferred = Eigen::VectorXd(),
                        double limit_margin = 0.0, double limit_gain = 0.0) {
  ArmKinematics kin = ArmKinematics::from_urdf_file(std::string(BOOKGRASP_SOURCE_DIR) + "/config/robot/lwa3_pg70.urdf",
                                                    "base", "gripper");
  ArmLimits l;
  l.joint_names = kin.joint_names();
  l.lower = kin.lower_limits();
  l.upper = kin.upper_limits();
  l.max_velocity = kin.velocity_limits() * 0.5;
  l.max_acceleration = Eigen::VectorXd::Constant(7, 2.0);
  l.workspace_min = Eigen::Vector3d(-0.35, -0.95, -0.75);
  l.workspace_max = Eigen::Vector3d(1.15, 0.95, 1.3);
  l.start_tolerance = 0.03;
  l.max_linear_speed = 0.15;
  l.max_angular_speed = 0.6;
  DriverParams p;
  p.heartbeat_timeout_s = 0.5;
  p.nullspace_gain = nullspace_gain;
  p.preferred_posture = preferred;
  p.nullspace_limit_margin = limit_margin;
  p.nullspace_limit_gain = limit_gain;
  return ArmDriverCore(std::move(kin), l, p);
}

// A bent, well-conditioned start posture.
Eigen::VectorXd home() {
  Eigen::VectorXd q(7);
  q << 0.0, 0.6, 0.0, 1.2, 0.0, 0.6, 0.0;
  return q;
}

JointTrajectory move(const Eigen::VectorXd& from, const Eigen::VectorXd& to, double duration) {
  JointTrajectory t;
  const int n = 21;
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / (n - 1);
    // Smooth s-curve 3s^2 - 2s^3 and its derivative.
    const double p = 3 * s * s - 2 * s * s * s, dp = (6 * s - 6 * s * s) / duration;
    t.times.push_back(s * duration);
    t.positions.push_back(from + p * (to - from));
    t.velocities.push_back(dp * (to - from));
  }
  return t;
}

constexpr int64_t kT0 = 1000000000;

// Runs the driver from kT0 for 1 s at 100 Hz with a heartbeat each step; returns the last setpoint.
DriverSetpoint stream_for_one_second(ArmDriverCore& d) {
  DriverSetpoint sp;
  d.update(kT0);
  for (int64_t t = kT0 + 10000; t <= kT0 + 1000000; t += 10000) {
    d.heartbeat();
    sp = d.update(t);
  }
  return sp;
}

TEST(ArmDriverCore, RefusesCommandsBeforeAnyMeasurement) {
  ArmDriverCore d = make_core();
  EXPECT_NE(d.command_trajectory(move(home(), home(), 1.0), 1).find("no measurement"), std::string::npos);
}

TEST(ArmDriverCore, HoldsAMeasuredGripperWidthOnlyWithinTheStroke) {
  // A (re)started driver holds the plates where they are; a reading a little beyond the stroke
  // (0.0603 m with max_width 0.0602) must not become a setpoint the gripper rejects.
  const DriverParams limits;  // make_core() keeps the default stroke [0, 0.0602] m
  ArmDriverCore d = make_core();
  d.on_measurement(kT0, home(), limits.gripper_max_width + 0.0001);
  EXPECT_DOUBLE_EQ(d.update(kT0).gripper_width, limits.gripper_max_width);
  d.restart(kT0 + 1000, home(), limits.gripper_min_width - 0.001);
  EXPECT_DOUBLE_EQ(d.update(kT0 + 1000).gripper_width, limits.gripper_min_width);
  d.restart(kT0 + 2000, home(), 0.031);
  EXPECT_DOUBLE_EQ(d.update(kT0 + 2000).gripper_width, 0.031);
}

TEST(ArmDriverCore, ARestartedDriverKeepsSqueezingWhatThePlatesHold) {
  // Started (or its source restarted) while the plates touch something (a book 24.8 mm wide): the setpoint
  // keeps closing with force; holding the measured width would hold the book with no force and drop it.
  const DriverParams p;
  ArmDriverCore d = make_core();
  d.on_measurement(kT0, home(), 0.0248, true);
  DriverSetpoint sp = d.update(kT0);
  EXPECT_DOUBLE_EQ(sp.gripper_width, p.gripper_min_width);
  EXPECT_DOUBLE_EQ(sp.gripper_force, p.gripper_default_force);
  d.restart(kT0 + 1000, home(), 0.0248, true);
  sp = d.update(kT0 + 1000);
  EXPECT_DOUBLE_EQ(sp.gripper_width, p.gripper_min_width);
  EXPECT_GT(sp.gripper_force, 0);
  // Without contact the plates stay where they are.
  ArmDriverCore free = make_core();
  free.on_measurement(kT0, home(), 0.0248, false);
  EXPECT_DOUBLE_EQ(free.update(kT0).gripper_width, 0.0248);
  // Open plates that touch a neighbour hold nothing: they stay open.
  ArmDriverCore open = make_core();
  open.on_measurement(kT0, home(), 0.060, true);
  EXPECT_DOUBLE_EQ(open.update(kT0).gripper_width, 0.060);
}

TEST(ArmDriverCore, HoldsAMeasuredPostureOnlyWithinTheJointLimits) {
  // A restarted driver finds the elbow pushed 0.01 rad past its limit: it holds the limit itself,
  // a setpoint the arm accepts, not the measured value.
  ArmDriverCore d = make_core();
  Eigen::VectorXd q = home();
  q[3] = d.limits().upper[3] + 0.01;
  d.restart(kT0, q, 0.03);
  const DriverSetpoint sp = d.update(kT0);
  EXPECT_DOUBLE_EQ(sp.q[3], d.limits().upper[3]);
  for (int j = 0; j < 7; ++j) {
    if (j != 3) {
      EXPECT_DOUBLE_EQ(sp.q[j], q[j]);
    }
  }
  ArmDriverCore fresh = make_core();
  q[3] = fresh.limits().lower[3] - 0.02;
  fresh.on_measurement(kT0, q, 0.03);
  EXPECT_DOUBLE_EQ(fresh.update(kT0).q[3], fresh.limits().lower[3]);
}

TEST(ArmDriverCore, ExecutesATrajectoryToItsGoal) {
  ArmDriverCore d = make_core();
  d.on_measurement(kT0, home(), 0.06);
  Eigen::VectorXd goal = home();
  goal[0] += 0.4;
  goal[3] -= 0.3;
  ASSERT_EQ(d.command_trajectory(move(home(), goal, 2.0), 7), "");
  EXPECT_EQ(d.state(), DriverState::kExecuting);
  DriverSetpoint sp;
  for (int64_t t = kT0; t <= kT0 + 2500000; t += 10000) {
    if ((t - kT0) % 100000 == 0) d.heartbeat();
    sp = d.update(t);
    if (t == kT0 + 1000000) {
      // Halfway in time the s-curve is halfway in space.
      EXPECT_NEAR(sp.q[0], home()[0] + 0.2, 1e-9);
    }
  }
  EXPECT_EQ(d.state(), DriverState::kIdle);
  EXPECT_LT((sp.q - goal).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(sp.qd.norm(), 0.0);
  EXPECT_EQ(d.active_command_id(), 7);
}

TEST(ArmDriverCore, StopsWhenHeartbeatsStop) {
  ArmDriverCore d = make_core();
  d.on_measurement(kT0, home(), 0.06);
  Eigen::VectorXd goal = home();
  goal[0] += 0.8;
  ASSERT_EQ(d.command_trajectory(move(home(), goal, 4.0), 1), "");
  DriverSetpoint sp;
  for (int64_t t = kT0; t <= kT0 + 2000000; t += 10000) sp = d.update(t);
  EXPECT_EQ(d.state(), DriverState::kStopped);
  EXPECT_NE(d.message().find("heartbeat"), std::string::npos) << d.message();
  // Stopped just after 0.5 s of message time: far from the goal, at rest, holding.
  EXPECT_LT(sp.q[0], home()[0] + 0.1);
  EXPECT_EQ(sp.qd.norm(), 0.0);
  const DriverSetpoint later = d.update(kT0 + 3000000);
  EXPECT_EQ(later.q, sp.q);
}

// After a Cartesian motion is stopped the arm is still catching up with the setpoint: a trajectory
// planned from the measured state (ARM_STATE) starts at the current state and is accepted; one that
// starts near neither the measured state nor the setpoint is refused.
TEST(ArmDriverCore, ATrajectoryFromTheMeasuredStateIsAcceptedWhileTheArmCatchesUp) {
  ArmDriverCore d = make_core();
  d.on_measurement(kT0, home(), 0.06);
  Eigen::Matrix<double, 6, 1> tw;
  tw << 0.1, 0.0, 0.0, 0, 0, 0;
  ASSERT_EQ(d.command_cartesian_velocity(tw, "base", 3), "");
  const DriverSetpoint sp = stream_for_one_second(d);
  d.command_stop("servo finished");
  // The arm lags the setpoint by 0.04 rad on every joint that moved.
  Eigen::VectorXd lagging = sp.q;
  for (int j = 0; j < 7; ++j)
    if (std::abs(sp.q[j] - home()[j]) > 0.05) lagging[j] -= std::copysign(0.04, sp.q[j] - home()[j]);
  ASSERT_GT((lagging - sp.q).cwiseAbs().maxCoeff(), 0.035);
  d.on_measurement(kT0 + 1010000, lagging, 0.06);
  Eigen::VectorXd goal = lagging;
  goal[0] += 0.2;
  EXPECT_EQ(d.command_trajectory(move(lagging, goal, 2.0), 8), "");
  // Neither at the setpoint nor at the measured state: refused with the reason.
  Eigen::VectorXd off = lagging;
  off[6] += 0.05;
  const std::string why = d.command_trajectory(move(off, goal, 2.0), 9);
  EXPECT_NE(why.find("does not start at the current state"), std::string::npos) << why;
}

TEST(ArmDriverCore, StopsAtOnceOnStop) {
  ArmDriverCore d = make_core();
  d.on_measurement(kT0, home(), 0.06);
  Eigen::VectorXd goal = home();
  goal[1] += 0.5;
  ASSERT_EQ(d.command_trajectory(move(home(), goal, 2.0), 1), "");
  d.update(kT0 + 300000);
  d.heartbeat();
  const DriverSetpoint before = d.update(kT0 + 400000);
  d.command_stop("operator");
  EXPECT_EQ(d.state(), DriverState::kStopped);
  const DriverSetpoint after = d.update(kT0 + 410000);
  EXPECT_EQ(after.q, before.q) << "the setpoint freezes where it was";
  EXPECT_EQ(after.qd.norm(), 0.0);
}

TEST(ArmDriverCore, CartesianVelocityMovesTheGripperAsCommanded) {
  ArmDriverCore d = make_core();
  d.on_measurement(kT0, home(), 0.06);
  const Eigen::Vector3d p0 = d.kinematics().tip_pose(home()).translation();
  Eigen::Matrix<double, 6, 1> tw;
  tw << 0.02, -0.01, 0.0, 0, 0, 0;  // 2 cm/s forward, 1 cm/s to the right
  ASSERT_EQ(d.command_cartesian_velocity(tw, "base", 3), "");
  const DriverSetpoint sp = stream_for_one_second(d);
  const Eigen::Vector3d p1 = d.kinematics().tip_pose(sp.q).translation();
  EXPECT_NEAR(p1.x() - p0.x(), 0.02, 0.001);
  EXPECT_NEAR(p1.y() - p0.y(), -0.01, 0.001);
  EXPECT_NEAR(p1.z() - p0.z(), 0.0, 0.001);
  EXPECT_EQ(d.state(), DriverState::kExecuting);
}

// The null-space term moves the redundant joints towards the preferred posture without moving the TCP (forward
// kinematics of the streamed setpoint is the ground truth), and leaves a commanded twist followed.
TEST(ArmDriverCore, NullspacePullKeepsTheTcpAndApproachesThePreferredPosture) {
  Eigen::VectorXd start = home();
  start[0] = 0.4;  // the swivel (arm_1 / arm_3 / arm_5) away from the preferred posture
  start[2] = -0.5;
  start[4] = 0.5;
  ArmDriverCore d = make_core(0.5, home());
  d.on_measurement(kT0, start, 0.06);
  const Eigen::Isometry3d tip0 = d.kinematics().tip_pose(start);
  ASSERT_EQ(d.command_cartesian_velocity(Eigen::Matrix<double, 6, 1>::Zero(), "base", 1), "");
  DriverSetpoint sp;
  d.update(kT0);
  for (int64_t t = kT0 + 10000; t <= kT0 + 3000000; t += 10000) {
    d.heartbeat();
    sp = d.update(t);
  }
  const Eigen::Isometry3d tip1 = d.kinematics().tip_pose(sp.q);
  EXPECT_LT((tip1.translation() - tip0.translation()).norm(), 0.002) << "the TCP stays";
  EXPECT_LT(Eigen::AngleAxisd(tip0.linear().transpose() * tip1.linear()).angle(), 0.01);
  EXPECT_LT((sp.q - home()).norm(), 0.8 * (start - home()).norm()) << "the posture approaches the preferred one";
  EXPECT_EQ(d.state(), DriverState::kExecuting);

  // A twist is still followed (2 cm/s forward for 1 s) while the pull acts.
  ArmDriverCore e = make_core(0.5, home());
  e.on_measurement(kT0, start, 0.06);
  Eigen::Matrix<double, 6, 1> tw = Eigen::Matrix<double, 6, 1>::Zero();
  tw[0] = 0.02;
  ASSERT_EQ(e.command_cartesian_velocity(tw, "base", 2), "");
  e.update(kT0);
  for (int64_t t = kT0 + 10000; t <= kT0 + 1000000; t += 10000) {
    e.heartbeat();
    sp = e.update(t);
  }
  const Eigen::Vector3d dp = e.kinematics().tip_pose(sp.q).translation() - tip0.translation();
  EXPECT_NEAR(dp.x(), 0.02, 0.002);
  EXPECT_NEAR(dp.y(), 0.0, 0.002);
  EXPECT_NEAR(dp.z(), 0.0, 0.002);
}

// Runs a straight move of `twist` (base frame) for at most 4 s at 100 Hz; returns how far the TCP went
// before the driver stopped (or in 4 s) and the smallest distance of any joint to its limit on the way.
std::pair<double, double> straight_move_distance(ArmDriverCore& d, const Eigen::VectorXd& start,
                                                 const Eigen::Matrix<double, 6, 1>& twist) {
  d.on_measurement(kT0, start, 0.06);
  const Eigen::Vector3d p0 = d.kinematics().tip_pose(start).translation();
  EXPECT_EQ(d.command_cartesian_velocity(twist, "base", 1), "");
  d.update(kT0);
  DriverSetpoint sp;
  double closest = 1e9;
  for (int64_t t = kT0 + 10000; t <= kT0 + 4000000; t += 10000) {
    d.heartbeat();
    sp = d.update(t);
    if (d.state() != DriverState::kExecuting) break;
    for (int j = 0; j < 7; ++j)
      closest = std::min({closest, sp.q[j] - d.limits().lower[j], d.limits().upper[j] - sp.q[j]});
  }
  return {(d.kinematics().tip_pose(sp.q).translation() - p0).norm(), closest};
}

// far_cart seed 16 (stop 16): the retreat from the holder, 5 cm/s along base -y from this logged posture,
// drove arm_6 from -1.83 into its -1.97 limit after 9 cm of the 10 cm asked. The push away from the limits
// uses the redundant joint so the same move goes on well past 10 cm, the TCP still moving straight.
TEST(ArmDriverCore, NullspaceLimitPushKeepsAStraightMoveAwayFromAWristLimit) {
  Eigen::VectorXd start(7);
  start << 0.1500428311, 1.453928765, 0.1982606048, 0.8325352503, 1.533321834, -1.834285604, 2.035539293;
  Eigen::VectorXd preferred(7);
  preferred << 0.0, 0.6, 0.0, 1.5, 0.0, 0.6, 0.0;
  Eigen::Matrix<double, 6, 1> tw = Eigen::Matrix<double, 6, 1>::Zero();
  tw[1] = -0.05;

  ArmDriverCore pull_only = make_core(0.5, preferred);
  const auto [without, closest_without] = straight_move_distance(pull_only, start, tw);
  EXPECT_EQ(pull_only.state(), DriverState::kStopped) << "the case this test is about: it stops without the push";
  EXPECT_NE(pull_only.message().find("arm_6_joint"), std::string::npos) << pull_only.message();
  EXPECT_LT(without, 0.10);

  ArmDriverCore pushed = make_core(0.5, preferred, 0.4, 2.0);
  const Eigen::Isometry3d tip0 = pushed.kinematics().tip_pose(start);
  const auto [with, closest_with] = straight_move_distance(pushed, start, tw);
  EXPECT_GT(with, 0.14) << pushed.message();
  EXPECT_GE(closest_with, 0.0);
  // Straight: the TCP moved along -y only, orientation unchanged (checked at 10 cm along the way).
  ArmDriverCore again = make_core(0.5, preferred, 0.4, 2.0);
  again.on_measurement(kT0, start, 0.06);
  ASSERT_EQ(again.command_cartesian_velocity(tw, "base", 2), "");
  again.update(kT0);
  DriverSetpoint sp;
  for (int64_t t = kT0 + 10000; t <= kT0 + 2000000; t += 10000) {
    again.heartbeat();
    sp = again.update(t);
  }
  ASSERT_EQ(again.state(), DriverState::kExecuting) << again.message();
  const Eigen::Isometry3d tip1 = again.kinematics().tip_pose(sp.q);
  const Eigen::Vector3d dp = tip1.translation() - tip0.translation();
  EXPECT_NEAR(dp.y(), -0.10, 0.003);
  EXPECT_NEAR(dp.x(), 0.0, 0.003);
  EXPECT_NEAR(dp.z(), 0.0, 0.003);
  EXPECT_LT(Eigen::AngleAxisd(tip0.linear().transpose() * tip1.linear()).angle(), 0.01);
}

TEST(ArmDriverCore, BadCartesianAndGripperCommandsAreRefused) {
  ArmDriverCore d = make_core();
  d.on_measurement(kT0, home(), 0.06);
  Eigen::Matrix<double, 6, 1> tw = Eigen::Matrix<double, 6, 1>::Zero();
  tw[0] = 0.5;
  EXPECT_NE(d.command_cartesian_velocity(tw, "base", 1).find("linear speed 0.500 m/s > limit 0.150"),
            std::string::npos);
  tw.setZero();
  tw[5] = 2.0;
  EXPECT_NE(d.command_cartesian_velocity(tw, "base", 1).find("angular speed"), std::string::npos);
  tw[5] = NAN;
  EXPECT_NE(d.command_cartesian_velocity(tw, "base", 1).find("not finite"), std::string::npos);
  tw.setZero();
  EXPECT_NE(d.command_cartesian_velocity(tw, "camera", 1).find("twist_frame"), std::string::npos);
  EXPECT_EQ(d.state(), DriverState::kIdle) << "refused commands change nothing";
  EXPECT_NE(d.command_gripper(0.08, 10).find("outside"), std::string::npos);
  EXPECT_NE(d.command_gripper(NAN, 10).find("not finite"), std::string::npos);
  EXPECT_EQ(d.command_gripper(0.03, 0), "");
  EXPECT_DOUBLE_EQ(d.update(kT0 + 1000).gripper_width, 0.03);
}

TEST(ArmDriverCore, CartesianMotionStopsAtTheWorkspaceBoundary) {
  ArmDriverCore d = make_core();
  d.on_measurement(kT0, home(), 0.06);
  Eigen::Matrix<double, 6, 1> tw = Eigen::Matrix<double, 6, 1>::Zero();
  tw[2] = -0.15;  // straight down at full speed until the floor of the workspace
  ASSERT_EQ(d.command_cartesian_velocity(tw, "base", 1), "");
  for (int64_t t = kT0; t <= kT0 + 20000000 && d.state() == DriverState::kExecuting; t += 10000) {
    d.heartbeat();
    d.update(t);
  }
  EXPECT_EQ(d.state(), DriverState::kStopped);
  EXPECT_TRUE(d.message().find("workspace") != std::string::npos || d.message().find("limit") != std::string::npos)
      << d.message();
}

}  // namespace
}  // namespace bookgrasp

namespace bookgrasp {
namespace {

TEST(ArmDriverCore, RestartOfTheSourceStopsMotionAndHoldsTheNewPosition) {
  ArmDriverCore d = make_core();
  d.on_measurement(kT0, home(), 0.06);
  Eigen::VectorXd goal = home();
  goal[0] += 0.5;
  ASSERT_EQ(d.command_trajectory(move(home(), goal, 2.0), 1), "");
  d.heartbeat();
  d.update(kT0 + 500000);
  Eigen::VectorXd reset_pose(7);  // the simulation's folded start pose
  reset_pose << 0, -M_PI / 2, 0, -M_PI / 2, 0, -M_PI / 2, 0;
  d.restart(1000, reset_pose, 0.06);  // the simulation starts again at its epoch
  EXPECT_EQ(d.state(), DriverState::kStopped);
  EXPECT_NE(d.message().find("restarted"), std::string::npos);
  const DriverSetpoint sp = d.update(11000);
  EXPECT_EQ(sp.q, reset_pose) << "the setpoint is where the arm now is, not where the old world had it";
  EXPECT_EQ(sp.qd.norm(), 0.0);
  // Commands work again from the new position.
  Eigen::VectorXd g2 = reset_pose;
  g2[0] = 0.2;
  EXPECT_EQ(d.command_trajectory(move(reset_pose, g2, 1.0), 2), "");
}

}  // namespace
}  // namespace bookgrasp
