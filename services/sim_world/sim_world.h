#pragma once
/// @file
/// The simulated world without LCM: a SimModel stepped in simulation time,
/// fed with validated setpoints, producing SIM_STATE and SIM_GROUND_TRUTH
/// messages at their configured periods.

#include <cstdint>
#include <string>
#include <vector>

#include "bookgrasp/arm_setpoint_t.hpp"
#include "bookgrasp/gripper_setpoint_t.hpp"
#include "bookgrasp/ground_truth_t.hpp"
#include "bookgrasp/sim_state_t.hpp"
#include "common/scene/sim_model.h"

namespace bookgrasp {

/// Timing of the simulated world.
struct SimWorldTiming {
  int64_t epoch_utime = 1000000000000000;  ///< utime of simulation time 0 (us)
  double state_period_s = 0.01;           ///< SIM_STATE period (simulation time)
  double ground_truth_period_s = 0.1;     ///< SIM_GROUND_TRUTH period (simulation time)
};

/// Messages due after an advance, in time order per type.
struct SimWorldOutputs {
  std::vector<sim_state_t> states;
  std::vector<ground_truth_t> ground_truths;
};

/// Physics of one scene, advanced in simulation time. Deterministic: the same
/// scene, setpoints and advance_to() calls give the same outputs bit for bit.
class SimWorld {
 public:
  /// Builds the model of `scene` (throws std::runtime_error if MuJoCo rejects it).
  SimWorld(const scene::Scene& scene, const SimWorldTiming& timing);

  /// Simulation time now, as a utime (epoch + steps x timestep).
  int64_t now_utime() const;
  /// Physics timestep in microseconds.
  int64_t step_utime() const { return step_us_; }

  /// Validates and applies an arm setpoint. Throws std::invalid_argument with
  /// the reason (wrong joint count, arrays not matching num_joints, NaN,
  /// outside the joint limits, older than the previous setpoint): nothing is applied then.
  void apply_arm_setpoint(const arm_setpoint_t& msg);
  /// Validates and applies a gripper setpoint (width in [0, 0.0602] m, force
  /// finite and >= 0; 0 keeps the scene's default force). Throws
  /// std::invalid_argument with the reason; nothing is applied then.
  void apply_gripper_setpoint(const gripper_setpoint_t& msg);

  /// Steps physics until simulation time reaches `utime` (whole steps; an
  /// earlier time does nothing) and returns the messages that fell due on
  /// the way (the first ones at the epoch itself).
  SimWorldOutputs advance_to(int64_t utime);

  /// The simulation model (for renderers and tests).
  scene::SimModel& model() { return model_; }
  const scene::SimModel& model() const { return model_; }

 private:
  void collect_due(SimWorldOutputs* out);

  scene::SimModel model_;
  SimWorldTiming timing_;
  int64_t step_us_ = 2000;
  int64_t steps_ = 0;
  int64_t next_state_utime_ = 0;
  int64_t next_truth_utime_ = 0;
  int64_t last_arm_utime_ = INT64_MIN;
  int64_t last_gripper_utime_ = INT64_MIN;
  double default_force_n_ = 100;
};

}  // namespace bookgrasp
