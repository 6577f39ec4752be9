#pragma once
/// @file
/// The hand_camera component: publishes HAND_IMAGE (image + calibration with
/// the camera pose at capture) from one of two backends:
///  - `sim`: renders the gripper camera for each SIM_STATE that is due at the
///    configured frame rate in simulation time (utime = the state's; the pose
///    comes from the state's joints);
///  - `files`: reads images from a folder and publishes one per tick, stamped
///    start_utime + index * period, with the fixed pose of the calibration file.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "bookgrasp/hand_image_t.hpp"
#include "bookgrasp/sim_state_t.hpp"
#include "common/component.h"
#include "common/time_order.h"
#include "common/config.h"
#include "common/sim_render/capture_schedule.h"

namespace bookgrasp {

namespace sim_render {
class SimCameraRig;
}

/// Everything the hand camera reads from its configuration.
struct HandCameraSettings {
  std::string sim_state_channel;   ///< channels.sim_state (sim_state_t, sim backend)
  std::string output_channel;      ///< channels.output (hand_image_t)
  std::string backend;             ///< backend: "sim" or "files"
  std::string image_encoding;      ///< image_encoding: "raw" (RGB8) or "png"

  std::string scene_file;          ///< sim.scene_file (absolute, resolved)
  int64_t seed = 0;                ///< sim.seed
  double sim_frame_rate_hz = 10;   ///< sim.frame_rate_hz, in simulation time

  std::string folder;              ///< files.folder (absolute, resolved)
  std::string suffix;              ///< files.suffix: every file ending with it is an image
  std::string calibration_file;    ///< files.calibration_file (absolute, resolved; `camera:` section)
  double files_frame_rate_hz = 1;  ///< files.frame_rate_hz (tick rate)
  int64_t start_utime = 0;         ///< files.start_utime: utime of the first frame
  bool loop = true;                ///< files.loop: start again after the last image

  /// Reads the whole configuration root. Relative paths are resolved against
  /// the source tree (kSourceDir). Throws ConfigError naming a bad key.
  static HandCameraSettings from_config(const Config& root);
};

/// The hand camera as a component.
class HandCameraNode : public Component {
 public:
  /// Sets up the backend (see StereoCameraNode). Throws ConfigError /
  /// std::runtime_error saying what is wrong.
  explicit HandCameraNode(const HandCameraSettings& settings);
  ~HandCameraNode() override;

  /// Sim backend core: renders an image for `state` if one is due. Returns
  /// false with `*reason` empty if no frame is due, false with a reason for
  /// a state that cannot be used, true with `*out` filled otherwise.
  bool capture_sim(const sim_state_t& state, hand_image_t* out, std::string* reason);
  /// Files backend core: the next image of the folder. False when the folder
  /// is exhausted and files.loop is off.
  bool next_file_frame(hand_image_t* out);

  void on_tick(int64_t now_utime) override;
  /// Renders the newest due SIM_STATE, if any (a backlog of states is skipped, not rendered late).
  bool on_inputs_drained() override;
  double tick_period_s() const override;

  /// Number of images (files backend; 0 for sim).
  size_t num_images() const { return images_.size(); }

 private:
  void on_sim_state(const sim_state_t& state);
  /// Admits `state` (content, seed, order, schedule): true if a frame is due; false with `*reason` for a bad state.
  bool admit_sim(const sim_state_t& state, std::string* reason);
  /// Renders `state`.
  hand_image_t render_sim(const sim_state_t& state);

  HandCameraSettings settings_;
  int64_t sequence_ = 0;
  std::unique_ptr<sim_render::SimCameraRig> rig_;
  std::unique_ptr<sim_render::CaptureSchedule> schedule_;
  std::optional<sim_state_t> pending_;  ///< newest due state, rendered in on_inputs_drained()
  TimeOrderGuard order_;
  std::vector<std::string> images_;
  camera_calibration_t calibration_;
  int64_t frame_index_ = 0;
};

}  // namespace bookgrasp
