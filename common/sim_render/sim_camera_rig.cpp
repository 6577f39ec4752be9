#include "common/sim_render/sim_camera_rig.h"

#include <cmath>
#include <set>
#include <stdexcept>

namespace bookgrasp::sim_render {
namespace {

RendererSettings settings_for(const scene::Scene& s) {
  RendererSettings r;
  for (const scene::CameraSpec* c : {&s.stereo_left, &s.stereo_right, &s.hand_camera}) {
    r.max_width = std::max(r.max_width, c->width);
    r.max_height = std::max(r.max_height, c->height);
  }
  r.shadows = s.lighting.shadows;
  r.shadow_size = s.lighting.shadow_size;
  r.base_body = "";  // MuJoCo's world frame is `base` (sim_model.h)
  return r;
}

bool finite(double v) { return std::isfinite(v); }

}  // namespace

std::string check_sim_state(const sim_state_t& state) {
  if (state.num_joints < 0 || static_cast<size_t>(state.num_joints) != state.joint_names.size() ||
      state.joint_names.size() != state.joint_positions.size() ||
      state.joint_names.size() != state.joint_velocities.size()) {
    return "num_joints " + std::to_string(state.num_joints) + " disagrees with the arrays (" +
           std::to_string(state.joint_names.size()) + " names, " + std::to_string(state.joint_positions.size()) +
           " positions, " + std::to_string(state.joint_velocities.size()) + " velocities)";
  }
  if (state.num_bodies < 0 || static_cast<size_t>(state.num_bodies) != state.bodies.size()) {
    return "num_bodies " + std::to_string(state.num_bodies) + " but " + std::to_string(state.bodies.size()) +
           " bodies";
  }
  const auto& arm = scene::arm_joint_names();
  std::set<std::string> seen;
  for (int i = 0; i < state.num_joints; ++i) {
    if (!seen.insert(state.joint_names[i]).second) return "joint '" + state.joint_names[i] + "' appears twice";
    if (!finite(state.joint_positions[i])) return "joint '" + state.joint_names[i] + "' position is not finite";
  }
  for (const auto& name : arm) {
    if (!seen.count(name)) {
      return "joint '" + name + "' missing (got " + std::to_string(state.num_joints) + " joints, need the " +
             std::to_string(arm.size()) + " arm joints)";
    }
  }
  if (!finite(state.gripper_width_m) || state.gripper_width_m < kMinSimGripperWidthM ||
      state.gripper_width_m > kMaxSimGripperWidthM) {
    return "gripper_width_m " + std::to_string(state.gripper_width_m) + " outside " +
           std::to_string(kMinSimGripperWidthM) + " .. " + std::to_string(kMaxSimGripperWidthM) + " m";
  }
  for (const auto& b : state.bodies) {
    double qn = 0.0;
    for (int k = 0; k < 3; ++k)
      if (!finite(b.position[k])) return "body '" + b.name + "' position is not finite";
    for (int k = 0; k < 4; ++k) {
      if (!finite(b.orientation[k])) return "body '" + b.name + "' orientation is not finite";
      qn += b.orientation[k] * b.orientation[k];
    }
    if (std::abs(std::sqrt(qn) - 1.0) > 1e-3) return "body '" + b.name + "' quaternion is not unit length";
  }
  return "";
}

SimCameraRig::SimCameraRig(const std::string& scene_file, uint64_t seed)
    : seed_(seed), model_(scene::SimModel::build(scene::load_scene(scene_file, seed))) {
  renderer_ = std::make_unique<OffscreenRenderer>(model_.model(), settings_for(model_.scene()));
  owner_of_geom_.resize(model_.model()->ngeom);
  for (int g = 0; g < model_.model()->ngeom; ++g) owner_of_geom_[g] = model_.geom_owner_id(g);
}

void SimCameraRig::apply(const sim_state_t& state) {
  const std::string problem = check_sim_state(state);
  if (!problem.empty()) throw std::invalid_argument(problem);
  if (static_cast<uint64_t>(state.seed) != seed_) {
    throw std::invalid_argument("state of seed " + std::to_string(state.seed) + " but this camera renders seed " +
                                std::to_string(seed_) + " (restart it with the simulation's scene and seed)");
  }
  model_.apply(state);
}

const scene::CameraSpec& SimCameraRig::spec(const std::string& name) const {
  const scene::Scene& s = model_.scene();
  if (name == "stereo_left") return s.stereo_left;
  if (name == "stereo_right") return s.stereo_right;
  if (name == "hand_camera") return s.hand_camera;
  throw std::invalid_argument("no simulated camera named '" + name +
                              "' (stereo_left, stereo_right, hand_camera)");
}

SensorModel SimCameraRig::sensor(const std::string& name) const {
  const scene::CameraSpec& c = spec(name);
  SensorModel s;
  s.exposure_gain = c.exposure;
  s.noise_stddev = c.noise_stddev;
  return s;
}

CameraImage SimCameraRig::capture(const std::string& name, int64_t utime, bool with_depth, bool with_owner) {
  const scene::CameraSpec& c = spec(name);
  RenderRequest req;
  req.camera = name;
  req.width = c.width;
  req.height = c.height;
  req.depth = with_depth;
  req.segmentation = with_owner;
  RenderedView view = renderer_->render(model_.data(), req);
  CameraImage out;
  out.camera = view.camera;
  out.rgb = apply_sensor_model(view.rgb, sensor(name), frame_seed(static_cast<int64_t>(seed_), utime, name));
  out.depth = view.depth;
  if (with_owner) out.owner = map_geom_ids(view.geom_id, owner_of_geom_, scene::kOwnerNone);
  return out;
}

Admission admit_sim_state(const sim_state_t& state, uint64_t rig_seed, TimeOrderGuard& order,
                          CaptureSchedule& schedule) {
  Admission a;
  a.reason = check_sim_state(state);
  if (!a.reason.empty()) return a;
  if (static_cast<uint64_t>(state.seed) != rig_seed) {
    a.reason = "SIM_STATE is of seed " + std::to_string(state.seed) + " but this camera renders seed " +
               std::to_string(rig_seed) + " (set sim.seed to the simulation's seed)";
    return a;
  }
  const TimeOrder verdict = order.check(state.utime);
  if (verdict == TimeOrder::kStale) {
    a.reason = "SIM_STATE " + order.describe(state.utime, verdict);
    return a;
  }
  if (verdict == TimeOrder::kRestarted) {
    a.restarted = true;
    a.reason = "SIM_STATE " + order.describe(state.utime, verdict);
    schedule = CaptureSchedule(1e6 / static_cast<double>(schedule.period_us()));
  }
  a.render = schedule.due(state.utime);
  return a;
}

}  // namespace bookgrasp::sim_render
