#pragma once
/// @file
/// Everything the planner service reads from config/services/planner.yaml,
/// and the objects built from it (kinematics, IK, planning scene, planner).
/// Shared by the node, the benchmark tool and the tests.

#include <string>
#include <vector>

#include "common/config.h"
#include "common/kinematics/inverse_kinematics.h"
#include "services/planner/motion_planner.h"
#include "services/planner/planning_scene.h"
#include "services/planner/scene_geometry.h"

namespace bookgrasp {

/// How a held book sits in the gripper (configuration `held_book`).
struct HeldBookParams {
  std::vector<std::string> touch_links;  ///< links the book may touch
  double top_above_tcp_m = 0.015;        ///< book top above the TCP (gripper +x)
  double behind_tcp_m = 0.03;            ///< fore-edge behind the TCP (gripper -z)
  double max_tilt_rad = 0.0;             ///< > 0: a planned path keeps the book (gripper x) this upright
  double max_pitch_rad = 0.0;            ///< > 0: ... and the approach (gripper z) this near horizontal
  double environment_margin_m = -1.0;    ///< the book's distance to keep from the environment (< 0: the scene's)
};

/// The whole planner configuration, validated.
struct PlannerSettings {
  std::string channel_plan_request, channel_markers, channel_plan_result;
  std::string urdf_path;  ///< absolute
  std::string base_link, tip_link;
  IkParams ik;
  PlanningSceneParams scene;
  HeldBookParams held_book;
  MotionPlannerParams planner;
  double default_time_budget_s = 1.0;
  double max_time_budget_s = 10.0;
  SceneGeometry geometry;
  /// A request that arrives before the first MARKERS (a planner restarted while the task runs) is answered
  /// once they arrive instead of at the cart's and holder's nominal poses (`scene.defer_until_markers`).
  bool defer_until_markers = true;

  /// Reads every key (all required); throws ConfigError naming a bad key.
  static PlannerSettings from_config(const Config& root);
  /// Loads config/services/planner.yaml (or `path`) and reads it; checks that every key was read.
  static PlannerSettings load(const std::string& path);
};

/// The box of a held book of size (width = thickness along gripper y, height along gripper x,
/// depth along gripper z), placed as HeldBookParams says.
AttachedBox held_book_box(const Eigen::Vector3d& width_height_depth, const HeldBookParams& params);

/// The objects a planner needs, built from the settings.
struct PlannerStack {
  ArmKinematics kinematics;
  InverseKinematics ik;
  MotionPlanner planner;
  PlanningScene scene;  ///< with the nominal environment
  /// Builds everything; throws ConfigError / std::runtime_error with what is wrong.
  explicit PlannerStack(const PlannerSettings& settings);
};

}  // namespace bookgrasp
