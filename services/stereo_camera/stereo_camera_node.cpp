#include "services/stereo_camera/stereo_camera_node.h"

#include <climits>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "common/image_conversion.h"
#include "common/sim_render/sim_camera_rig.h"
#include "common/version.h"

namespace bookgrasp {
namespace {

std::string resolve(const std::string& path) {
  if (path.empty() || std::filesystem::path(path).is_absolute()) return path;
  return (std::filesystem::path(kSourceDir) / path).string();
}

}  // namespace

StereoCameraSettings StereoCameraSettings::from_config(const Config& root) {
  StereoCameraSettings s;
  s.sim_state_channel = root.get<std::string>("channels.sim_state");
  s.output_channel = root.get<std::string>("channels.output");
  s.backend = root.get_choice("backend", {"sim", "files"});
  s.image_encoding = root.get_choice("image_encoding", image_encodings());
  s.scene_file = resolve(root.get<std::string>("sim.scene_file"));
  s.seed = root.get<int64_t>("sim.seed");
  if (s.seed < 0) throw ConfigError(root.source() + ": sim.seed must be >= 0");
  s.sim_frame_rate_hz = root.get_double("sim.frame_rate_hz", 0.01, 1000.0);
  s.folder = resolve(root.get<std::string>("files.folder"));
  s.left_suffix = root.get<std::string>("files.left_suffix");
  s.right_suffix = root.get<std::string>("files.right_suffix");
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

stereo_frame_t make_stereo_frame(const cv::Mat& left_rgb, const cv::Mat& right_rgb,
                                 const camera_calibration_t& left, const camera_calibration_t& right,
                                 double baseline_m, int64_t utime, int64_t sequence, const std::string& encoding) {
  stereo_frame_t f;
  f.utime = utime;
  f.sequence = sequence;
  f.left = encode_image(left_rgb, encoding, utime, left.frame);
  f.right = encode_image(right_rgb, encoding, utime, right.frame);
  f.left_calibration = left;
  f.right_calibration = right;
  f.left_calibration.utime = utime;
  f.right_calibration.utime = utime;
  f.left_calibration.camera_in_base.utime = utime;
  f.right_calibration.camera_in_base.utime = utime;
  f.baseline_m = baseline_m;
  return f;
}

StereoCameraNode::StereoCameraNode(const StereoCameraSettings& settings)
    : Component("stereo_camera", settings.backend), settings_(settings) {
  if (settings_.backend == "sim") {
    rig_ = std::make_unique<sim_render::SimCameraRig>(settings_.scene_file, static_cast<uint64_t>(settings_.seed));
    schedule_ = std::make_unique<sim_render::CaptureSchedule>(settings_.sim_frame_rate_hz);
    subscribe(settings_.sim_state_channel, &StereoCameraNode::on_sim_state);
  } else {
    pairs_ = sim_render::find_image_pairs(settings_.folder, settings_.left_suffix, settings_.right_suffix);
    calibration_ = sim_render::load_stereo_calibration(settings_.calibration_file);
    for (const auto& p : pairs_) {
      for (const std::string& path : {p.left, p.right}) {
        const cv::Mat img = sim_render::read_rgb(path);
        if (img.cols != calibration_.left.width || img.rows != calibration_.left.height) {
          throw std::runtime_error("image '" + path + "' is " + std::to_string(img.cols) + "x" +
                                   std::to_string(img.rows) + " but the calibration '" +
                                   settings_.calibration_file + "' is for " +
                                   std::to_string(calibration_.left.width) + "x" +
                                   std::to_string(calibration_.left.height));
        }
      }
    }
  }
}

StereoCameraNode::~StereoCameraNode() = default;

bool StereoCameraNode::admit_sim(const sim_state_t& state, std::string* reason) {
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

stereo_frame_t StereoCameraNode::render_sim(const sim_state_t& state) {
  rig_->apply(state);
  const sim_render::CameraImage left = rig_->capture("stereo_left", state.utime);
  const sim_render::CameraImage right = rig_->capture("stereo_right", state.utime);
  const double baseline = (left.camera.camera_in_base.translation() - right.camera.camera_in_base.translation()).norm();
  return make_stereo_frame(left.rgb, right.rgb, left.camera.to_message(state.utime),
                           right.camera.to_message(state.utime), baseline, state.utime, sequence_++,
                           settings_.image_encoding);
}

bool StereoCameraNode::capture_sim(const sim_state_t& state, stereo_frame_t* out, std::string* reason) {
  if (!admit_sim(state, reason)) return false;
  *out = render_sim(state);
  return true;
}

bool StereoCameraNode::next_file_frame(stereo_frame_t* out) {
  if (pairs_.empty()) return false;
  const int64_t n = static_cast<int64_t>(pairs_.size());
  if (!settings_.loop && frame_index_ >= n) return false;
  const auto& pair = pairs_[static_cast<size_t>(frame_index_ % n)];
  const int64_t period_us = static_cast<int64_t>(std::llround(1e6 / settings_.files_frame_rate_hz));
  const int64_t utime = settings_.start_utime + frame_index_ * period_us;
  *out = make_stereo_frame(sim_render::read_rgb(pair.left), sim_render::read_rgb(pair.right), calibration_.left,
                           calibration_.right, calibration_.baseline_m, utime, frame_index_,
                           settings_.image_encoding);
  ++frame_index_;
  return true;
}

void StereoCameraNode::on_sim_state(const sim_state_t& state) {
  // Rendered once no newer state waits (on_inputs_drained): a camera slower than the simulation on a loaded
  // machine then skips states instead of working through a growing backlog (images 2-3 s late, deployed).
  std::string reason;
  if (admit_sim(state, &reason)) {
    pending_ = state;
  } else if (!reason.empty()) {
    reject(settings_.sim_state_channel, reason);
  }
}

bool StereoCameraNode::on_inputs_drained() {
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

void StereoCameraNode::on_tick(int64_t /*now_utime*/) {
  if (settings_.backend != "files") return;
  stereo_frame_t frame;
  try {
    if (next_file_frame(&frame)) publish(settings_.output_channel, frame);
  } catch (const std::exception& e) {
    report_error(e.what());
  }
}

double StereoCameraNode::tick_period_s() const {
  return settings_.backend == "files" ? 1.0 / settings_.files_frame_rate_hz : 0.0;
}

}  // namespace bookgrasp
