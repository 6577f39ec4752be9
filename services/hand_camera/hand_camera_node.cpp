#include "services/hand_camera/hand_camera_node.h"

#include <climits>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "common/image_conversion.h"
#include "common/sim_render/calibration_file.h"
#include "common/sim_render/image_folder.h"
#include "common/sim_render/sim_camera_rig.h"
#include "common/version.h"

namespace bookgrasp {
namespace {

std::string resolve(const std::string& path) {
  if (path.empty() || std::filesystem::path(path).is_absolute()) return path;
  return (std::filesystem::path(kSourceDir) / path).string();
}

hand_image_t make_hand_image(const cv::Mat& rgb, const camera_calibration_t& calibration, int64_t utime,
                             int64_t sequence, const std::string& encoding) {
  hand_image_t m;
  m.utime = utime;
  m.sequence = sequence;
  m.image = encode_image(rgb, encoding, utime, calibration.frame);
  m.calibration = calibration;
  m.calibration.utime = utime;
  m.calibration.camera_in_base.utime = utime;
  return m;
}

}  // namespace

HandCameraSettings HandCameraSettings::from_config(const Config& root) {
  HandCameraSettings s;
  s.sim_state_channel = root.get<std::string>("channels.sim_state");
  s.output_channel = root.get<std::string>("channels.output");
  s.backend = root.get_choice("backend", {"sim", "files"});
  s.image_encoding = root.get_choice("image_encoding", image_encodings());
  s.scene_file = resolve(root.get<std::string>("sim.scene_file"));
  s.seed = root.get<int64_t>("sim.seed");
  if (s.seed < 0) throw ConfigError(root.source() + ": sim.seed must be >= 0");
  s.sim_frame_rate_hz = root.get_double("sim.frame_rate_hz", 0.01, 1000.0);
  s.folder = resolve(root.get<std::string>("files.folder"));
  s.suffix = root.get<std::string>("files.suffix");
  s.calibration_file = resolve(root.get<std::string>("files.calibration_file"));
  s.files_frame_rate_hz = root.get_double("files.frame_rate_hz", 0.01, 1000.0);
  s.start_utime = root.get<int64_t>("files.start_utime");
  if (s.start_utime < 0) throw ConfigError(root.source() + ": files.start_utime must be >= 0");
  s.loop = root.get<bool>("files.loop");
  if (s.backend == "sim" && !std::filesystem::is_regular_file(s.scene_file)) {
    throw ConfigError(root.source() + ": sim.scene_file '" + s.scene_file + "' does not exist");
  }
  return s;
}

HandCameraNode::HandCameraNode(const HandCameraSettings& settings)
    : Component("hand_camera", settings.backend), settings_(settings) {
  if (settings_.backend == "sim") {
    rig_ = std::make_unique<sim_render::SimCameraRig>(settings_.scene_file, static_cast<uint64_t>(settings_.seed));
    schedule_ = std::make_unique<sim_render::CaptureSchedule>(settings_.sim_frame_rate_hz);
    subscribe(settings_.sim_state_channel, &HandCameraNode::on_sim_state);
  } else {
    images_ = sim_render::find_images(settings_.folder, settings_.suffix);
    calibration_ = sim_render::load_camera_calibration(settings_.calibration_file);
    for (const std::string& path : images_) {
      const cv::Mat img = sim_render::read_rgb(path);
      if (img.cols != calibration_.width || img.rows != calibration_.height) {
        throw std::runtime_error("image '" + path + "' is " + std::to_string(img.cols) + "x" +
                                 std::to_string(img.rows) + " but the calibration '" + settings_.calibration_file +
                                 "' is for " + std::to_string(calibration_.width) + "x" +
                                 std::to_string(calibration_.height));
      }
    }
  }
}

HandCameraNode::~HandCameraNode() = default;

bool HandCameraNode::admit_sim(const sim_state_t& state, std::string* reason) {
  reason->clear();
  if (!rig_) {
    *reason = "not the sim backend";
    return false;
  }
  const sim_render::Admission a = sim_render::admit_sim_state(state, rig_->seed(), order_, *schedule_);
  if (a.restarted) {
    report_error(a.reason);  // followed, not rejected
  } else if (!a.reason.empty()) {
    *reason = a.reason;
    return false;
  }
  return a.render;
}

hand_image_t HandCameraNode::render_sim(const sim_state_t& state) {
  rig_->apply(state);
  const sim_render::CameraImage img = rig_->capture("hand_camera", state.utime);
  return make_hand_image(img.rgb, img.camera.to_message(state.utime), state.utime, sequence_++,
                         settings_.image_encoding);
}

bool HandCameraNode::capture_sim(const sim_state_t& state, hand_image_t* out, std::string* reason) {
  if (!admit_sim(state, reason)) return false;
  *out = render_sim(state);
  return true;
}

bool HandCameraNode::next_file_frame(hand_image_t* out) {
  if (images_.empty()) return false;
  const int64_t n = static_cast<int64_t>(images_.size());
  if (!settings_.loop && frame_index_ >= n) return false;
  const int64_t period_us = static_cast<int64_t>(std::llround(1e6 / settings_.files_frame_rate_hz));
  const int64_t utime = settings_.start_utime + frame_index_ * period_us;
  *out = make_hand_image(sim_render::read_rgb(images_[static_cast<size_t>(frame_index_ % n)]), calibration_, utime,
                         frame_index_, settings_.image_encoding);
  ++frame_index_;
  return true;
}

void HandCameraNode::on_sim_state(const sim_state_t& state) {
  // Rendered once no newer state waits (on_inputs_drained): a camera slower than the simulation on a loaded
  // machine then skips states instead of working through a growing backlog (images 2-3 s late, deployed).
  std::string reason;
  if (admit_sim(state, &reason)) {
    pending_ = state;
  } else if (!reason.empty()) {
    reject(settings_.sim_state_channel, reason);
  }
}

bool HandCameraNode::on_inputs_drained() {
  if (!pending_) return false;
  const sim_state_t state = std::move(*pending_);
  pending_.reset();
  try {
    publish(settings_.output_channel, render_sim(state));
  } catch (const std::exception& e) {
    report_error(std::string("rendering failed: ") + e.what());
  }
  return true;
}

void HandCameraNode::on_tick(int64_t /*now_utime*/) {
  if (settings_.backend != "files") return;
  hand_image_t img;
  try {
    if (next_file_frame(&img)) publish(settings_.output_channel, img);
  } catch (const std::exception& e) {
    report_error(e.what());
  }
}

double HandCameraNode::tick_period_s() const {
  return settings_.backend == "files" ? 1.0 / settings_.files_frame_rate_hz : 0.0;
}

}  // namespace bookgrasp
