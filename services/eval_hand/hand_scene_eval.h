#pragma once
/// @file
/// One scene of the hand-camera evaluation, closed in simulation with the
/// harness (hand_servo_harness.h): the stripe servo from station A (PS against
/// the true stripe end), the corner servo from a seeded start offset around the
/// true P1 (P2 and the slope against the truth), and the marker detector's time
/// on the scene's stereo left image. Errors in the cart's grasp frame.

#include <cstdint>
#include <string>

#include <Eigen/Core>

#include "services/eval_hand/hand_eval_metrics.h"

namespace bookgrasp {

/// What to run per scene.
struct HandSceneSettings {
  std::string scene_file;  ///< scene YAML (e.g. services/eval_hand/scenes/hand_eval.yaml)
  std::string config_dir;  ///< config/services
  /// Station A in the grasp frame: the coordinator's until stop 43 (it now starts at Y 0.36, coordinator.yaml), kept
  /// here so the figures in docs/HAND_CAMERA.md stay comparable.
  Eigen::Vector3d station_a = Eigen::Vector3d(0.10, 0.30, -0.10);
  double stripe_timeout_s = 20.0;                                  ///< SERVO_REQUEST.timeout_s of the stripe task
  double corner_standoff_m = 0.22;                                 ///< corner task: TCP to the book front
  double corner_max_offset_m = 0.05;  ///< corner start: P1 + an offset drawn (seeded) in a disc of this radius
  double corner_timeout_s = 15.0;     ///< SERVO_REQUEST.timeout_s of the corner task
  double camera_rate_hz = 15.0;       ///< hand camera frames per second of simulation time
  bool run_markers = true;            ///< time the marker detector on the stereo left image
  std::string debug_image_dir;        ///< first/last hand images of each task (optional)
  int debug_every_frames = 0;         ///< with debug_image_dir: also every this many frames
};

/// Runs scene `seed`. Never throws: a set-up error goes into HandSceneOutcome::error.
HandSceneOutcome evaluate_hand_scene(uint64_t seed, const HandSceneSettings& settings);

/// Signed angle (deg) from the book's up axis to the gripper's x axis about the grasp frame's Z, both
/// projected onto the grasp frame's X-Y plane. `grasp_in_base`, `gripper_in_base`, `book_in_base`: poses
/// (book body frame: z = height, docs of common/scene/scene.h).
double slope_error_deg(const Eigen::Matrix3d& grasp_in_base, const Eigen::Matrix3d& gripper_in_base,
                       const Eigen::Matrix3d& book_in_base);

}  // namespace bookgrasp
