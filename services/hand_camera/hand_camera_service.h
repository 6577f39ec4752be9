#pragma once
/// @file
/// What the hand_camera process is (name, summary, default configuration, factory), shared by its
/// main() and by the offline tools (replay, evaluation) that build it in one process.

#include <memory>

#include "common/process_main.h"
#include "services/hand_camera/hand_camera_node.h"

namespace bookgrasp {

/// The hand_camera service.
inline ServiceDescription hand_camera_service() {
  return ServiceDescription{
          "hand_camera", "gripper camera image + pose at capture (sim: rendered per SIM_STATE; files) -> HAND_IMAGE",
          "config/services/hand_camera.yaml", [](const bookgrasp::Config& root) {
            return std::make_unique<bookgrasp::HandCameraNode>(bookgrasp::HandCameraSettings::from_config(root));
          }};
}

}  // namespace bookgrasp
