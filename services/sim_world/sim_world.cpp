#include "services/sim_world/sim_world.h"

#include <cmath>
#include <stdexcept>

namespace bookgrasp {

namespace {
int64_t period_us(double s, const char* what) {
  if (!(s > 0)) throw std::invalid_argument(std::string(what) + " must be > 0 s");
  return static_cast<int64_t>(std::llround(s * 1e6));
}
}  // namespace

SimWorld::SimWorld(const scene::Scene& scene, const SimWorldTiming& timing)
    : model_(scene::SimModel::build(scene)), timing_(timing) {
  step_us_ = static_cast<int64_t>(std::llround(model_.model()->opt.timestep * 1e6));
  if (step_us_ <= 0) throw std::invalid_argument("physics timestep below 1 us");
  period_us(timing.state_period_s, "state period");
  period_us(timing.ground_truth_period_s, "ground truth period");
  next_state_utime_ = timing.epoch_utime;
  next_truth_utime_ = timing.epoch_utime;
  default_force_n_ = scene.physics.gripper_max_force_n;
}

int64_t SimWorld::now_utime() const { return timing_.epoch_utime + steps_ * step_us_; }

void SimWorld::apply_arm_setpoint(const arm_setpoint_t& msg) {
  if (msg.num_joints != 7)
    throw std::invalid_argument("num_joints is " + std::to_string(msg.num_joints) + ", the arm has 7 joints");
  if (msg.positions.size() != static_cast<size_t>(msg.num_joints))
    throw std::invalid_argument("positions has " + std::to_string(msg.positions.size()) +
                                " values, num_joints says " + std::to_string(msg.num_joints));
  if (msg.utime < last_arm_utime_)
    throw std::invalid_argument("setpoint utime " + std::to_string(msg.utime) + " is older than the previous one (" +
                                std::to_string(last_arm_utime_) + ")");
  model_.set_arm_setpoint(msg.positions);  // checks NaN and limits, applies nothing on error
  last_arm_utime_ = msg.utime;
}

void SimWorld::apply_gripper_setpoint(const gripper_setpoint_t& msg) {
  if (!std::isfinite(msg.width_m) || msg.width_m < 0.0 || msg.width_m > 0.0602)
    throw std::invalid_argument("width_m " + std::to_string(msg.width_m) + " is not within [0, 0.0602] m");
  if (!std::isfinite(msg.max_force_n) || msg.max_force_n < 0.0)
    throw std::invalid_argument("max_force_n " + std::to_string(msg.max_force_n) + " is not a finite value >= 0");
  if (msg.utime < last_gripper_utime_)
    throw std::invalid_argument("setpoint utime " + std::to_string(msg.utime) + " is older than the previous one (" +
                                std::to_string(last_gripper_utime_) + ")");
  model_.set_gripper_max_force(msg.max_force_n > 0 ? msg.max_force_n : default_force_n_);
  model_.set_gripper_width(msg.width_m);
  last_gripper_utime_ = msg.utime;
}

void SimWorld::collect_due(SimWorldOutputs* out) {
  const int64_t now = now_utime();
  if (now >= next_state_utime_) {
    out->states.push_back(model_.state(now));
    const int64_t p = period_us(timing_.state_period_s, "state period");
    while (next_state_utime_ <= now) next_state_utime_ += p;
  }
  if (now >= next_truth_utime_) {
    out->ground_truths.push_back(model_.ground_truth(now));
    const int64_t p = period_us(timing_.ground_truth_period_s, "ground truth period");
    while (next_truth_utime_ <= now) next_truth_utime_ += p;
  }
}

SimWorldOutputs SimWorld::advance_to(int64_t utime) {
  SimWorldOutputs out;
  collect_due(&out);
  while (now_utime() + step_us_ <= utime) {
    model_.step(1);
    ++steps_;
    collect_due(&out);
  }
  return out;
}

}  // namespace bookgrasp
