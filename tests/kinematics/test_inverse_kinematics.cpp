// InverseKinematics: round trips FK(IK(p)) = p over random reachable poses
// (made by FK of random joint values), limits, redundancy use, failures.
#include "common/kinematics/inverse_kinematics.h"

#include <random>

#include <gtest/gtest.h>

namespace bookgrasp {
namespace {

const std::string kUrdf = std::string(BOOKGRASP_SOURCE_DIR) + "/config/robot/lwa3_pg70.urdf";

IkParams params() {
  IkParams p;
  p.max_iterations = 150;
  p.max_restarts = 10;
  p.position_tolerance_m = 1e-4;
  p.orientation_tolerance_rad = 1e-3;
  p.damping = 0.05;
  p.max_step_rad = 0.3;
  p.nullspace_gain = 0.1;
  p.orientation_weight_m = 0.2;
  p.posture_iterations = 50;
  p.preferred_posture = (Eigen::VectorXd(7) << 0, 0.6, 0, 1.4, 0, 0.6, 0).finished();
  p.seed = 3;
  return p;
}

Eigen::VectorXd random_q(const ArmKinematics& k, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  Eigen::VectorXd q(7);
  for (int j = 0; j < 7; ++j) q[j] = k.lower_limits()[j] + u(rng) * (k.upper_limits()[j] - k.lower_limits()[j]);
  return q;
}

TEST(InverseKinematics, RoundTripOverRandomReachablePoses) {
  const ArmKinematics k = ArmKinematics::from_urdf_file(kUrdf, "base", "gripper");
  const InverseKinematics ik(k, params());
  std::mt19937 rng(2024);
  const int n = 300;
  int solved = 0;
  for (int i = 0; i < n; ++i) {
    const Eigen::VectorXd truth = random_q(k, rng);
    const Eigen::Isometry3d target = k.tip_pose(truth);
    const IkResult r = ik.solve(target, params().preferred_posture);
    ASSERT_EQ(r.q.size(), 7);
    EXPECT_TRUE(k.within_limits(r.q)) << "IK left the joint limits: " << r.q.transpose();
    if (!r.success) continue;
    ++solved;
    const Eigen::Isometry3d got = k.tip_pose(r.q);
    EXPECT_LT((got.translation() - target.translation()).norm(), 1e-4);
    EXPECT_LT(Eigen::AngleAxisd(got.linear().transpose() * target.linear()).angle(), 1e-3);
  }
  // Every pose is reachable by construction; the restarts must find (almost) all.
  EXPECT_GE(solved, n - 1) << "solved " << solved << " of " << n;
}

TEST(InverseKinematics, NullSpaceKeepsSolutionsNearThePreferredPosture) {
  const ArmKinematics k = ArmKinematics::from_urdf_file(kUrdf, "base", "gripper");
  IkParams with = params(), without = params();
  without.nullspace_gain = 0.0;
  const InverseKinematics ik_with(k, with), ik_without(k, without);
  std::mt19937 rng(99);
  double dist_with = 0, dist_without = 0;
  int count = 0;
  for (int i = 0; i < 60; ++i) {
    // Targets near the preferred posture's workspace: perturb it.
    Eigen::VectorXd truth = with.preferred_posture;
    std::normal_distribution<double> g(0, 0.4);
    for (int j = 0; j < 7; ++j) truth[j] += g(rng);
    truth = truth.cwiseMax(k.lower_limits()).cwiseMin(k.upper_limits());
    const Eigen::Isometry3d target = k.tip_pose(truth);
    // Seed beside the solution, on the far side from the preferred posture, so the posture term has work to do.
    const Eigen::VectorXd seed = (truth + 0.5 * (truth - with.preferred_posture))
                                     .cwiseMax(k.lower_limits()).cwiseMin(k.upper_limits());
    const IkResult a = ik_with.solve_once(target, seed, 300), b = ik_without.solve_once(target, seed, 300);
    if (!a.success || !b.success) continue;
    dist_with += (a.q - with.preferred_posture).norm();
    dist_without += (b.q - with.preferred_posture).norm();
    ++count;
  }
  ASSERT_GT(count, 20);
  EXPECT_LT(dist_with, 0.9 * dist_without) << "mean distance with " << dist_with / count << " without "
                                           << dist_without / count;
}

TEST(InverseKinematics, UnreachablePoseFailsWithAReason) {
  const ArmKinematics k = ArmKinematics::from_urdf_file(kUrdf, "base", "gripper");
  const InverseKinematics ik(k, params());
  Eigen::Isometry3d far = Eigen::Isometry3d::Identity();
  far.translation() = Eigen::Vector3d(2.0, 0, 0.25);
  const IkResult r = ik.solve(far, params().preferred_posture);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.reason.find("no IK solution"), std::string::npos) << r.reason;
  EXPECT_TRUE(k.within_limits(r.q));
  Eigen::Isometry3d bad = Eigen::Isometry3d::Identity();
  bad.translation().x() = NAN;
  EXPECT_FALSE(ik.solve(bad, params().preferred_posture).success);
  EXPECT_FALSE(ik.solve(far, Eigen::VectorXd::Zero(3)).success);
}

TEST(InverseKinematics, DeterministicForTheSameSeed) {
  const ArmKinematics k = ArmKinematics::from_urdf_file(kUrdf, "base", "gripper");
  const InverseKinematics ik(k, params());
  std::mt19937 rng(5);
  for (int i = 0; i < 10; ++i) {
    const Eigen::Isometry3d target = k.tip_pose(random_q(k, rng));
    const Eigen::VectorXd seed = random_q(k, rng);
    const IkResult a = ik.solve(target, seed), b = ik.solve(target, seed);
    EXPECT_EQ(a.success, b.success);
    EXPECT_TRUE(a.q == b.q);
  }
}

TEST(InverseKinematics, RejectsInconsistentParameters) {
  const ArmKinematics k = ArmKinematics::from_urdf_file(kUrdf, "base", "gripper");
  IkParams p = params();
  p.preferred_posture = Eigen::VectorXd::Zero(6);
  EXPECT_THROW(InverseKinematics(k, p), std::invalid_argument);
  p = params();
  p.preferred_posture[1] = 3.0;
  EXPECT_THROW(InverseKinematics(k, p), std::invalid_argument);
  p = params();
  p.damping = 0;
  EXPECT_THROW(InverseKinematics(k, p), std::invalid_argument);
}

}  // namespace
}  // namespace bookgrasp
