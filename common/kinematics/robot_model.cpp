#include "common/kinematics/robot_model.h"

#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>

#include <urdf_parser/urdf_parser.h>

namespace bookgrasp {
namespace {

Eigen::Isometry3d to_isometry(const urdf::Pose& p) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  t.linear() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z).normalized()
                   .toRotationMatrix();
  return t;
}

CollisionShape to_shape(const urdf::Collision& c, const std::string& link, const std::string& source) {
  CollisionShape s;
  s.origin = to_isometry(c.origin);
  if (!c.geometry) throw std::runtime_error(source + ": link '" + link + "' has a <collision> without geometry");
  switch (c.geometry->type) {
    case urdf::Geometry::SPHERE:
      s.kind = CollisionShape::Kind::kSphere;
      s.radius = static_cast<const urdf::Sphere&>(*c.geometry).radius;
      break;
    case urdf::Geometry::BOX: {
      const auto& b = static_cast<const urdf::Box&>(*c.geometry);
      s.kind = CollisionShape::Kind::kBox;
      s.box_size = Eigen::Vector3d(b.dim.x, b.dim.y, b.dim.z);
      break;
    }
    case urdf::Geometry::CYLINDER: {
      const auto& cy = static_cast<const urdf::Cylinder&>(*c.geometry);
      s.kind = CollisionShape::Kind::kCylinder;
      s.radius = cy.radius;
      s.length = cy.length;
      break;
    }
    default:
      throw std::runtime_error(source + ": link '" + link +
                               "' uses a mesh collision geometry; use cylinders, spheres or boxes");
  }
  return s;
}

}  // namespace

RobotModel RobotModel::load_urdf_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read the robot description '" + path + "' (check the path)");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_urdf(ss.str(), path);
}

RobotModel RobotModel::parse_urdf(const std::string& xml, const std::string& source) {
  const urdf::ModelInterfaceSharedPtr urdf_model = urdf::parseURDF(xml);
  if (!urdf_model) throw std::runtime_error(source + ": not a valid URDF (urdfdom could not parse it)");
  const urdf::LinkConstSharedPtr root = urdf_model->getRoot();
  if (!root) throw std::runtime_error(source + ": URDF has no root link");

  RobotModel model;
  model.name = urdf_model->getName();
  std::function<void(const urdf::LinkConstSharedPtr&, int, int)> visit =
      [&](const urdf::LinkConstSharedPtr& link, int parent_link, int parent_joint) {
        RobotLink l;
        l.name = link->name;
        l.parent_link = parent_link;
        l.parent_joint = parent_joint;
        for (const auto& c : link->collision_array) {
          if (c) l.collision.push_back(to_shape(*c, link->name, source));
        }
        if (l.collision.empty() && link->collision) l.collision.push_back(to_shape(*link->collision, link->name, source));
        model.links.push_back(l);
        const int self = static_cast<int>(model.links.size()) - 1;
        for (const auto& child : link->child_links) {
          const urdf::JointSharedPtr& uj = child->parent_joint;
          RobotJoint j;
          j.name = uj->name;
          j.origin = to_isometry(uj->parent_to_joint_origin_transform);
          j.axis = Eigen::Vector3d(uj->axis.x, uj->axis.y, uj->axis.z);
          switch (uj->type) {
            case urdf::Joint::FIXED: j.kind = RobotJoint::Kind::kFixed; break;
            case urdf::Joint::REVOLUTE: j.kind = RobotJoint::Kind::kRevolute; break;
            case urdf::Joint::PRISMATIC: j.kind = RobotJoint::Kind::kPrismatic; break;
            default:
              throw std::runtime_error(source + ": joint '" + uj->name +
                                       "' has an unsupported type (only fixed, revolute, prismatic)");
          }
          if (j.kind != RobotJoint::Kind::kFixed) {
            if (j.axis.norm() < 1e-9) throw std::runtime_error(source + ": joint '" + uj->name + "' has a zero axis");
            j.axis.normalize();
            if (!uj->limits) throw std::runtime_error(source + ": joint '" + uj->name + "' has no <limit>");
            j.lower = uj->limits->lower;
            j.upper = uj->limits->upper;
            j.max_velocity = uj->limits->velocity;
          }
          if (uj->mimic) {
            j.mimic_of = uj->mimic->joint_name;
            j.mimic_multiplier = uj->mimic->multiplier;
            j.mimic_offset = uj->mimic->offset;
          }
          model.joints.push_back(j);
          visit(child, self, static_cast<int>(model.joints.size()) - 1);
        }
      };
  visit(root, -1, -1);
  return model;
}

int RobotModel::link_index(const std::string& n) const {
  for (size_t i = 0; i < links.size(); ++i)
    if (links[i].name == n) return static_cast<int>(i);
  return -1;
}

int RobotModel::joint_index(const std::string& n) const {
  for (size_t i = 0; i < joints.size(); ++i)
    if (joints[i].name == n) return static_cast<int>(i);
  return -1;
}

int RobotModel::require_link(const std::string& n) const {
  const int i = link_index(n);
  if (i >= 0) return i;
  std::string all;
  for (const auto& l : links) all += (all.empty() ? "" : ", ") + l.name;
  throw std::runtime_error("robot '" + name + "' has no link '" + n + "' (links: " + all + ")");
}

std::vector<int> RobotModel::chain(const std::string& from, const std::string& to) const {
  const int a = require_link(from);
  std::vector<int> out;
  for (int i = require_link(to); i != a; i = links[i].parent_link) {
    if (i < 0) throw std::runtime_error("link '" + to + "' is not below link '" + from + "' in robot '" + name + "'");
    out.insert(out.begin(), i);
  }
  return out;
}

std::vector<int> RobotModel::movable_joints(const std::string& from, const std::string& to) const {
  std::vector<int> out;
  for (int l : chain(from, to)) {
    const int j = links[l].parent_joint;
    if (joints[j].kind != RobotJoint::Kind::kFixed) out.push_back(j);
  }
  return out;
}

}  // namespace bookgrasp
