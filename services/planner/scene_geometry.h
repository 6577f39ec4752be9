#pragma once
/// @file
/// The planning environment as boxes: cart and holder boxes given in their
/// marker frames (placed by the marker poses from MARKERS, or nominal poses
/// until a marker is seen), and fixed boxes in the base frame (the user's
/// screen, the floor, the user). Read from the planner configuration.

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "common/config.h"
#include "services/planner/planning_scene.h"

namespace bookgrasp {

/// A box given relative to some parent frame (a marker or base).
struct BoxSpec {
  std::string name;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  ///< box centre and axes in the parent frame
  Eigen::Vector3d size = Eigen::Vector3d::Zero();           ///< full edge lengths
};

/// Boxes of one object (cart, holder) that is located by its marker.
struct MarkerBoxes {
  std::string role;  ///< marker role in MARKERS ("cart", "holder")
  Eigen::Isometry3d nominal_object_in_base = Eigen::Isometry3d::Identity();  ///< used until the marker is seen
  Eigen::Isometry3d marker_in_object = Eigen::Isometry3d::Identity();  ///< where the marker frame sits on the object
  std::vector<BoxSpec> boxes;  ///< in the object frame
};

/// The whole environment description.
struct SceneGeometry {
  std::vector<MarkerBoxes> marker_groups;  ///< cart, holder
  std::vector<BoxSpec> fixed_boxes;        ///< in base: screen, floor, user
};

/// Reads `scene` of the planner configuration:
///   scene.fixed_boxes.<name>: {center: [x,y,z], rpy: [r,p,y], size: [x,y,z]}   (base frame)
///   scene.objects.<role>.nominal_pose: {position: [x,y,z], rpy: [r,p,y]}  (object frame in base)
///   scene.objects.<role>.marker_pose: {position, rpy}                      (marker frame in the object frame)
///   scene.objects.<role>.boxes.<name>: {center, rpy, size}                 (object frame)
/// Throws ConfigError naming the key for a missing or bad value (sizes must be > 0).
SceneGeometry scene_geometry_from_config(const Config& scene);

/// Pose from roll-pitch-yaw (fixed axes x, y, z: R = Rz(yaw) Ry(pitch) Rx(roll)) and a position.
Eigen::Isometry3d pose_from_rpy(const Eigen::Vector3d& position, const Eigen::Vector3d& rpy);

/// The environment boxes in base for the given marker poses (role -> marker pose in base; an object
/// whose role is not given stays at its nominal pose): object = marker * marker_in_object^-1.
/// Box names are "<role>_<box>" for object boxes.
std::vector<SceneBox> build_environment(const SceneGeometry& geometry,
                                        const std::vector<std::pair<std::string, Eigen::Isometry3d>>& marker_poses);

}  // namespace bookgrasp
