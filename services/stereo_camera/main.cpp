/// @file
/// stereo_camera process: STEREO_IMAGES from the simulation (SIM_STATE) or from image files.

#include <memory>

#include "common/process_main.h"
#include "services/stereo_camera/stereo_camera_node.h"

int main(int argc, char** argv) {
  return bookgrasp::run_service_main(
      argc, argv,
      bookgrasp::ServiceDescription{
          "stereo_camera", "rectified stereo pair (sim: rendered per SIM_STATE; files: image pairs) -> STEREO_IMAGES",
          "config/services/stereo_camera.yaml", [](const bookgrasp::Config& root) {
            return std::make_unique<bookgrasp::StereoCameraNode>(
                bookgrasp::StereoCameraSettings::from_config(root));
          }});
}
