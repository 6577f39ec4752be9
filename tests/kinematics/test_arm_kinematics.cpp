// ArmKinematics against poses computed by hand from the URDF's joint origins
// (see the comments: each expected value is derived from the URDF numbers,
// not from the code), plus the two Jacobians against finite differences.
#include "common/kinematics/arm_kinematics.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace bookgrasp {
namespace {

const std::string kUrdf = std::string(BOOKGRASP_SOURCE_DIR) + "/config/robot/lwa3_pg70.urdf";
constexpr double kPi = 3.14159265358979323846;
// Link lengths written in the URDF.
constexpr double kShoulder = 0.25, kUpper = 0.408, kFore = 0.3165, kWrist = 0.1927, kTcp = 0.1089;
constexpr double kReach = kUpper + kFore + kWrist + kTcp;  // shoulder to TCP when straight

ArmKinematics arm() { return ArmKinematics::from_urdf_file(kUrdf, "base", "gripper"); }

Eigen::VectorXd joints(std::initializer_list<double> v) {
  Eigen::VectorXd q(v.size());
  int i = 0;
  for (double x : v) q[i++] = x;
  return q;
}

void expect_pose(const Eigen::Isometry3d& t, const Eigen::Vector3d& p, const Eigen::Matrix3d& r, double tol = 1e-9) {
  EXPECT_NEAR((t.translation() - p).norm(), 0.0, tol) << "position " << t.translation().transpose() << " expected "
                                                      << p.transpose();
  EXPECT_NEAR((t.linear() - r).norm(), 0.0, 1e-8) << "rotation\n" << t.linear() << "\nexpected\n" << r;
}

Eigen::Matrix3d rot_y(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix(); }
Eigen::Matrix3d rot_z(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix(); }

TEST(ArmKinematics, SevenJointsNamedAndLimitedAsInTheUrdf) {
  const ArmKinematics k = arm();
  ASSERT_EQ(k.num_joints(), 7);
  EXPECT_EQ(k.joint_names()[0], "arm_1_joint");
  EXPECT_EQ(k.joint_names()[6], "arm_7_joint");
  EXPECT_DOUBLE_EQ(k.upper_limits()[1], 1.97);
  EXPECT_DOUBLE_EQ(k.lower_limits()[0], -3.1415);
  EXPECT_TRUE(k.within_limits(Eigen::VectorXd::Zero(7)));
  EXPECT_FALSE(k.within_limits(joints({0, 2.0, 0, 0, 0, 0, 0})));
  EXPECT_FALSE(k.within_limits(joints({0, NAN, 0, 0, 0, 0, 0})));
  EXPECT_FALSE(k.within_limits(Eigen::VectorXd::Zero(6)));
}

// All zeros: the chain's rotations are Rx(pi) Rx(pi/2) Rx(-pi/2) ... Rx(pi) = identity and every
// offset is along the arm: the TCP is straight up, gripper axes = base axes.
TEST(ArmKinematics, AllZerosPointsStraightUp) {
  const ArmKinematics k = arm();
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(7);
  expect_pose(k.tip_pose(q), {0, 0, kShoulder + kReach}, Eigen::Matrix3d::Identity());
  expect_pose(k.tip_pose_kdl(q), {0, 0, 1.2761}, Eigen::Matrix3d::Identity());
  expect_pose(k.frame_pose(q, "flange"), {0, 0, 1.2761 - kTcp}, Eigen::Matrix3d::Identity());
  // Hand camera: flange + (0.06, 0, 0.06), rotated Rz(pi/2).
  expect_pose(k.frame_pose(q, "hand_camera"), {0.06, 0, 1.2761 - kTcp + 0.06}, rot_z(kPi / 2));
  // Elbow (arm_4_link origin) at shoulder + upper arm.
  EXPECT_NEAR(k.frame_pose(q, "arm_4_link").translation().z(), kShoulder + kUpper, 1e-9);
}

// Joint 2's frame is Rx(pi) Rx(pi/2) = Rx(-pi/2) in base, so its z axis is base +y:
// +pi/2 tips the straight arm forward onto base +x at shoulder height.
TEST(ArmKinematics, Joint2QuarterTurnPointsTheArmForward) {
  const ArmKinematics k = arm();
  const Eigen::VectorXd q = joints({0, kPi / 2, 0, 0, 0, 0, 0});
  expect_pose(k.tip_pose(q), {kReach, 0, kShoulder}, rot_y(kPi / 2));
  expect_pose(k.tip_pose_kdl(q), {kReach, 0, kShoulder}, rot_y(kPi / 2));
}

// Joint 1's axis is base -z (arm_1 frame is Rx(pi)): +pi/2 then turns the forward arm to base -y.
TEST(ArmKinematics, Joint1TurnsAboutMinusZ) {
  const ArmKinematics k = arm();
  const Eigen::VectorXd q = joints({kPi / 2, kPi / 2, 0, 0, 0, 0, 0});
  expect_pose(k.tip_pose(q), {0, -kReach, kShoulder}, rot_z(-kPi / 2) * rot_y(kPi / 2));
}

// Joint 4 (elbow) axis is base +y at zero: the forearm tips forward at elbow height.
TEST(ArmKinematics, Joint4BendsTheForearm) {
  const ArmKinematics k = arm();
  const double fore = kFore + kWrist + kTcp;
  expect_pose(k.tip_pose(joints({0, 0, 0, kPi / 2, 0, 0, 0})), {fore, 0, kShoulder + kUpper}, rot_y(kPi / 2));
  // Shoulder forward, elbow back: upper arm horizontal, forearm vertical again.
  expect_pose(k.tip_pose(joints({0, kPi / 2, 0, -kPi / 2, 0, 0, 0})), {kUpper, 0, kShoulder + fore},
              Eigen::Matrix3d::Identity());
}

// Joint 6 (wrist pitch) axis is base +y; joint 7's axis is base -z (arm_7 frame Rx(pi)).
TEST(ArmKinematics, WristJoints) {
  const ArmKinematics k = arm();
  const double wrist_z = kShoulder + kUpper + kFore;
  expect_pose(k.tip_pose(joints({0, 0, 0, 0, 0, kPi / 2, 0})), {kWrist + kTcp, 0, wrist_z}, rot_y(kPi / 2));
  expect_pose(k.tip_pose(joints({0, 0, 0, 0, 0, 0, kPi / 2})), {0, 0, 1.2761}, rot_z(-kPi / 2));
  // Joints 3 and 5 (frames Rx(pi): axes base -z, along the straight arm) only spin it about its own
  // axis: the TCP stays on the vertical line.
  const Eigen::Isometry3d t = k.tip_pose(joints({0, 0, 0.7, 0, -0.4, 0, 0}));
  EXPECT_NEAR(t.translation().head<2>().norm(), 0.0, 1e-9);
  EXPECT_NEAR(t.translation().z(), 1.2761, 1e-9);
}

TEST(ArmKinematics, FingersFollowTheFingerValueWithMimic) {
  const ArmKinematics k = arm();
  const auto poses = k.link_poses(Eigen::VectorXd::Zero(7), 0.02);
  const Eigen::Vector3d left = poses[k.model().require_link("gripper_finger_left")].translation();
  const Eigen::Vector3d right = poses[k.model().require_link("gripper_finger_right")].translation();
  // Palm at the flange (z = 1.1672), fingers 0.0789 further, travelling +-y.
  EXPECT_NEAR((left - Eigen::Vector3d(0, 0.02, 1.1672 + 0.0789)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((right - Eigen::Vector3d(0, -0.02, 1.1672 + 0.0789)).norm(), 0.0, 1e-9);
}

TEST(ArmKinematics, AllFkRoutesAgreeOnRandomPostures) {
  const ArmKinematics k = arm();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < 100; ++i) {
    Eigen::VectorXd q(7);
    for (int j = 0; j < 7; ++j) q[j] = k.lower_limits()[j] + u(rng) * (k.upper_limits()[j] - k.lower_limits()[j]);
    const Eigen::Isometry3d a = k.tip_pose(q), b = k.tip_pose_kdl(q), c = k.link_poses(q)[k.tip_link()];
    EXPECT_TRUE(a.isApprox(b, 1e-9));
    EXPECT_TRUE(a.isApprox(c, 1e-9));
  }
}

TEST(ArmKinematics, JacobiansMatchFiniteDifferences) {
  const ArmKinematics k = arm();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  for (int i = 0; i < 20; ++i) {
    Eigen::VectorXd q(7);
    for (int j = 0; j < 7; ++j) q[j] = u(rng);
    Eigen::Isometry3d tip;
    Jacobian fast(6, 7);
    k.tip_pose_and_jacobian(q, tip, fast);
    const Jacobian kdl = k.jacobian(q);
    Jacobian numeric(6, 7);
    const double h = 1e-6;
    for (int j = 0; j < 7; ++j) {
      Eigen::VectorXd qp = q, qm = q;
      qp[j] += h;
      qm[j] -= h;
      const Eigen::Isometry3d tp = k.tip_pose(qp), tm = k.tip_pose(qm);
      numeric.col(j).head<3>() = (tp.translation() - tm.translation()) / (2 * h);
      numeric.col(j).tail<3>() = orientation_error(tm.linear(), tp.linear()) / (2 * h);
    }
    EXPECT_LT((fast - numeric).cwiseAbs().maxCoeff(), 1e-6);
    EXPECT_LT((kdl - numeric).cwiseAbs().maxCoeff(), 1e-6);
  }
}

TEST(ArmKinematics, WrongJointCountThrows) {
  const ArmKinematics k = arm();
  EXPECT_THROW(k.tip_pose(Eigen::VectorXd::Zero(6)), std::invalid_argument);
  EXPECT_THROW(k.jacobian(Eigen::VectorXd::Zero(8)), std::invalid_argument);
  EXPECT_THROW(k.frame_pose(Eigen::VectorXd::Zero(7), "nope"), std::runtime_error);
  EXPECT_THROW(ArmKinematics(k.model(), "base", "nope"), std::runtime_error);
}

}  // namespace
}  // namespace bookgrasp
