#include "services/sim_world/sim_world_node.h"

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "common/scene/scene.h"

namespace bookgrasp {

SimWorldSettings SimWorldSettings::from_config(const Config& root) {
  SimWorldSettings s;
  s.arm_setpoint_channel = root.get<std::string>("channels.arm_setpoint");
  s.gripper_setpoint_channel = root.get<std::string>("channels.gripper_setpoint");
  s.sim_state_channel = root.get<std::string>("channels.sim_state");
  s.ground_truth_channel = root.get<std::string>("channels.ground_truth");
  s.task_status_channel = root.get_channel("channels.task_status");
  s.user_event_channel = root.get_channel("channels.user_event");
  s.librarian = SimLibrarianParams::from_config(root);
  const std::string file = root.get<std::string>("scene.file");
  namespace fs = std::filesystem;
  fs::path p(file);
  if (p.is_relative() && !fs::exists(p)) {
    const fs::path tree = fs::path(root.source()).parent_path() / ".." / "..";
    if (fs::exists(tree / p)) p = (tree / p).lexically_normal();
  }
  if (!fs::exists(p))
    throw ConfigError(root.source() + ": " + root.path_of("scene.file") + " '" + file +
                      "' not found (relative to the working directory or the source tree)");
  s.scene_file = p.string();
  const int64_t seed = root.get<int64_t>("scene.seed");
  if (seed < 0) throw ConfigError(root.source() + ": " + root.path_of("scene.seed") + " must be >= 0");
  s.seed = static_cast<uint64_t>(seed);
  s.timing.epoch_utime = root.get<int64_t>("simulation.epoch_utime");
  if (s.timing.epoch_utime < 0)
    throw ConfigError(root.source() + ": " + root.path_of("simulation.epoch_utime") + " must be >= 0");
  s.timing.state_period_s = root.get_double("simulation.state_period_s", 0.001, 10.0);
  s.timing.ground_truth_period_s = root.get_double("simulation.ground_truth_period_s", 0.001, 60.0);
  s.drive = root.get_choice("simulation.drive", {"wall", "external"});
  s.real_time_factor = root.get_double("simulation.real_time_factor", 0.01, 100.0);
  s.tick_period_s = root.get_double("simulation.tick_period_s", 0.001, 1.0);
  s.max_lag_s = root.get_double("simulation.max_lag_s", 0.01, 10.0);
  return s;
}

SimWorldNode::SimWorldNode(const SimWorldSettings& settings)
    : Component("sim_world", "mujoco"),
      settings_(settings),
      world_(scene::load_scene(settings.scene_file, settings.seed), settings.timing),
      librarian_(settings.librarian) {
  subscribe(settings_.arm_setpoint_channel, &SimWorldNode::on_arm_setpoint);
  subscribe(settings_.gripper_setpoint_channel, &SimWorldNode::on_gripper_setpoint);
  subscribe(settings_.task_status_channel, &SimWorldNode::on_task_status);
}

void SimWorldNode::on_task_status(const task_status_t& msg) {
  // The librarian's clock is the simulation's (a status stamped by another clock would not start the wait).
  librarian_.on_task_state(msg.state, world_.now_utime());
}

void SimWorldNode::librarian_act() {
  auto& model = world_.model();
  const int64_t now = world_.now_utime();
  std::string taken;
  int n = 0;
  for (const auto& b : model.ground_truth(now).books) {
    if (b.place != "holder") continue;
    // Out of the scene: on the floor 2 m behind the robot, a book's length apart.
    model.move_book(b.id, Eigen::Isometry3d(Eigen::Translation3d(-2.0, 1.0 + 0.4 * n++, model.scene().floor_z + 0.2)));
    taken += " " + std::to_string(b.id);
  }
  user_event_t u;
  u.utime = now;
  u.event = "taken";
  u.detail = taken.empty() ? "the simulated librarian found no book on the holder"
                           : "the simulated librarian took book" + taken + " off the holder";
  publish(settings_.user_event_channel, u);
}

void SimWorldNode::on_arm_setpoint(const arm_setpoint_t& msg) {
  try {
    world_.apply_arm_setpoint(msg);
  } catch (const std::invalid_argument& e) {
    reject(settings_.arm_setpoint_channel, std::string("arm setpoint not applied: ") + e.what());
  }
}

void SimWorldNode::on_gripper_setpoint(const gripper_setpoint_t& msg) {
  try {
    world_.apply_gripper_setpoint(msg);
  } catch (const std::invalid_argument& e) {
    reject(settings_.gripper_setpoint_channel, std::string("gripper setpoint not applied: ") + e.what());
  }
}

void SimWorldNode::publish_outputs(const SimWorldOutputs& out) {
  for (const auto& s : out.states) publish(settings_.sim_state_channel, s);
  for (const auto& g : out.ground_truths) publish(settings_.ground_truth_channel, g);
}

void SimWorldNode::advance_to(int64_t utime) {
  publish_outputs(world_.advance_to(utime));
  if (librarian_.due(world_.now_utime())) librarian_act();
}

void SimWorldNode::on_tick(int64_t now_utime) {
  if (settings_.drive != "wall") return;
  if (wall_start_ < 0) {
    wall_start_ = now_utime;
    sim_start_ = world_.now_utime();
  }
  int64_t target =
      sim_start_ + static_cast<int64_t>(std::llround(static_cast<double>(now_utime - wall_start_) * settings_.real_time_factor));
  const int64_t max_lag = static_cast<int64_t>(settings_.max_lag_s * 1e6);
  if (target - world_.now_utime() > max_lag) {
    // Physics cannot keep up: drop the backlog (re-anchor) rather than fall ever further behind.
    report_error("physics behind wall time by more than " + std::to_string(settings_.max_lag_s) +
                 " s: lower simulation.real_time_factor");
    sim_start_ = world_.now_utime() + max_lag;
    wall_start_ = now_utime;
    target = sim_start_;
  }
  advance_to(target);
}

}  // namespace bookgrasp
