#pragma once
/// @file
/// One visual-servoing task closed in simulation, in one process on memq://
/// (common/composition.h): the SimWorld core stepped by this harness in
/// simulation time, and the real components: arm_driver, hand_camera (sim
/// backend), bwh_detector, bswh_detector, visual_servo, each configured from
/// its config/services/*.yaml. Used by the closed-loop tests and by the
/// evaluation tool bookgrasp_eval_hand.
///
/// The stations (paper Figure 7) come from the scene's geometry and ground
/// truth here, as the coordinator computes them from the cart marker and P1:
///  - station A: a point of the cart's grasp frame (origin at the upper shelf's
///    front edge centre, X up, Y right, Z into the shelf), by default
///    [0.10, 0.30, -0.10] (stripe height, right part of the stripe, 0.46 m in
///    front of the rear board; the coordinator's until stop 43);
///  - corner start: the right-most book's P1 (+ an offset in the grasp frame's
///    X/Y), `corner_standoff_m` in front of it.
/// The arm starts there (the scene's initial joints are replaced by an IK
/// solution before the world is built).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "bookgrasp/ground_truth_t.hpp"
#include "common/scene/scene.h"

namespace bookgrasp {

/// What to run.
struct HandServoTask {
  int mode = 1;                                                 ///< servo_request_t::BOOK_CORNER (1) or STRIPE_END (2)
  Eigen::Isometry3d start_tcp = Eigen::Isometry3d::Identity();  ///< start pose of the TCP in base
  double standoff_m = 0.2;                                      ///< SERVO_REQUEST.fixed_depth_m
  double timeout_s = 20.0;                                      ///< SERVO_REQUEST.timeout_s (simulation time)
  int rank_from_right = 0;
};

/// Harness options.
struct HandServoOptions {
  std::string config_dir;                 ///< folder with the services' YAML files (config/services)
  double camera_rate_hz = 15.0;           ///< hand camera frames per second of simulation time
  std::string debug_image_dir;            ///< if set: first and last hand image of the task (PNG) go here
  std::string debug_prefix;               ///< file name prefix of the debug images
  int debug_every_frames = 0;             ///< with debug_image_dir: also every this many frames (0 = first/last only)
  std::optional<bool> require_occlusion;  ///< overrides visual_servo stripe_end.require_occlusion
  std::optional<std::string> search_direction;  ///< overrides stripe_end.search_direction ("right"/"left")
};

/// What happened.
struct HandServoResult {
  bool ik_ok = false;  ///< the start pose was reachable
  std::string ik_message;
  int state = 0;        ///< final servo_status_t state (0 = none reported)
  std::string message;  ///< its message
  int iterations = 0;
  double sim_time_s = 0;                                                  ///< request to final status, simulation time
  double wall_time_s = 0;                                                 ///< the whole task (build + run)
  std::optional<Eigen::Isometry3d> converged_pose;                        ///< CONVERGED: the TCP pose (P2 or PS)
  ground_truth_t truth;                                                   ///< ground truth at the end of the task
  std::vector<double> bwh_ms, bswh_ms;                                    ///< detector processing time per frame
  int frames = 0;                                                         ///< hand images rendered during the task
  cv::Mat last_image;                                                     ///< last hand image (RGB)
  Eigen::Isometry3d last_camera_in_base = Eigen::Isometry3d::Identity();  ///< its camera pose
  bool last_book_found = false;                                           ///< BwH result on the last image
  Eigen::Vector2d last_r_px = Eigen::Vector2d::Zero();
  bool last_stripe_end_found = false;  ///< BSwH result on the last image
  Eigen::Vector2d last_stripe_end_px = Eigen::Vector2d::Zero();
};

/// The grasp orientation of the TCP for `scene` (gripper z into the shelf along
/// the cart's x axis, x up, y right) at `origin`.
Eigen::Isometry3d grasp_pose_for_cart(const scene::Scene& scene, const Eigen::Vector3d& origin);

/// The TCP pose in the grasp orientation at `p_grasp` of the cart's grasp frame.
Eigen::Isometry3d cart_grasp_pose(const scene::Scene& scene, const Eigen::Vector3d& p_grasp);

/// The cart marker's position in the cart's grasp frame (ground truth).
Eigen::Vector3d cart_marker_in_grasp(const scene::Scene& scene, const ground_truth_t& truth);

/// Start pose for the corner servo: P1 of the right-most book + (dx up, dy right)
/// in the grasp frame, `standoff_m` in front. Returns nullopt if the truth has no right-most book.
std::optional<Eigen::Isometry3d> corner_start(const scene::Scene& scene, const ground_truth_t& truth, double dx,
                                              double dy, double standoff_m);

/// Ground truth of a freshly generated scene (built once, no servoing).
ground_truth_t scene_truth(const scene::Scene& scene);

/// Runs one task in a fresh world of `scene` (seeded; the arm placed at
/// task.start_tcp by IK). Throws std::runtime_error if the simulation or a
/// component cannot be set up (message says what).
HandServoResult run_hand_servo_task(const scene::Scene& scene, const HandServoTask& task,
                                    const HandServoOptions& options);

}  // namespace bookgrasp
