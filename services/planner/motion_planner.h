#pragma once
/// @file
/// The motion planner core (no LCM, no OMPL in this header): a start
/// configuration and a goal (joint values or a tool pose with tolerances) in
/// a PlanningScene -> a collision-free, simplified, time-parameterised joint
/// trajectory, or a failure with its reason. Planners: CellBiRRT (the
/// paper's), and OMPL's RRTConnect and BiTRRT for comparison.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/kinematics/inverse_kinematics.h"
#include "services/planner/planning_scene.h"
#include "services/planner/time_parameterization.h"

namespace bookgrasp {

/// Why a plan failed (values equal plan_result_t's constants).
enum class PlanFailure {
  kNone = 0,
  kInvalidRequest = 1,
  kStartInCollision = 2,  ///< the start is no valid state: in collision, or outside the path's orientation bounds
  kGoalInCollision = 3,
  kNoIk = 4,
  kTimeout = 5,
  kUnknownPlanner = 6,
};

/// Short name of a failure ("timeout", "no_ik", ...).
const char* to_string(PlanFailure failure);

/// One planning query.
struct PlanRequest {
  Eigen::VectorXd start;                  ///< start joints (rad)
  bool goal_is_pose = false;              ///< false: goal_joints; true: goal_pose
  Eigen::VectorXd goal_joints;            ///< joint goal (rad)
  Eigen::Isometry3d goal_pose = Eigen::Isometry3d::Identity();  ///< tool (gripper) pose in base
  double position_tolerance_m = 0.001;    ///< pose goal: accepted position error
  double orientation_tolerance_rad = 0.01;///< pose goal error; also the band of keep_orientation
  bool keep_orientation = false;          ///< keep the tool orientation of the start along the path
  /// > 0: along the whole path the tool's x axis stays within this angle of base +z (a held book, whose
  /// up is the gripper's x, stays upright); start and goal must meet it. 0 = no such constraint.
  double max_tool_tilt_rad = 0.0;
  /// > 0: along the whole path the tool's z axis (the approach) stays within this angle of horizontal (a held
  /// book does not creep along the plates towards their tips); start and goal must meet it. 0 = no such constraint.
  double max_tool_pitch_rad = 0.0;
  /// Pose goal: the straight (Cartesian) moves the arm makes after it, in order (tool poses in base). Goal IK
  /// solutions from which tracking them leaves the joint limits are used only when there is no other.
  std::vector<Eigen::Isometry3d> then_poses;
  double time_budget_s = 1.0;  ///< planning time limit (wall clock; see MotionPlannerParams::max_search_steps)
  std::string planner;                    ///< "CellBiRRT", "RRTConnect", "BiTRRT"; "" = default
  uint64_t seed = 1;                      ///< random seed (same request + seed -> same path)
};

/// The answer.
struct PlanOutcome {
  bool success = false;
  PlanFailure failure = PlanFailure::kNone;
  std::string message;                 ///< what happened, for people
  std::string planner;                 ///< planner that ran
  std::vector<Eigen::VectorXd> path;   ///< simplified waypoints (start first)
  std::vector<Eigen::VectorXd> raw_path;  ///< waypoints as the planner found them
  TimedTrajectory trajectory;          ///< time-parameterised path
  double planning_time_s = 0.0;        ///< everything (checks, goal IK, search, simplification), wall clock
  double goal_ik_time_s = 0.0;         ///< part of planning_time_s spent on goal IK
  double search_time_s = 0.0;          ///< part spent in the planner's search
  double simplify_time_s = 0.0;        ///< part spent simplifying and timing the path
  long search_steps = 0;               ///< termination checks the search made (MotionPlannerParams::max_search_steps)
  double path_length_rad = 0.0;        ///< joint-space length of `path`
};

/// Settings of the planner (configuration `planner`; see docs/PLANNER.md).
struct MotionPlannerParams {
  std::string default_planner = "CellBiRRT";
  double collision_resolution_rad = 0.01;  ///< motion checks every this many rad (joint-space norm)
  double range_rad = 0.3;                  ///< tree extension step of all planners
  /// > 0: the search stops after this many evaluations of its termination condition (about one per tree
  /// extension), whatever the clock says, so the outcome does not depend on the machine's load; the request's
  /// time budget still applies as a safety stop. 0: the time budget alone decides.
  int max_search_steps = 0;
  /// true: the request's time_budget_s also ends a search (the safety stop above). false: only
  /// max_search_steps does (it must then be > 0), so a replay on a slow or busy machine gives the recorded
  /// answers; a deployed planner keeps it true, so that no request waits longer than its budget.
  bool wall_clock_stop = true;
  int simplify_shortcuts = 60;             ///< random shortcut attempts
  int goal_ik_solutions = 4;               ///< distinct valid IK solutions used as goals for a pose goal
  int goal_ik_attempts = 24;               ///< IK attempts to find them
  double goal_limit_margin_rad = 0.0;      ///< goal IK solutions this close to a joint limit are a last resort
  /// > 0: a start within the margins but touching nothing is left first on a straight segment (checked on the
  /// exact shapes) to the nearest valid state found within this joint-space distance. 0: such a start fails.
  double start_escape_max_rad = 0.0;
  int start_escape_attempts = 200;         ///< random directions tried, at radii growing to start_escape_max_rad
  double then_step_m = 0.005;              ///< then_poses are tracked by IK in steps of this length ...
  double then_step_rad = 0.02;             ///< ... and of this rotation
  double then_limit_margin_rad = 0.02;     ///< every tracked posture keeps this far from the joint limits
  Eigen::VectorXd max_velocity;            ///< rad/s per joint (trajectory)
  Eigen::VectorXd max_acceleration;        ///< rad/s^2 per joint (trajectory)
  double sample_period_s = 0.02;           ///< trajectory sample period
  // CellBiRRT
  double cell_size_m = 0.1;
  Eigen::Vector3d workspace_min{-1.2, -1.2, -0.9};
  Eigen::Vector3d workspace_max{1.2, 1.2, 1.4};
  double tube_sigma_m = 0.25;
  double min_cell_weight = 0.02;
  double failure_decay = 0.7;
  double cell_sample_probability = 0.8;
  double orientation_noise_rad = 0.5;
  int cell_ik_iterations = 40;
};

/// The planner. Immutable; plan() is const and may run concurrently on different scenes.
class MotionPlanner {
 public:
  /// Throws std::invalid_argument for inconsistent parameters (limit sizes, unknown default planner).
  MotionPlanner(InverseKinematics ik, MotionPlannerParams params);

  /// Plans in `scene` (which holds the environment and any attached book).
  /// Never throws for a bad request: it is answered with kInvalidRequest.
  PlanOutcome plan(const PlanningScene& scene, const PlanRequest& request) const;

  /// Planner names accepted in PlanRequest::planner.
  static const std::vector<std::string>& planner_names();
  /// The IK solver.
  const InverseKinematics& ik() const { return ik_; }
  /// The parameters.
  const MotionPlannerParams& params() const { return params_; }

 private:
  InverseKinematics ik_;
  MotionPlannerParams params_;
};

/// True if every configuration on the straight segment a -> b, at spacing
/// `resolution_rad` (joint-space norm, both ends included), passes `scene.check`
/// (with or without margins). Used by the planner and by tests at finer resolution.
bool segment_collision_free(const PlanningScene& scene, const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                            double resolution_rad, bool with_margins);

}  // namespace bookgrasp
