#pragma once
/// @file
/// Forward kinematics of every link, the tip (TCP) pose and the Jacobian of
/// the arm chain base -> tip, built from a RobotModel (URDF). KDL stays inside
/// the .cpp; this header only needs Eigen.

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/kinematics/robot_model.h"

namespace bookgrasp {

/// 6 x n Jacobian: rows vx, vy, vz, wx, wy, wz (base frame, reference point at the tip origin).
using Jacobian = Eigen::Matrix<double, 6, Eigen::Dynamic>;

/// Kinematics of the serial arm from `base_link` to `tip_link` of a robot.
///
/// Arm joint values (`q`) are the movable joints of that chain, root first
/// (for the LWA3: arm_1_joint .. arm_7_joint, radians). Movable joints off the
/// chain (the gripper fingers) take one shared value `finger_position`
/// (metres, the URDF finger joint value), with <mimic> applied.
/// Immutable after construction; copies share the KDL chain; const methods are thread-safe.
class ArmKinematics {
 public:
  /// Builds the kinematics of `model` for the chain base_link -> tip_link.
  /// Throws std::runtime_error naming the missing link or an unsupported joint.
  ArmKinematics(RobotModel model, const std::string& base_link, const std::string& tip_link);
  /// Loads the URDF at `urdf_path` and builds the chain base_link -> tip_link.
  static ArmKinematics from_urdf_file(const std::string& urdf_path, const std::string& base_link,
                                      const std::string& tip_link);

  /// The robot description.
  const RobotModel& model() const { return model_; }
  /// Number of arm joints (7 for the LWA3).
  int num_joints() const { return static_cast<int>(arm_joints_.size()); }
  /// Names of the arm joints, root first.
  const std::vector<std::string>& joint_names() const { return joint_names_; }
  /// Lower position limits of the arm joints.
  const Eigen::VectorXd& lower_limits() const { return lower_; }
  /// Upper position limits of the arm joints.
  const Eigen::VectorXd& upper_limits() const { return upper_; }
  /// URDF velocity limits of the arm joints.
  const Eigen::VectorXd& velocity_limits() const { return max_velocity_; }
  /// True if q has num_joints() finite values within the limits (plus `tolerance`).
  bool within_limits(const Eigen::VectorXd& q, double tolerance = 0.0) const;
  /// Index of the tip link.
  int tip_link() const { return tip_link_; }
  /// Name of the base link.
  const std::string& base_link_name() const { return base_name_; }

  /// Pose of every link (RobotModel::links order) in the base link's frame.
  /// Requires q.size() == num_joints() (throws std::invalid_argument otherwise).
  std::vector<Eigen::Isometry3d> link_poses(const Eigen::VectorXd& q, double finger_position = 0.0) const;
  /// Same as link_poses, writing into `out` (resized) to avoid allocation in loops.
  void link_poses(const Eigen::VectorXd& q, double finger_position, std::vector<Eigen::Isometry3d>& out) const;
  /// Pose of the tip link (TCP) in the base frame.
  Eigen::Isometry3d tip_pose(const Eigen::VectorXd& q) const;
  /// Pose of any link in the base frame (e.g. "hand_camera", "flange"). Throws for an unknown link.
  Eigen::Isometry3d frame_pose(const Eigen::VectorXd& q, const std::string& link) const;

  /// Tip pose and geometric Jacobian in one pass (Eigen, no allocation beyond `jacobian`).
  void tip_pose_and_jacobian(const Eigen::VectorXd& q, Eigen::Isometry3d& tip, Jacobian& jacobian) const;
  /// Geometric Jacobian at the tip computed by KDL (ChainJntToJacSolver) on the
  /// chain built from the URDF; an independent implementation of the one above.
  Jacobian jacobian(const Eigen::VectorXd& q) const;
  /// Tip pose computed by KDL (ChainFkSolverPos_recursive).
  Eigen::Isometry3d tip_pose_kdl(const Eigen::VectorXd& q) const;

 private:
  struct KdlChain;
  void check_size(const Eigen::VectorXd& q) const;

  RobotModel model_;
  std::string base_name_;
  int base_link_ = 0;
  int tip_link_ = 0;
  std::vector<int> arm_joints_;         // joint indices
  std::vector<int> joint_variable_;     // per joint: arm variable index, -1 = not an arm joint
  std::vector<int> tip_chain_;          // links base (excl.) -> tip (incl.)
  std::vector<std::string> joint_names_;
  Eigen::VectorXd lower_, upper_, max_velocity_;
  std::shared_ptr<const KdlChain> kdl_;
};

/// Rotation error as an axis-angle vector: the rotation that takes `current` to `target`, in the base frame.
Eigen::Vector3d orientation_error(const Eigen::Matrix3d& current, const Eigen::Matrix3d& target);

}  // namespace bookgrasp
