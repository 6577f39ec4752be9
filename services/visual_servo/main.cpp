/// @file
/// visual_servo process: IBVS on the book corner R (P2) and PBVS along the black stripe (PS).

#include <memory>

#include "common/process_main.h"
#include "services/visual_servo/visual_servo_node.h"

int main(int argc, char** argv) {
  return bookgrasp::run_service_main(
      argc, argv,
      bookgrasp::ServiceDescription{
          "visual_servo",
          "visual servoing: SERVO_REQUEST + features + ARM_STATE -> ARM_COMMAND (Cartesian velocity), SERVO_STATUS",
          "config/services/visual_servo.yaml", [](const bookgrasp::Config& root) {
            return std::make_unique<bookgrasp::VisualServoNode>(bookgrasp::VisualServoSettings::from_config(root));
          }});
}
