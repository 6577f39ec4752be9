#pragma once
/// @file
/// Builds each service's component from its configuration, exactly as its main() does.
/// (Kept out of full_cycle_harness.cpp: marker_detector and visual_servo both define
/// bookgrasp::CameraIntrinsics (now renamed TagCameraIntrinsics in marker_detector), so their headers could not share a translation unit.)

#include <memory>

#include "common/component.h"
#include "common/config.h"

namespace bookgrasp::factories {

std::unique_ptr<Component> sim_world(const Config& c);        ///< SimWorldNode
std::unique_ptr<Component> stereo_camera(const Config& c);    ///< StereoCameraNode
std::unique_ptr<Component> hand_camera(const Config& c);      ///< HandCameraNode
std::unique_ptr<Component> marker_detector(const Config& c);  ///< MarkerDetectorNode
std::unique_ptr<Component> bws_detector(const Config& c);     ///< BwsDetectorNode
std::unique_ptr<Component> bwh_detector(const Config& c);     ///< BwhDetectorNode
std::unique_ptr<Component> bswh_detector(const Config& c);    ///< BswhDetectorNode
std::unique_ptr<Component> visual_servo(const Config& c);     ///< VisualServoNode
std::unique_ptr<Component> arbiter(const Config& c);          ///< ArbiterNode
std::unique_ptr<Component> planner(const Config& c);          ///< PlannerNode
std::unique_ptr<Component> arm_driver(const Config& c);       ///< ArmDriverNode
std::unique_ptr<Component> coordinator(const Config& c);      ///< CoordinatorNode

}  // namespace bookgrasp::factories
