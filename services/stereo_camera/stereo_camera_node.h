#pragma once
/// @file
/// The stereo_camera component: publishes STEREO_IMAGES (left and right
/// images, both calibrations, baseline) from one of two backends:
///  - `sim`: renders the scene's stereo pair for each SIM_STATE that is due
///    at the configured frame rate in simulation time (utime = the state's);
///  - `files`: reads image pairs from a folder and publishes one per tick,
///    stamped start_utime + index * period (deterministic).

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "bookgrasp/sim_state_t.hpp"
#include "bookgrasp/stereo_frame_t.hpp"
#include "common/component.h"
#include "common/time_order.h"
#include "common/config.h"
#include "common/sim_render/calibration_file.h"
#include "common/sim_render/capture_schedule.h"
#include "common/sim_render/image_folder.h"

namespace bookgrasp {

namespace sim_render {
class SimCameraRig;
}

/// Everything the stereo camera reads from its configuration.
struct StereoCameraSettings {
  std::string sim_state_channel;   ///< channels.sim_state (sim_state_t, sim backend)
  std::string output_channel;      ///< channels.output (stereo_frame_t)
  std::string backend;             ///< backend: "sim" or "files"
  std::string image_encoding;      ///< image_encoding: "raw" (RGB8), "png" or "jpeg"

  std::string scene_file;          ///< sim.scene_file (absolute, resolved)
  int64_t seed = 0;                ///< sim.seed
  double sim_frame_rate_hz = 10;   ///< sim.frame_rate_hz, in simulation time

  std::string folder;              ///< files.folder (absolute, resolved)
  std::string left_suffix;         ///< files.left_suffix, e.g. "im2.png"
  std::string right_suffix;        ///< files.right_suffix, e.g. "im6.png"
  std::string calibration_file;    ///< files.calibration_file (absolute, resolved)
  double files_frame_rate_hz = 1;  ///< files.frame_rate_hz (tick rate)
  int64_t start_utime = 0;         ///< files.start_utime: utime of the first frame
  bool loop = true;                ///< files.loop: start again after the last pair

  /// Reads the whole configuration root. Relative paths are resolved against
  /// the source tree (kSourceDir). Throws ConfigError naming a bad key.
  static StereoCameraSettings from_config(const Config& root);
};

/// Builds a stereo frame message from two RGB images (CV_8UC3) with
/// `encoding` "raw" (RGB8) or "png".
stereo_frame_t make_stereo_frame(const cv::Mat& left_rgb, const cv::Mat& right_rgb,
                                 const camera_calibration_t& left, const camera_calibration_t& right,
                                 double baseline_m, int64_t utime, int64_t sequence, const std::string& encoding);

/// The stereo camera as a component.
class StereoCameraNode : public Component {
 public:
  /// Sets up the backend: `sim` builds the scene model and the renderer,
  /// `files` lists the pairs and reads the calibration, checking every image
  /// against it. Throws ConfigError / std::runtime_error saying what is wrong.
  explicit StereoCameraNode(const StereoCameraSettings& settings);
  ~StereoCameraNode() override;

  /// Sim backend core: renders a frame for `state` if one is due. Returns
  /// false with `*reason` empty if no frame is due, false with a reason for
  /// a state that cannot be used, true with `*out` filled otherwise.
  bool capture_sim(const sim_state_t& state, stereo_frame_t* out, std::string* reason);
  /// Files backend core: the next frame of the folder. False when the folder
  /// is exhausted and files.loop is off.
  bool next_file_frame(stereo_frame_t* out);

  void on_tick(int64_t now_utime) override;
  /// Renders the newest due SIM_STATE, if any (a backlog of states is skipped, not rendered late).
  bool on_inputs_drained() override;
  double tick_period_s() const override;

  /// Number of image pairs (files backend; 0 for sim).
  size_t num_pairs() const { return pairs_.size(); }

 private:
  void on_sim_state(const sim_state_t& state);
  /// Admits `state` (content, seed, order, schedule): true if a frame is due; false with `*reason` for a bad state.
  bool admit_sim(const sim_state_t& state, std::string* reason);
  /// Renders `state`.
  stereo_frame_t render_sim(const sim_state_t& state);

  StereoCameraSettings settings_;
  int64_t sequence_ = 0;
  // sim
  std::unique_ptr<sim_render::SimCameraRig> rig_;
  std::unique_ptr<sim_render::CaptureSchedule> schedule_;
  std::optional<sim_state_t> pending_;  ///< newest due state, rendered in on_inputs_drained()
  TimeOrderGuard order_;
  // files
  std::vector<sim_render::ImagePairFiles> pairs_;
  sim_render::StereoCalibration calibration_;
  int64_t frame_index_ = 0;
};

}  // namespace bookgrasp
