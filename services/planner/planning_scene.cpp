#include "services/planner/planning_scene.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include <fcl/narrowphase/collision.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>

namespace bookgrasp {

struct PlanningScene::Geometry {
  /// One robot primitive (or the attached box) with its exact and inflated FCL shapes.
  struct Part {
    std::string name;   // link name (or attached box name)
    int link = -1;      // link the part moves with
    bool attached = false;
    Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();  // in the link frame
    std::shared_ptr<fcl::CollisionGeometryd> exact, env_inflated, self_inflated;
    double bound_radius = 0;  // bounding sphere of the exact shape around `origin`
  };
  struct EnvBox {
    std::shared_ptr<fcl::Boxd> box;
    Eigen::Isometry3d pose, inverse;
    Eigen::Vector3d half;
  };
  std::vector<Part> parts;                 // robot parts first, the attached box last if any
  size_t num_robot_parts = 0;
  std::vector<EnvBox> env;
  std::vector<std::pair<int, int>> self_pairs;  // part indices checked against each other
  std::vector<std::vector<bool>> allowed;       // link x link
  std::set<std::pair<std::string, std::string>> allowed_names;
};

namespace {

std::shared_ptr<fcl::CollisionGeometryd> make_shape(const CollisionShape& s, double inflate) {
  switch (s.kind) {
    case CollisionShape::Kind::kSphere:
      return std::make_shared<fcl::Sphered>(s.radius + inflate);
    case CollisionShape::Kind::kBox:
      return std::make_shared<fcl::Boxd>(s.box_size.x() + 2 * inflate, s.box_size.y() + 2 * inflate,
                                         s.box_size.z() + 2 * inflate);
    case CollisionShape::Kind::kCylinder:
      return std::make_shared<fcl::Cylinderd>(s.radius + inflate, s.length + 2 * inflate);
  }
  return nullptr;
}

double bound_radius(const CollisionShape& s) {
  switch (s.kind) {
    case CollisionShape::Kind::kSphere: return s.radius;
    case CollisionShape::Kind::kBox: return 0.5 * s.box_size.norm();
    case CollisionShape::Kind::kCylinder: return std::hypot(s.radius, 0.5 * s.length);
  }
  return 0;
}

// Nearest ancestor that has collision geometry (-1 if none).
int geometric_parent(const RobotModel& m, int link) {
  for (int p = m.links[link].parent_link; p >= 0; p = m.links[p].parent_link)
    if (!m.links[p].collision.empty()) return p;
  return -1;
}

bool collide(const fcl::CollisionGeometryd* a, const Eigen::Isometry3d& ta, const fcl::CollisionGeometryd* b,
             const Eigen::Isometry3d& tb) {
  fcl::CollisionRequestd request;
  fcl::CollisionResultd result;
  fcl::collide(a, ta, b, tb, request, result);
  return result.isCollision();
}

}  // namespace

PlanningScene::PlanningScene(ArmKinematics kinematics, PlanningSceneParams params)
    : kin_(std::move(kinematics)), params_(std::move(params)), geo_(std::make_unique<Geometry>()) {
  if (!(params_.environment_margin_m >= 0) || !(params_.self_margin_m >= 0))
    throw std::invalid_argument("planning scene margins must be >= 0");
  const RobotModel& m = kin_.model();
  const size_t n = m.links.size();
  geo_->allowed.assign(n, std::vector<bool>(n, false));
  for (size_t l = 0; l < n; ++l) {
    geo_->allowed[l][l] = true;
    const int p = geometric_parent(m, static_cast<int>(l));
    if (p >= 0) geo_->allowed[l][p] = geo_->allowed[p][l] = true;
  }
  for (const auto& pair : params_.allowed_collisions) {
    const int a = m.link_index(pair.first), b = m.link_index(pair.second);
    if (a < 0 || b < 0)
      throw std::invalid_argument("allowed collision pair names an unknown link: '" + pair.first + "', '" +
                                  pair.second + "'");
    geo_->allowed[a][b] = geo_->allowed[b][a] = true;
  }
  for (size_t l = 0; l < n; ++l) {
    for (const CollisionShape& s : m.links[l].collision) {
      Geometry::Part part;
      part.name = m.links[l].name;
      part.link = static_cast<int>(l);
      part.origin = s.origin;
      part.exact = make_shape(s, 0.0);
      part.env_inflated = make_shape(s, params_.environment_margin_m);
      part.self_inflated = make_shape(s, params_.self_margin_m);
      part.bound_radius = bound_radius(s);
      geo_->parts.push_back(part);
    }
  }
  geo_->num_robot_parts = geo_->parts.size();
  rebuild_pairs();
}

PlanningScene::~PlanningScene() = default;

PlanningScene::PlanningScene(const PlanningScene& o)
    : kin_(o.kin_), params_(o.params_), environment_(o.environment_), attached_(o.attached_),
      geo_(std::make_unique<Geometry>(*o.geo_)) {}

PlanningScene& PlanningScene::operator=(const PlanningScene& o) {
  if (this != &o) {
    kin_ = o.kin_;
    params_ = o.params_;
    environment_ = o.environment_;
    attached_ = o.attached_;
    geo_ = std::make_unique<Geometry>(*o.geo_);
  }
  return *this;
}

void PlanningScene::rebuild_pairs() {
  geo_->self_pairs.clear();
  const auto& parts = geo_->parts;
  for (size_t i = 0; i < parts.size(); ++i) {
    for (size_t j = i + 1; j < parts.size(); ++j) {
      if (parts[i].attached || parts[j].attached) {
        const Geometry::Part& book = parts[i].attached ? parts[i] : parts[j];
        const Geometry::Part& other = parts[i].attached ? parts[j] : parts[i];
        const auto& touch = attached_.box.touch_links;
        (void)book;
        if (std::find(touch.begin(), touch.end(), other.name) != touch.end()) continue;
        if (other.link == kin_.tip_link()) continue;
      } else if (geo_->allowed[parts[i].link][parts[j].link]) {
        continue;
      }
      geo_->self_pairs.emplace_back(static_cast<int>(i), static_cast<int>(j));
    }
  }
}

void PlanningScene::set_environment(std::vector<SceneBox> boxes) {
  std::vector<Geometry::EnvBox> env;
  for (const SceneBox& b : boxes) {
    if (!b.size.allFinite() || (b.size.array() <= 0).any() || !b.pose.matrix().allFinite())
      throw std::invalid_argument("environment box '" + b.name + "' has a non-positive or non-finite size or pose");
    Geometry::EnvBox e;
    e.box = std::make_shared<fcl::Boxd>(b.size.x(), b.size.y(), b.size.z());
    e.pose = b.pose;
    e.inverse = b.pose.inverse();
    e.half = 0.5 * b.size;
    env.push_back(e);
  }
  geo_->env = std::move(env);
  environment_ = std::move(boxes);
}

void PlanningScene::attach(const AttachedBox& box) {
  detach();
  if (!box.size.allFinite() || (box.size.array() <= 0).any() || !box.pose_in_tip.matrix().allFinite())
    throw std::invalid_argument("attached box '" + box.name + "' has a non-positive or non-finite size or pose");
  for (const auto& l : box.touch_links)
    if (kin_.model().link_index(l) < 0)
      throw std::invalid_argument("attached box touch link '" + l + "' is not a link of the robot");
  CollisionShape s;
  s.kind = CollisionShape::Kind::kBox;
  s.box_size = box.size;
  Geometry::Part part;
  part.name = box.name;
  part.link = kin_.tip_link();
  part.attached = true;
  part.origin = box.pose_in_tip;
  part.exact = make_shape(s, 0.0);
  // At most the scene's margin: check() prefilters with the scene's margin around the bounding sphere.
  const double env_margin = box.environment_margin_m < 0
                                ? params_.environment_margin_m
                                : std::min(box.environment_margin_m, params_.environment_margin_m);
  part.env_inflated = make_shape(s, env_margin);
  part.self_inflated = make_shape(s, params_.self_margin_m);
  part.bound_radius = bound_radius(s);
  geo_->parts.push_back(part);
  attached_.has_value = true;
  attached_.box = box;
  rebuild_pairs();
}

void PlanningScene::detach() {
  if (!attached_.has_value) return;
  geo_->parts.resize(geo_->num_robot_parts);
  attached_ = Attached{};
  rebuild_pairs();
}

bool PlanningScene::is_valid(const Eigen::VectorXd& q) const {
  if (!kin_.within_limits(q)) return false;
  return !check(q, true).collision;
}

CollisionReport PlanningScene::check(const Eigen::VectorXd& q, bool with_margins) const {
  CollisionReport report;
  std::vector<Eigen::Isometry3d> links;
  kin_.link_poses(q, params_.finger_position_m, links);
  const Eigen::Vector3d tool = links[kin_.tip_link()].translation();
  if ((tool.array() < params_.tool_min.array()).any() || (tool.array() > params_.tool_max.array()).any()) {
    report.collision = true;
    report.first = kin_.model().links[kin_.tip_link()].name;
    report.second = "tool workspace bounds";
    return report;
  }
  const auto& parts = geo_->parts;
  std::vector<Eigen::Isometry3d> pose(parts.size());
  for (size_t i = 0; i < parts.size(); ++i) pose[i] = links[parts[i].link] * parts[i].origin;

  const double env_margin = with_margins ? params_.environment_margin_m : 0.0;
  for (size_t i = 0; i < parts.size(); ++i) {
    const auto* shape = with_margins ? parts[i].env_inflated.get() : parts[i].exact.get();
    const double reach = parts[i].bound_radius + env_margin;
    for (size_t e = 0; e < geo_->env.size(); ++e) {
      const Geometry::EnvBox& box = geo_->env[e];
      // Bounding sphere against the box: exact distance from a point to an oriented box.
      const Eigen::Vector3d local = box.inverse * pose[i].translation();
      const Eigen::Vector3d outside = (local.cwiseAbs() - box.half).cwiseMax(0.0);
      if (outside.squaredNorm() > reach * reach) continue;
      if (collide(shape, pose[i], box.box.get(), box.pose)) {
        report.collision = true;
        report.first = parts[i].name;
        report.second = environment_[e].name;
        return report;
      }
    }
  }
  const double self_margin = with_margins ? params_.self_margin_m : 0.0;
  for (const auto& [a, b] : geo_->self_pairs) {
    const double reach = parts[a].bound_radius + parts[b].bound_radius + 2 * self_margin;
    if ((pose[a].translation() - pose[b].translation()).squaredNorm() > reach * reach) continue;
    const auto* sa = with_margins ? parts[a].self_inflated.get() : parts[a].exact.get();
    const auto* sb = with_margins ? parts[b].self_inflated.get() : parts[b].exact.get();
    if (collide(sa, pose[a], sb, pose[b])) {
      report.collision = true;
      report.first = parts[a].name;
      report.second = parts[b].name;
      return report;
    }
  }
  return report;
}

std::vector<std::pair<std::string, std::string>> PlanningScene::allowed_pairs() const {
  std::vector<std::pair<std::string, std::string>> out;
  const RobotModel& m = kin_.model();
  for (size_t a = 0; a < m.links.size(); ++a)
    for (size_t b = a + 1; b < m.links.size(); ++b)
      if (geo_->allowed[a][b] && !m.links[a].collision.empty() && !m.links[b].collision.empty())
        out.emplace_back(m.links[a].name, m.links[b].name);
  return out;
}

}  // namespace bookgrasp
