// RobotModel: the URDF read into links, joints and collision primitives.
#include "common/kinematics/robot_model.h"

#include <gtest/gtest.h>

namespace bookgrasp {
namespace {

const std::string kUrdf = std::string(BOOKGRASP_SOURCE_DIR) + "/config/robot/lwa3_pg70.urdf";

TEST(RobotModel, LoadsTheArmWithLimitsFromTheUrdfText) {
  const RobotModel m = RobotModel::load_urdf_file(kUrdf);
  EXPECT_EQ(m.name, "lwa3_pg70");
  ASSERT_EQ(m.links.front().name, "base");
  // Values as written in the URDF file.
  const RobotJoint& j2 = m.joints[m.joint_index("arm_2_joint")];
  EXPECT_EQ(j2.kind, RobotJoint::Kind::kRevolute);
  EXPECT_DOUBLE_EQ(j2.lower, -1.97);
  EXPECT_DOUBLE_EQ(j2.upper, 1.97);
  EXPECT_DOUBLE_EQ(j2.max_velocity, 2.0);
  const RobotJoint& right = m.joints[m.joint_index("gripper_finger_right_joint")];
  EXPECT_EQ(right.kind, RobotJoint::Kind::kPrismatic);
  EXPECT_EQ(right.mimic_of, "gripper_finger_left_joint");
  EXPECT_EQ(m.joints[m.joint_index("flange_joint")].kind, RobotJoint::Kind::kFixed);
}

TEST(RobotModel, LinksAreInTopologicalOrder) {
  const RobotModel m = RobotModel::load_urdf_file(kUrdf);
  for (size_t i = 1; i < m.links.size(); ++i) EXPECT_LT(m.links[i].parent_link, static_cast<int>(i));
}

TEST(RobotModel, CollisionPrimitivesAsInTheUrdf) {
  const RobotModel m = RobotModel::load_urdf_file(kUrdf);
  const RobotLink& a2 = m.links[m.require_link("arm_2_link")];
  ASSERT_EQ(a2.collision.size(), 1u);
  EXPECT_EQ(a2.collision[0].kind, CollisionShape::Kind::kCylinder);
  EXPECT_DOUBLE_EQ(a2.collision[0].radius, 0.06);
  EXPECT_DOUBLE_EQ(a2.collision[0].length, 0.30);
  EXPECT_NEAR(a2.collision[0].origin.translation().y(), -0.204, 1e-12);
  const RobotLink& a3 = m.links[m.require_link("arm_3_link")];
  EXPECT_EQ(a3.collision[0].kind, CollisionShape::Kind::kSphere);
  EXPECT_DOUBLE_EQ(a3.collision[0].radius, 0.065);
  const RobotLink& palm = m.links[m.require_link("gripper_palm")];
  EXPECT_EQ(palm.collision[0].kind, CollisionShape::Kind::kBox);
  EXPECT_TRUE(palm.collision[0].box_size.isApprox(Eigen::Vector3d(0.082, 0.114, 0.078)));
  EXPECT_TRUE(m.links[m.require_link("flange")].collision.empty());
}

TEST(RobotModel, ChainFromBaseToGripperHasSevenMovableJoints) {
  const RobotModel m = RobotModel::load_urdf_file(kUrdf);
  const std::vector<int> joints = m.movable_joints("base", "gripper");
  ASSERT_EQ(joints.size(), 7u);
  for (int k = 0; k < 7; ++k) EXPECT_EQ(m.joints[joints[k]].name, "arm_" + std::to_string(k + 1) + "_joint");
}

TEST(RobotModel, ErrorsNameTheProblem) {
  EXPECT_THROW(RobotModel::load_urdf_file("/nonexistent/robot.urdf"), std::runtime_error);
  EXPECT_THROW(RobotModel::parse_urdf("<robot name='x'><link name='a'/><oops"), std::runtime_error);
  const RobotModel m = RobotModel::load_urdf_file(kUrdf);
  try {
    m.require_link("no_such_link");
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_link"), std::string::npos);
  }
  EXPECT_THROW(m.chain("gripper", "base"), std::runtime_error);
}

}  // namespace
}  // namespace bookgrasp
