// arm_driver: executes arm and gripper commands within limits; streams setpoints; reports ARM_STATE.
#include "common/process_main.h"
#include "services/arm_driver/arm_driver_node.h"

int main(int argc, char** argv) {
  return bookgrasp::run_service_main(
      argc, argv,
      {"arm_driver", "arm driver: trajectories, Cartesian velocity, gripper; limits and heartbeat",
       "config/services/arm_driver.yaml",
       [](const bookgrasp::Config& root) { return std::make_unique<bookgrasp::ArmDriverNode>(root); }});
}
