/// @file
/// sim_world process: MuJoCo physics of the library scene -> SIM_STATE, SIM_GROUND_TRUTH.

#include <memory>

#include "common/process_main.h"
#include "services/sim_world/sim_world_node.h"

int main(int argc, char** argv) {
  return bookgrasp::run_service_main(
      argc, argv,
      bookgrasp::ServiceDescription{
          "sim_world", "MuJoCo physics of the library scene: ARM_SETPOINT, GRIPPER_SETPOINT -> SIM_STATE, SIM_GROUND_TRUTH",
          "config/services/sim_world.yaml", [](const bookgrasp::Config& root) {
            return std::make_unique<bookgrasp::SimWorldNode>(bookgrasp::SimWorldSettings::from_config(root));
          }});
}
