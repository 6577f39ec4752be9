#pragma once
/// @file
/// What the stereo_camera process is (name, summary, default configuration, factory), shared by its
/// main() and by the offline tools (replay, evaluation) that build it in one process.

#include <memory>

#include "common/process_main.h"
#include "services/stereo_camera/stereo_camera_node.h"

namespace bookgrasp {

/// The stereo_camera service.
inline ServiceDescription stereo_camera_service() {
  return ServiceDescription{
          "stereo_camera", "rectified stereo pair (sim: rendered per SIM_STATE; files: image pairs) -> STEREO_IMAGES",
          "config/services/stereo_camera.yaml", [](const bookgrasp::Config& root) {
            return std::make_unique<bookgrasp::StereoCameraNode>(
                bookgrasp::StereoCameraSettings::from_config(root));
          }};
}

}  // namespace bookgrasp
