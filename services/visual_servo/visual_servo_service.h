#pragma once
/// @file
/// What the visual_servo process is (name, summary, default configuration, factory), shared by its
/// main() and by the offline tools (replay) that build it in one process.

#include <memory>

#include "common/process_main.h"
#include "services/visual_servo/visual_servo_node.h"

namespace bookgrasp {

/// The visual servo service.
inline ServiceDescription visual_servo_service() {
  return ServiceDescription{
      "visual_servo",
      "visual servoing: SERVO_REQUEST + features + ARM_STATE -> ARM_COMMAND (Cartesian velocity), SERVO_STATUS",
      "config/services/visual_servo.yaml", [](const Config& root) -> std::unique_ptr<Component> {
        return std::make_unique<VisualServoNode>(VisualServoSettings::from_config(root));
      }};
}

}  // namespace bookgrasp
