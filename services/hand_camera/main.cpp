/// @file
/// hand_camera process: HAND_IMAGE from the simulation (SIM_STATE) or from image files.

#include <memory>

#include "common/process_main.h"
#include "services/hand_camera/hand_camera_node.h"

int main(int argc, char** argv) {
  return bookgrasp::run_service_main(
      argc, argv,
      bookgrasp::ServiceDescription{
          "hand_camera", "gripper camera image + pose at capture (sim: rendered per SIM_STATE; files) -> HAND_IMAGE",
          "config/services/hand_camera.yaml", [](const bookgrasp::Config& root) {
            return std::make_unique<bookgrasp::HandCameraNode>(bookgrasp::HandCameraSettings::from_config(root));
          }});
}
