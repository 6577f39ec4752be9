#pragma once
/// @file
/// The robot as the rest of the system needs it, read once from the URDF:
/// links in tree order, joints with limits, collision primitives. No urdfdom
/// or KDL types appear here, so including this header is cheap.

#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace bookgrasp {

/// A collision primitive of a link (URDF <collision>), in the link frame.
struct CollisionShape {
  /// Primitive kinds; meshes are not supported (the URDF uses none).
  enum class Kind { kSphere, kBox, kCylinder };
  Kind kind = Kind::kSphere;
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();  ///< shape frame in the link frame
  Eigen::Vector3d box_size = Eigen::Vector3d::Zero();        ///< full box edge lengths (kBox)
  double radius = 0.0;                                       ///< kSphere, kCylinder
  double length = 0.0;                                       ///< kCylinder, along the shape's z
};

/// A joint of the tree, from its parent link to its child link.
struct RobotJoint {
  /// Joint kinds used by the robot; continuous/floating/planar are rejected at load.
  enum class Kind { kFixed, kRevolute, kPrismatic };
  std::string name;
  Kind kind = Kind::kFixed;
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();  ///< child frame at q = 0, in the parent link frame
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();           ///< unit axis in the joint frame
  double lower = 0.0;         ///< position limit (rad or m)
  double upper = 0.0;         ///< position limit (rad or m)
  double max_velocity = 0.0;  ///< URDF velocity limit (rad/s or m/s)
  std::string mimic_of;       ///< name of the joint this one mimics ("" = none)
  double mimic_multiplier = 1.0;
  double mimic_offset = 0.0;
};

/// A link: its parent joint (index into RobotModel::joints, -1 for the root),
/// its parent link, and its collision primitives.
struct RobotLink {
  std::string name;
  int parent_link = -1;   ///< index into RobotModel::links, -1 for the root
  int parent_joint = -1;  ///< index into RobotModel::joints, -1 for the root
  std::vector<CollisionShape> collision;
};

/// The robot read from a URDF. Links are in topological order (a parent comes
/// before its children), so forward kinematics is one pass over `links`.
struct RobotModel {
  std::string name;
  std::vector<RobotLink> links;
  std::vector<RobotJoint> joints;

  /// Loads a URDF file. Throws std::runtime_error naming the file and the
  /// problem (cannot parse, mesh geometry, unsupported joint type).
  static RobotModel load_urdf_file(const std::string& path);
  /// Parses URDF text; `source` names it in error messages.
  static RobotModel parse_urdf(const std::string& xml, const std::string& source = "<string>");

  /// Index of the link named `name`, or -1.
  int link_index(const std::string& name) const;
  /// Index of the joint named `name`, or -1.
  int joint_index(const std::string& name) const;
  /// Index of the link named `name`; throws std::runtime_error listing the links if absent.
  int require_link(const std::string& name) const;
  /// Links from `from` (exclusive) down to `to` (inclusive), root first.
  /// Throws std::runtime_error if `to` is not below `from`.
  std::vector<int> chain(const std::string& from, const std::string& to) const;
  /// The movable joints on the chain from `from` to `to`, root first (joint indices).
  std::vector<int> movable_joints(const std::string& from, const std::string& to) const;
};

}  // namespace bookgrasp
