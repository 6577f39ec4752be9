#pragma once
/// @file
/// The arm driver process: ARM_COMMAND, GRIPPER_COMMAND and the arm's
/// measurements (SIM_STATE for the `sim` backend) in; ARM_SETPOINT,
/// GRIPPER_SETPOINT and ARM_STATE out, at a fixed rate in message time.

#include <memory>
#include <string>

#include "bookgrasp/arm_command_t.hpp"
#include "bookgrasp/arm_state_t.hpp"
#include "bookgrasp/gripper_command_t.hpp"
#include "bookgrasp/sim_state_t.hpp"
#include "common/component.h"
#include "common/config.h"
#include "common/time_order.h"
#include "services/arm_driver/arm_driver_core.h"

namespace bookgrasp {

/// Builds the driver's core (kinematics, limits, parameters) from its configuration.
ArmDriverCore make_arm_driver_core(const Config& root);

/// The arm driver component.
class ArmDriverNode : public Component {
 public:
  /// Reads channels, backend, robot, limits, timing from `root`; throws ConfigError naming a bad key.
  explicit ArmDriverNode(const Config& root);

 private:
  void on_sim_state(const sim_state_t& msg);
  void on_arm_command(const arm_command_t& msg);
  void on_gripper_command(const gripper_command_t& msg);
  void publish_state(int64_t utime);

  struct Channels {
    std::string arm_state, arm_setpoint, gripper_setpoint, arm_command;
  } ch_;
  ArmDriverCore core_;
  double setpoint_period_s_;
  int64_t last_setpoint_utime_ = -1;
  int64_t last_measure_utime_ = 0;
  TimeOrderGuard measure_order_;
  Eigen::VectorXd q_, qd_;
  double gripper_width_ = 0;
  bool gripper_contact_ = false;
};

}  // namespace bookgrasp
