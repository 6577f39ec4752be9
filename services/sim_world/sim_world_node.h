#pragma once
/// @file
/// sim_world as a Component: ARM_SETPOINT, GRIPPER_SETPOINT in; SIM_STATE,
/// SIM_GROUND_TRUTH out, stamped with simulation time. The simulated librarian (sim_librarian.h) reads
/// TASK_STATUS and, having taken a book off the holder, publishes USER_EVENT "taken".

#include <cstdint>
#include <memory>
#include <string>

#include "bookgrasp/task_status_t.hpp"
#include "bookgrasp/user_event_t.hpp"
#include "common/component.h"
#include "common/config.h"
#include "services/sim_world/sim_librarian.h"
#include "services/sim_world/sim_world.h"

namespace bookgrasp {

/// Everything sim_world reads from config/services/sim_world.yaml.
struct SimWorldSettings {
  std::string arm_setpoint_channel;
  std::string gripper_setpoint_channel;
  std::string sim_state_channel;
  std::string ground_truth_channel;
  std::string task_status_channel;  ///< in: the librarian follows the task
  std::string user_event_channel;   ///< out: the librarian's "taken"
  SimLibrarianParams librarian;
  std::string scene_file;       ///< resolved path of the scene YAML
  uint64_t seed = 0;
  SimWorldTiming timing;
  std::string drive;            ///< "wall": on_tick follows wall time; "external": advance_to() only
  double real_time_factor = 1;  ///< simulation seconds per wall second (drive: wall)
  double tick_period_s = 0.005; ///< on_tick period (drive: wall)
  double max_lag_s = 0.2;       ///< if physics falls further behind, the backlog is dropped

  /// Reads and checks the settings. A relative scene file is looked up from
  /// the working directory, then from the source tree that holds the config
  /// file (config/services/../..). Throws ConfigError naming the key.
  static SimWorldSettings from_config(const Config& root);
};

/// The sim_world component.
class SimWorldNode : public Component {
 public:
  /// Loads the scene and builds the world. Throws ConfigError / std::runtime_error.
  explicit SimWorldNode(const SimWorldSettings& settings);

  /// Composed mode: steps physics to `utime` and publishes what fell due.
  void advance_to(int64_t utime);
  /// The world (tests, renderers in the same process).
  SimWorld& world() { return world_; }

  void on_tick(int64_t now_utime) override;
  double tick_period_s() const override { return settings_.drive == "wall" ? settings_.tick_period_s : 0.0; }

 private:
  void on_arm_setpoint(const arm_setpoint_t& msg);
  void on_gripper_setpoint(const gripper_setpoint_t& msg);
  void on_task_status(const task_status_t& msg);
  /// The librarian's turn: every book on the holder goes out of the scene, then USER_EVENT "taken".
  void librarian_act();
  void publish_outputs(const SimWorldOutputs& out);

  SimWorldSettings settings_;
  SimWorld world_;
  SimLibrarian librarian_;
  int64_t wall_start_ = -1;
  int64_t sim_start_ = 0;
};

}  // namespace bookgrasp
