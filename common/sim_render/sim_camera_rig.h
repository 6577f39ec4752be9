#pragma once
/// @file
/// The simulated cameras of a scene: a SimModel built from a scene file and a
/// seed, put into the state of each SIM_STATE, and rendered through each
/// camera's sensor model. Library `bookgrasp_sim_camera` (this folder).

#include <cstdint>
#include <memory>
#include <string>

#include <opencv2/core.hpp>

#include "bookgrasp/sim_state_t.hpp"
#include "common/sim_render/capture_schedule.h"
#include "common/time_order.h"
#include "common/scene/scene.h"
#include "common/scene/sim_model.h"
#include "common/sim_render/offscreen_renderer.h"
#include "common/sim_render/sensor_model.h"

namespace bookgrasp::sim_render {

/// One captured frame of one simulated camera.
struct CameraImage {
  PinholeCamera camera;  ///< calibration and pose (in base) at capture
  cv::Mat rgb;           ///< CV_8UC3 RGB after the sensor model
  cv::Mat depth;         ///< CV_32FC1 metres along the optical axis, NaN = nothing (if requested)
  cv::Mat owner;         ///< CV_32SC1 book id >= 0 or scene::GeomOwner code per pixel (if requested)
};

/// The three cameras of a simulated scene. Holds its own SimModel (the
/// physics runs elsewhere: sim_world); apply() copies a SIM_STATE into it.
class SimCameraRig {
 public:
  /// Generates the scene of `scene_file` with `seed`, builds its model and a
  /// renderer. Throws scene::ConfigError / std::runtime_error naming the
  /// problem, RenderError if no offscreen context can be made.
  SimCameraRig(const std::string& scene_file, uint64_t seed);

  /// Puts the model into `state` (arm and finger joints, book poses). Throws
  /// std::invalid_argument saying what is wrong (array sizes that disagree
  /// with num_joints/num_bodies, a missing or duplicated arm joint, NaN,
  /// another seed) without changing the model.
  void apply(const sim_state_t& state);

  /// Renders camera `name` ("stereo_left", "stereo_right", "hand_camera") at
  /// the current state, with the scene's resolution, shadows and sensor model;
  /// the noise is seeded by (scene seed, `utime`, camera name). Depth and the
  /// owner image are exact (no noise) and made only if asked for.
  CameraImage capture(const std::string& name, int64_t utime, bool with_depth = false,
                      bool with_owner = false);

  /// The camera's scene settings (resolution, fovy, noise, exposure).
  const scene::CameraSpec& spec(const std::string& name) const;
  /// The sensor model of camera `name`, from its scene settings.
  SensorModel sensor(const std::string& name) const;

  /// The scene (geometry, lighting, cameras) the rig renders.
  const scene::Scene& scene() const { return model_.scene(); }
  /// The MuJoCo model in its current state.
  scene::SimModel& model() { return model_; }
  /// The scene seed.
  uint64_t seed() const { return seed_; }

 private:
  uint64_t seed_;
  scene::SimModel model_;
  std::unique_ptr<OffscreenRenderer> renderer_;
  std::vector<int> owner_of_geom_;
};

/// The gripper widths a SIM_STATE may carry (m). A closed gripper reads below
/// zero: the URDF lets each finger 1 mm past it and MuJoCo's joint limits and
/// finger coupling are soft (CI saw -1.7 mm with the gripper closed).
constexpr double kMinSimGripperWidthM = -0.005;
constexpr double kMaxSimGripperWidthM = 0.1;  ///< see kMinSimGripperWidthM

/// Checks a SIM_STATE before it is applied: array lengths agree with
/// num_joints / num_bodies, every arm joint appears exactly once, all numbers
/// are finite, the gripper width is within [kMinSimGripperWidthM,
/// kMaxSimGripperWidthM], quaternions are not zero. Returns "" if fine,
/// otherwise the reason.
std::string check_sim_state(const sim_state_t& state);

/// Whether a camera renders a SIM_STATE.
struct Admission {
  bool render = false;     ///< a frame is due: render it
  bool restarted = false;  ///< the simulation restarted (its clock jumped back): schedule reset; not an error
  std::string reason;      ///< why not rendered (bad state), or what the restart was
};

/// The one gate every simulated camera puts a SIM_STATE through: content (check_sim_state), the
/// scene seed (`rig_seed`), time order (`order`: out-of-order states are refused, a restarted
/// simulation is followed) and the frame schedule (`schedule`, reset on a restart).
Admission admit_sim_state(const sim_state_t& state, uint64_t rig_seed, TimeOrderGuard& order,
                          CaptureSchedule& schedule);

}  // namespace bookgrasp::sim_render
