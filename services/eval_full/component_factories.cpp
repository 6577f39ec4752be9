#include "services/eval_full/component_factories.h"

#include "services/arbiter/arbiter_node.h"
#include "services/arm_driver/arm_driver_node.h"
#include "services/bswh_detector/bswh_detector_node.h"
#include "services/bwh_detector/bwh_detector_node.h"
#include "services/bws_detector/bws_detector_node.h"
#include "services/coordinator/coordinator_node.h"
#include "services/hand_camera/hand_camera_node.h"
#include "services/planner/planner_node.h"
#include "services/sim_world/sim_world_node.h"
#include "services/stereo_camera/stereo_camera_node.h"
#include "services/visual_servo/visual_servo_node.h"

namespace bookgrasp::factories {

std::unique_ptr<Component> sim_world(const Config& c) {
  return std::make_unique<SimWorldNode>(SimWorldSettings::from_config(c));
}
std::unique_ptr<Component> stereo_camera(const Config& c) {
  return std::make_unique<StereoCameraNode>(StereoCameraSettings::from_config(c));
}
std::unique_ptr<Component> hand_camera(const Config& c) {
  return std::make_unique<HandCameraNode>(HandCameraSettings::from_config(c));
}
std::unique_ptr<Component> bws_detector(const Config& c) {
  return std::make_unique<BwsDetectorNode>(BwsDetectorSettings::from_config(c));
}
std::unique_ptr<Component> bwh_detector(const Config& c) {
  return std::make_unique<BwhDetectorNode>(BwhDetectorSettings::from_config(c));
}
std::unique_ptr<Component> bswh_detector(const Config& c) {
  return std::make_unique<BswhDetectorNode>(BswhDetectorSettings::from_config(c));
}
std::unique_ptr<Component> visual_servo(const Config& c) {
  return std::make_unique<VisualServoNode>(VisualServoSettings::from_config(c));
}
std::unique_ptr<Component> arbiter(const Config& c) { return std::make_unique<ArbiterNode>(c); }
std::unique_ptr<Component> planner(const Config& c) {
  return std::make_unique<PlannerNode>(PlannerSettings::from_config(c));
}
std::unique_ptr<Component> arm_driver(const Config& c) { return std::make_unique<ArmDriverNode>(c); }
std::unique_ptr<Component> coordinator(const Config& c) { return std::make_unique<CoordinatorNode>(c); }

}  // namespace bookgrasp::factories
