#include "services/planner/planner_config.h"

#include <cmath>
#include <sstream>

#include "common/version.h"

namespace bookgrasp {
namespace {

Eigen::VectorXd vecn(const Config& c, const std::string& key, size_t n) {
  const std::vector<double> v = c.get_vector(key, n);
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

Eigen::Vector3d vec3(const Config& c, const std::string& key) { return vecn(c, key, 3); }

}  // namespace

PlannerSettings PlannerSettings::from_config(const Config& root) {
  PlannerSettings s;
  const Config ch = root.child("channels");
  s.channel_plan_request = ch.get<std::string>("plan_request");
  s.channel_markers = ch.get<std::string>("markers");
  s.channel_plan_result = ch.get<std::string>("plan_result");

  const Config robot = root.child("robot");
  s.urdf_path = robot.get<std::string>("urdf");
  if (!s.urdf_path.empty() && s.urdf_path[0] != '/') s.urdf_path = std::string(kSourceDir) + "/" + s.urdf_path;
  s.base_link = robot.get<std::string>("base_link");
  s.tip_link = robot.get<std::string>("tip_link");
  s.scene.finger_position_m = robot.get_double("finger_position_m", -0.01, 0.1);

  // The joint count comes from the URDF; vectors are checked against it below.
  const ArmKinematics kin = ArmKinematics::from_urdf_file(s.urdf_path, s.base_link, s.tip_link);
  const size_t n = static_cast<size_t>(kin.num_joints());

  const Config ik = root.child("ik");
  s.ik.max_iterations = ik.get_int("max_iterations", 1, 100000);
  s.ik.max_restarts = ik.get_int("max_restarts", 0, 1000);
  s.ik.position_tolerance_m = ik.get_double("position_tolerance_m", 1e-9, 0.1);
  s.ik.orientation_tolerance_rad = ik.get_double("orientation_tolerance_rad", 1e-9, 1.0);
  s.ik.damping = ik.get_double("damping", 1e-9, 10.0);
  s.ik.max_step_rad = ik.get_double("max_step_rad", 1e-6, 3.2);
  s.ik.nullspace_gain = ik.get_double("nullspace_gain", 0.0, 1.0);
  s.ik.posture_iterations = ik.get_int("posture_iterations", 0, 100000);
  s.ik.orientation_weight_m = ik.get_double("orientation_weight_m", 1e-6, 100.0);
  s.ik.preferred_posture = vecn(ik, "preferred_posture", n);
  if (!kin.within_limits(s.ik.preferred_posture))
    throw ConfigError(root.source() + ": " + ik.path_of("preferred_posture") + " is outside the joint limits");
  s.ik.seed = static_cast<uint64_t>(ik.get<int64_t>("seed"));

  const Config col = root.child("collision");
  s.scene.environment_margin_m = col.get_double("environment_margin_m", 0.0, 0.5);
  s.scene.self_margin_m = col.get_double("self_margin_m", 0.0, 0.5);
  s.scene.tool_min = vec3(col, "tool_workspace_min");
  s.scene.tool_max = vec3(col, "tool_workspace_max");
  if ((s.scene.tool_max - s.scene.tool_min).minCoeff() <= 0)
    throw ConfigError(root.source() + ": " + col.path_of("tool_workspace_max") + " must exceed tool_workspace_min");
  for (const std::string& pair : col.get<std::vector<std::string>>("allowed_pairs")) {
    std::istringstream in(pair);
    std::string a, b, extra;
    in >> a >> b;
    if (a.empty() || b.empty() || (in >> extra) || kin.model().link_index(a) < 0 || kin.model().link_index(b) < 0)
      throw ConfigError(root.source() + ": " + col.path_of("allowed_pairs") + " entry '" + pair +
                        "' must be two link names of the robot separated by a space");
    s.scene.allowed_collisions.emplace_back(a, b);
  }

  const Config hb = root.child("held_book");
  s.held_book.touch_links = hb.get<std::vector<std::string>>("touch_links");
  for (const auto& l : s.held_book.touch_links)
    if (kin.model().link_index(l) < 0)
      throw ConfigError(root.source() + ": " + hb.path_of("touch_links") + " names '" + l + "', not a robot link");
  s.held_book.top_above_tcp_m = hb.get_double("top_above_tcp_m", -0.5, 0.5);
  s.held_book.behind_tcp_m = hb.get_double("behind_tcp_m", -0.5, 0.5);
  s.held_book.max_tilt_rad = hb.get_double("max_tilt_deg", 0.0, 90.0) * M_PI / 180.0;
  s.held_book.max_pitch_rad = hb.get_double("max_pitch_deg", 0.0, 90.0) * M_PI / 180.0;
  s.held_book.environment_margin_m = hb.get_double("environment_margin_m", 0.0, 0.5);

  const Config pl = root.child("planner");
  MotionPlannerParams& p = s.planner;
  p.default_planner = pl.get_choice("default", MotionPlanner::planner_names());
  s.default_time_budget_s = pl.get_double("default_time_budget_s", 1e-3, 600.0);
  s.max_time_budget_s = pl.get_double("max_time_budget_s", 1e-3, 600.0);
  p.collision_resolution_rad = pl.get_double("collision_resolution_rad", 1e-4, 0.5);
  p.range_rad = pl.get_double("range_rad", 1e-3, 10.0);
  p.max_search_steps = pl.get_int("max_search_steps", 0, 100000000);
  p.wall_clock_stop = pl.get<bool>("wall_clock_stop");
  if (!p.wall_clock_stop && p.max_search_steps == 0)
    throw ConfigError(root.source() + ": " + pl.path_of("wall_clock_stop") + " is false and " +
                      pl.path_of("max_search_steps") +
                      " is 0: nothing would end a search; set max_search_steps > 0 or wall_clock_stop: true");
  p.simplify_shortcuts = pl.get_int("simplify_shortcuts", 0, 100000);
  p.goal_ik_solutions = pl.get_int("goal_ik_solutions", 1, 100);
  p.goal_ik_attempts = pl.get_int("goal_ik_attempts", 1, 10000);
  p.goal_limit_margin_rad = pl.get_double("goal_limit_margin_rad", 0.0, 1.0);
  p.start_escape_max_rad = pl.get_double("start_escape_max_rad", 0.0, 1.0);
  p.start_escape_attempts = pl.get_int("start_escape_attempts", 1, 100000);
  p.then_step_m = pl.get_double("then_step_m", 1e-4, 0.1);
  p.then_step_rad = pl.get_double("then_step_rad", 1e-4, 0.5);
  p.then_limit_margin_rad = pl.get_double("then_limit_margin_rad", 0.0, 0.5);
  p.max_velocity = vecn(pl, "max_velocity_rad_s", n);
  p.max_acceleration = vecn(pl, "max_acceleration_rad_s2", n);
  for (size_t k = 0; k < n; ++k) {
    if (!(p.max_velocity[k] > 0) || p.max_velocity[k] > kin.velocity_limits()[k])
      throw ConfigError(root.source() + ": " + pl.path_of("max_velocity_rad_s") + "[" + std::to_string(k) +
                        "] must be in (0, " + std::to_string(kin.velocity_limits()[k]) + "] (URDF limit)");
    if (!(p.max_acceleration[k] > 0))
      throw ConfigError(root.source() + ": " + pl.path_of("max_acceleration_rad_s2") + " must be positive");
  }
  p.sample_period_s = pl.get_double("sample_period_s", 1e-3, 1.0);
  const Config cb = pl.child("cell_birrt");
  p.cell_size_m = cb.get_double("cell_size_m", 0.01, 1.0);
  p.workspace_min = vec3(cb, "workspace_min");
  p.workspace_max = vec3(cb, "workspace_max");
  if ((p.workspace_max - p.workspace_min).minCoeff() <= 0)
    throw ConfigError(root.source() + ": " + cb.path_of("workspace_max") + " must exceed workspace_min on every axis");
  p.tube_sigma_m = cb.get_double("tube_sigma_m", 1e-3, 10.0);
  p.min_cell_weight = cb.get_double("min_cell_weight", 0.0, 1.0);
  p.failure_decay = cb.get_double("failure_decay", 0.0, 1.0);
  p.cell_sample_probability = cb.get_double("cell_sample_probability", 0.0, 1.0);
  p.orientation_noise_rad = cb.get_double("orientation_noise_rad", 0.0, 3.2);
  p.cell_ik_iterations = cb.get_int("ik_iterations", 1, 10000);

  s.geometry = scene_geometry_from_config(root.child("scene"));
  s.defer_until_markers = root.get<bool>("scene.defer_until_markers");
  return s;
}

PlannerSettings PlannerSettings::load(const std::string& path) {
  const Config root = Config::load_file(path);
  root.mark_read("service");
  PlannerSettings s = from_config(root);
  root.require_all_read();
  return s;
}

AttachedBox held_book_box(const Eigen::Vector3d& whd, const HeldBookParams& params) {
  AttachedBox box;
  box.name = "held_book";
  box.size = Eigen::Vector3d(whd[1], whd[0], whd[2]);  // gripper x = height, y = width, z = depth
  box.pose_in_tip = Eigen::Isometry3d::Identity();
  box.pose_in_tip.translation() =
      Eigen::Vector3d(params.top_above_tcp_m - 0.5 * whd[1], 0.0, 0.5 * whd[2] - params.behind_tcp_m);
  box.touch_links = params.touch_links;
  box.environment_margin_m = params.environment_margin_m;
  return box;
}

PlannerStack::PlannerStack(const PlannerSettings& s)
    : kinematics(ArmKinematics::from_urdf_file(s.urdf_path, s.base_link, s.tip_link)),
      ik(kinematics, s.ik),
      planner(ik, s.planner),
      scene(kinematics, s.scene) {
  scene.set_environment(build_environment(s.geometry, {}));
}

}  // namespace bookgrasp
