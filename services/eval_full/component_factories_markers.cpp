// marker_detector in its own file (historically its tag_pose.h and visual_servo's hand_eye_geometry.h both defined CameraIntrinsics; marker_detector's is now TagCameraIntrinsics).
#include "services/eval_full/component_factories.h"

#include "services/marker_detector/marker_detector_node.h"

namespace bookgrasp::factories {

std::unique_ptr<Component> marker_detector(const Config& c) {
  return std::make_unique<MarkerDetectorNode>(MarkerDetectorSettings::from_config(c));
}

}  // namespace bookgrasp::factories
