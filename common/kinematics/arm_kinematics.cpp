#include "common/kinematics/arm_kinematics.h"

#include <cmath>
#include <stdexcept>

#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <kdl/frames.hpp>
#include <kdl/jacobian.hpp>
#include <kdl/jntarray.hpp>

namespace bookgrasp {

struct ArmKinematics::KdlChain {
  KDL::Chain chain;
};

namespace {

KDL::Frame to_kdl(const Eigen::Isometry3d& t) {
  const Eigen::Matrix3d& r = t.linear();
  return KDL::Frame(KDL::Rotation(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2)),
                    KDL::Vector(t.translation().x(), t.translation().y(), t.translation().z()));
}

Eigen::Isometry3d joint_motion(const RobotJoint& j, double value) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  if (j.kind == RobotJoint::Kind::kRevolute) {
    m.linear() = Eigen::AngleAxisd(value, j.axis).toRotationMatrix();
  } else if (j.kind == RobotJoint::Kind::kPrismatic) {
    m.translation() = value * j.axis;
  }
  return m;
}

}  // namespace

ArmKinematics::ArmKinematics(RobotModel model, const std::string& base_link, const std::string& tip_link)
    : model_(std::move(model)), base_name_(base_link) {
  base_link_ = model_.require_link(base_link);
  if (model_.links[base_link_].parent_link != -1)
    throw std::runtime_error("kinematics base link '" + base_link + "' must be the root of robot '" + model_.name + "'");
  tip_link_ = model_.require_link(tip_link);
  tip_chain_ = model_.chain(base_link, tip_link);
  arm_joints_ = model_.movable_joints(base_link, tip_link);
  joint_variable_.assign(model_.joints.size(), -1);
  const int n = static_cast<int>(arm_joints_.size());
  lower_.resize(n);
  upper_.resize(n);
  max_velocity_.resize(n);
  for (int k = 0; k < n; ++k) {
    const RobotJoint& j = model_.joints[arm_joints_[k]];
    joint_variable_[arm_joints_[k]] = k;
    joint_names_.push_back(j.name);
    lower_[k] = j.lower;
    upper_[k] = j.upper;
    max_velocity_[k] = j.max_velocity;
  }

  // KDL chain: one segment per link on the chain; fixed joints become Joint::None.
  auto kdl = std::make_shared<KdlChain>();
  for (int l : tip_chain_) {
    const RobotJoint& j = model_.joints[model_.links[l].parent_joint];
    const KDL::Frame origin = to_kdl(j.origin);
    const KDL::Vector axis(j.axis.x(), j.axis.y(), j.axis.z());
    KDL::Joint kj(j.name, KDL::Joint::None);
    if (j.kind == RobotJoint::Kind::kRevolute) kj = KDL::Joint(j.name, origin.p, origin.M * axis, KDL::Joint::RotAxis);
    if (j.kind == RobotJoint::Kind::kPrismatic) kj = KDL::Joint(j.name, origin.p, origin.M * axis, KDL::Joint::TransAxis);
    // Segment tip frame relative to the joint frame: the joint sits at `origin`, the child frame coincides with it.
    kdl->chain.addSegment(KDL::Segment(model_.links[l].name, kj, origin));
  }
  kdl_ = kdl;
}

ArmKinematics ArmKinematics::from_urdf_file(const std::string& urdf_path, const std::string& base_link,
                                            const std::string& tip_link) {
  return ArmKinematics(RobotModel::load_urdf_file(urdf_path), base_link, tip_link);
}

void ArmKinematics::check_size(const Eigen::VectorXd& q) const {
  if (q.size() != num_joints())
    throw std::invalid_argument("expected " + std::to_string(num_joints()) + " arm joint values, got " +
                                std::to_string(q.size()));
}

bool ArmKinematics::within_limits(const Eigen::VectorXd& q, double tolerance) const {
  if (q.size() != num_joints()) return false;
  for (int k = 0; k < q.size(); ++k) {
    if (!std::isfinite(q[k]) || q[k] < lower_[k] - tolerance || q[k] > upper_[k] + tolerance) return false;
  }
  return true;
}

void ArmKinematics::link_poses(const Eigen::VectorXd& q, double finger_position,
                               std::vector<Eigen::Isometry3d>& out) const {
  check_size(q);
  out.resize(model_.links.size());
  for (size_t l = 0; l < model_.links.size(); ++l) {
    const RobotLink& link = model_.links[l];
    if (link.parent_link < 0) {
      out[l] = Eigen::Isometry3d::Identity();
      continue;
    }
    const RobotJoint& j = model_.joints[link.parent_joint];
    double value = 0.0;
    const int var = joint_variable_[link.parent_joint];
    if (var >= 0) {
      value = q[var];
    } else if (j.kind != RobotJoint::Kind::kFixed) {
      value = j.mimic_of.empty() ? finger_position : j.mimic_multiplier * finger_position + j.mimic_offset;
    }
    out[l] = out[link.parent_link] * j.origin * joint_motion(j, value);
  }
}

std::vector<Eigen::Isometry3d> ArmKinematics::link_poses(const Eigen::VectorXd& q, double finger_position) const {
  std::vector<Eigen::Isometry3d> out;
  link_poses(q, finger_position, out);
  return out;
}

Eigen::Isometry3d ArmKinematics::tip_pose(const Eigen::VectorXd& q) const {
  check_size(q);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  for (int l : tip_chain_) {
    const int ji = model_.links[l].parent_joint;
    const int var = joint_variable_[ji];
    t = t * model_.joints[ji].origin * joint_motion(model_.joints[ji], var >= 0 ? q[var] : 0.0);
  }
  return t;
}

Eigen::Isometry3d ArmKinematics::frame_pose(const Eigen::VectorXd& q, const std::string& link) const {
  const int index = model_.require_link(link);
  return link_poses(q)[index];
}

void ArmKinematics::tip_pose_and_jacobian(const Eigen::VectorXd& q, Eigen::Isometry3d& tip, Jacobian& jac) const {
  check_size(q);
  const int n = num_joints();
  jac.resize(6, n);
  Eigen::Matrix<double, 3, Eigen::Dynamic> axes(3, n), origins(3, n);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  for (int l : tip_chain_) {
    const int ji = model_.links[l].parent_joint;
    const RobotJoint& j = model_.joints[ji];
    const int var = joint_variable_[ji];
    t = t * j.origin;
    if (var >= 0) {
      axes.col(var) = t.linear() * j.axis;
      origins.col(var) = t.translation();
      t = t * joint_motion(j, q[var]);
    }
  }
  tip = t;
  for (int k = 0; k < n; ++k) {
    const RobotJoint& j = model_.joints[arm_joints_[k]];
    const Eigen::Vector3d a = axes.col(k);
    if (j.kind == RobotJoint::Kind::kRevolute) {
      jac.col(k).head<3>() = a.cross(t.translation() - origins.col(k));
      jac.col(k).tail<3>() = a;
    } else {
      jac.col(k).head<3>() = a;
      jac.col(k).tail<3>().setZero();
    }
  }
}

Jacobian ArmKinematics::jacobian(const Eigen::VectorXd& q) const {
  check_size(q);
  KDL::JntArray jq(static_cast<unsigned>(num_joints()));
  for (int k = 0; k < num_joints(); ++k) jq(k) = q[k];
  KDL::Jacobian kj(static_cast<unsigned>(num_joints()));
  KDL::ChainJntToJacSolver solver(kdl_->chain);
  if (solver.JntToJac(jq, kj) < 0) throw std::runtime_error("KDL Jacobian solver failed");
  Jacobian out(6, num_joints());
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < num_joints(); ++c) out(r, c) = kj(r, c);
  return out;
}

Eigen::Isometry3d ArmKinematics::tip_pose_kdl(const Eigen::VectorXd& q) const {
  check_size(q);
  KDL::JntArray jq(static_cast<unsigned>(num_joints()));
  for (int k = 0; k < num_joints(); ++k) jq(k) = q[k];
  KDL::ChainFkSolverPos_recursive solver(kdl_->chain);
  KDL::Frame f;
  if (solver.JntToCart(jq, f) < 0) throw std::runtime_error("KDL forward kinematics failed");
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    t.translation()[r] = f.p(r);
    for (int c = 0; c < 3; ++c) t.linear()(r, c) = f.M(r, c);
  }
  return t;
}

Eigen::Vector3d orientation_error(const Eigen::Matrix3d& current, const Eigen::Matrix3d& target) {
  const Eigen::AngleAxisd aa(target * current.transpose());
  return aa.angle() * aa.axis();
}

}  // namespace bookgrasp
