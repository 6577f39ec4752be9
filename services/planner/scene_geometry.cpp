#include "services/planner/scene_geometry.h"

namespace bookgrasp {
namespace {

Eigen::Vector3d vec3(const Config& c, const std::string& key) {
  const std::vector<double> v = c.get_vector(key, 3);
  const Eigen::Vector3d out(v[0], v[1], v[2]);
  if (!out.allFinite()) throw ConfigError(c.source() + ": " + c.path_of(key) + " must be finite numbers");
  return out;
}

BoxSpec box_from(const Config& c, const std::string& name) {
  BoxSpec b;
  b.name = name;
  b.pose = pose_from_rpy(vec3(c, "center"), vec3(c, "rpy"));
  b.size = vec3(c, "size");
  if ((b.size.array() <= 0).any())
    throw ConfigError(c.source() + ": " + c.path_of("size") + " must be three positive edge lengths (metres)");
  return b;
}

}  // namespace

Eigen::Isometry3d pose_from_rpy(const Eigen::Vector3d& position, const Eigen::Vector3d& rpy) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = position;
  t.linear() = (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  return t;
}

SceneGeometry scene_geometry_from_config(const Config& scene) {
  SceneGeometry g;
  const Config fixed = scene.child("fixed_boxes");
  for (const auto& name : fixed.keys()) g.fixed_boxes.push_back(box_from(fixed.child(name), name));
  const Config objects = scene.child("objects");
  for (const auto& role : objects.keys()) {
    const Config m = objects.child(role);
    MarkerBoxes group;
    group.role = role;
    const Config nominal = m.child("nominal_pose");
    group.nominal_object_in_base = pose_from_rpy(vec3(nominal, "position"), vec3(nominal, "rpy"));
    const Config marker = m.child("marker_pose");
    group.marker_in_object = pose_from_rpy(vec3(marker, "position"), vec3(marker, "rpy"));
    const Config boxes = m.child("boxes");
    for (const auto& name : boxes.keys()) group.boxes.push_back(box_from(boxes.child(name), name));
    g.marker_groups.push_back(group);
  }
  return g;
}

std::vector<SceneBox> build_environment(const SceneGeometry& geometry,
                                        const std::vector<std::pair<std::string, Eigen::Isometry3d>>& marker_poses) {
  std::vector<SceneBox> out;
  for (const BoxSpec& b : geometry.fixed_boxes) out.push_back({b.name, b.pose, b.size});
  for (const MarkerBoxes& group : geometry.marker_groups) {
    Eigen::Isometry3d object = group.nominal_object_in_base;
    for (const auto& [role, pose] : marker_poses)
      if (role == group.role) object = pose * group.marker_in_object.inverse();
    for (const BoxSpec& b : group.boxes) out.push_back({group.role + "_" + b.name, object * b.pose, b.size});
  }
  return out;
}

}  // namespace bookgrasp
