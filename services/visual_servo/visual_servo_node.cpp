#include "services/visual_servo/visual_servo_node.h"

#include <cmath>
#include <filesystem>

#include "common/kinematics/arm_kinematics.h"
#include "common/pose_conversion.h"
#include "common/version.h"

namespace bookgrasp {

namespace {

std::string resolve(const std::string& p) {
  if (p.empty() || std::filesystem::path(p).is_absolute()) return p;
  return (std::filesystem::path(kSourceDir) / p).string();
}

int direction(const Config& c, const std::string& key) {
  return c.get_choice(key, {"right", "left"}) == "right" ? 1 : -1;
}

}  // namespace

VisualServoSettings VisualServoSettings::from_config(const Config& root) {
  VisualServoSettings s;
  s.servo_request_channel = root.get<std::string>("channels.servo_request");
  s.book_features_channel = root.get<std::string>("channels.book_features");
  s.stripe_features_channel = root.get<std::string>("channels.stripe_features");
  s.arm_state_channel = root.get<std::string>("channels.arm_state");
  s.arm_command_channel = root.get<std::string>("channels.arm_command");
  s.servo_status_channel = root.get<std::string>("channels.servo_status");
  s.urdf_path = resolve(root.get<std::string>("robot.urdf"));
  s.tcp_link = root.get<std::string>("robot.tcp_link");
  s.camera_link = root.get<std::string>("robot.camera_link");

  const Config cam = root.child("camera");
  s.camera.width = cam.get_int("width", 1, 100000);
  s.camera.height = cam.get_int("height", 1, 100000);
  s.camera.fx = cam.get_double("fx", 1e-3, 1e6);
  s.camera.fy = cam.get_double("fy", 1e-3, 1e6);
  s.camera.cx = cam.get_double("cx", -1e5, 1e5);
  s.camera.cy = cam.get_double("cy", -1e5, 1e5);

  const Config se = root.child("session");
  s.session.feature_lost_timeout_s = se.get_double("feature_lost_timeout_s", 0.01, 60);
  s.session.stale_feature_s = se.get_double("stale_feature_s", 0.0, 60);
  s.session.command_period_s = se.get_double("command_period_s", 0.001, 0.4);
  s.session.default_timeout_s = se.get_double("default_timeout_s", 0.1, 3600);
  s.session.max_start_error_m = se.get_double("max_start_error_m", 0.0, 10);
  s.session.default_corner_standoff_m = se.get_double("default_corner_standoff_m", 0.01, 2);
  s.session.default_stripe_standoff_m = se.get_double("default_stripe_standoff_m", 0.01, 2);
  s.session.pose_history_s = se.get_double("pose_history_s", 0.05, 10);
  {
    const Config tr = root.child("corner_triangulation");
    s.session.corner_triangulation.min_baseline_m = tr.get_double("min_baseline_m", 0.0, 1.0);
    s.session.corner_triangulation.max_rms_px = tr.get_double("max_rms_px", 0.01, 1000);
    s.session.corner_triangulation.min_sightings = tr.get_int("min_sightings", 2, 100000);
  }
  if (s.session.stale_feature_s > s.session.feature_lost_timeout_s)
    throw ConfigError(se.path_of("stale_feature_s") + " must not exceed feature_lost_timeout_s");

  const Config bc = root.child("book_corner");
  s.corner.gain = bc.get_double("gain", 0.0, 100);
  s.corner.slope_gain = bc.get_double("slope_gain", 0.0, 100);
  s.corner.max_linear_speed = bc.get_double("max_linear_speed", 0.0, 1);
  s.corner.max_angular_speed = bc.get_double("max_angular_speed", 0.0, 3);
  s.corner.converged_px = bc.get_double("converged_px", 0.01, 100);
  s.corner.converged_slope_rad = bc.get_double("converged_slope_deg", 0.01, 45) * M_PI / 180.0;
  s.corner.converged_frames = bc.get_int("converged_frames", 1, 1000);
  s.corner.target_above_tcp_m = bc.get_double("target_above_tcp_m", -0.1, 0.1);
  s.corner.align_slope = bc.get<bool>("align_slope");
  s.corner.compensate_capture_delay = bc.get<bool>("compensate_capture_delay");

  const Config st = root.child("stripe_end");
  s.stripe.gain = st.get_double("gain", 0.0, 100);
  s.stripe.max_linear_speed = st.get_double("max_linear_speed", 0.0, 1);
  s.stripe.search_speed = st.get_double("search_speed", 0.001, 1);
  s.stripe.search_direction = direction(st, "search_direction");
  s.stripe.end_side_direction = direction(st, "end_side");
  s.stripe.require_occlusion = st.get<bool>("require_occlusion");
  s.stripe.converged_x_m = st.get_double("converged_x_m", 1e-5, 0.1);
  s.stripe.converged_y_m = st.get_double("converged_y_m", 1e-5, 0.1);
  s.stripe.converged_frames = st.get_int("converged_frames", 1, 1000);
  s.stripe.max_search_distance_m = st.get_double("max_search_distance_m", 0.01, 10);
  if (st.has("min_track_speed")) s.stripe.min_track_speed = st.get_double("min_track_speed", 0.0, 0.1);
  if (st.has("occlusion_min_segment_px"))
    s.stripe.occlusion_min_segment_px = st.get_double("occlusion_min_segment_px", 0.0, 10000.0);
  s.stripe.compensate_capture_delay = st.get<bool>("compensate_capture_delay");
  if (st.has("track_lost_frames")) s.stripe.track_lost_frames = st.get_int("track_lost_frames", 0, 1000);
  return s;
}

Eigen::Isometry3d camera_in_tcp_from_urdf(const std::string& urdf_path, const std::string& tcp_link,
                                          const std::string& camera_link) {
  const ArmKinematics kin = ArmKinematics::from_urdf_file(urdf_path, "base", tcp_link);
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(kin.num_joints());
  return kin.tip_pose(q).inverse() * kin.frame_pose(q, camera_link);
}

VisualServoNode::VisualServoNode(const VisualServoSettings& settings)
    : Component("visual_servo", "ibvs_corner_pbvs_stripe"),
      settings_(settings),
      session_(HandEyeGeometry(settings.camera,
                               camera_in_tcp_from_urdf(settings.urdf_path, settings.tcp_link, settings.camera_link)),
               settings.session, settings.corner, settings.stripe) {
  subscribe(settings_.servo_request_channel, &VisualServoNode::on_request);
  subscribe(settings_.arm_state_channel, &VisualServoNode::on_arm_state);
  subscribe(settings_.book_features_channel, &VisualServoNode::on_book);
  subscribe(settings_.stripe_features_channel, &VisualServoNode::on_stripe);
}

void VisualServoNode::emit(const SessionOutput& out) {
  for (const ServoCommand& c : out.commands) {
    arm_command_t m;
    m.utime = c.utime;
    m.command_id = ++command_id_;
    m.mode = c.stop ? arm_command_t::STOP : arm_command_t::CARTESIAN_VELOCITY;
    m.trajectory = joint_trajectory_t();
    for (int i = 0; i < 6; ++i) m.twist[i] = c.stop ? 0.0 : c.twist(i);
    m.twist_frame = "gripper";
    publish(settings_.arm_command_channel, m);
  }
  for (const ServoReport& r : out.reports) {
    servo_status_t m{};
    m.utime = r.utime;
    m.request_id = r.request_id;
    m.mode = static_cast<int8_t>(r.mode);
    m.state = static_cast<int8_t>(r.state);
    m.iterations = r.iterations;
    m.error_px[0] = r.error_px.x();
    m.error_px[1] = r.error_px.y();
    m.slope_error_rad = r.slope_error_rad;
    m.converged_pose = r.converged_pose ? isometry_to_pose(*r.converged_pose, "base", "gripper", r.utime)
                                        : isometry_to_pose(Eigen::Isometry3d::Identity(), "", "", r.utime);
    m.corner_triangulated = r.corner.has_value();
    for (int i = 0; i < 3; ++i) m.corner_base[i] = r.corner ? r.corner->point(i) : 0.0;
    m.corner_baseline_m = r.corner ? r.corner->baseline_m : 0.0;
    m.corner_rms_px = r.corner ? r.corner->rms_px : 0.0;
    m.front_width_m = r.front_width_m;
    m.neighbour_offset_m = r.neighbour_offset_m;
    m.neighbour_width_m = r.neighbour_width_m;
    m.message = r.message;
    publish(settings_.servo_status_channel, m);
  }
}

void VisualServoNode::on_request(const servo_request_t& msg) {
  ServoRequest r;
  r.utime = msg.utime;
  r.request_id = msg.request_id;
  if (msg.mode == servo_request_t::CANCEL) {
    r.mode = ServoMode::kCancel;
  } else if (msg.mode == servo_request_t::BOOK_CORNER) {
    r.mode = ServoMode::kBookCorner;
  } else if (msg.mode == servo_request_t::STRIPE_END) {
    r.mode = ServoMode::kStripeEnd;
  } else {
    reject(settings_.servo_request_channel,
           "unknown mode " + std::to_string(msg.mode) + " (CANCEL 0, BOOK_CORNER 1, STRIPE_END 2)");
    return;
  }
  if (!std::isfinite(msg.fixed_depth_m) || !std::isfinite(msg.timeout_s) || msg.rank_from_right < 0) {
    reject(settings_.servo_request_channel, "fixed_depth_m / timeout_s not finite or rank_from_right < 0");
    return;
  }
  if (!msg.start_pose.frame.empty()) {
    if (msg.start_pose.frame != "base") {
      reject(settings_.servo_request_channel,
             "start_pose.frame must be 'base' (or empty for 'where the arm is'), got '" + msg.start_pose.frame + "'");
      return;
    }
    if (!is_valid_pose(msg.start_pose)) {
      reject(settings_.servo_request_channel, "start_pose is not a valid rigid transform (NaN or zero quaternion)");
      return;
    }
    r.start_pose = pose_to_isometry(msg.start_pose);
  }
  r.standoff_m = msg.fixed_depth_m;
  r.rank_from_right = msg.rank_from_right;
  r.timeout_s = msg.timeout_s;
  emit(session_.on_request(r));
}

void VisualServoNode::on_arm_state(const arm_state_t& msg) {
  if (!is_valid_pose(msg.end_effector)) {
    reject(settings_.arm_state_channel, "end_effector pose is not a valid rigid transform");
    return;
  }
  ArmCondition c = ArmCondition::kIdle;
  if (msg.state == arm_state_t::EXECUTING) c = ArmCondition::kExecuting;
  if (msg.state == arm_state_t::STOPPED) c = ArmCondition::kStopped;
  if (msg.state == arm_state_t::FAULT) c = ArmCondition::kFault;
  emit(session_.on_arm_state(msg.utime, pose_to_isometry(msg.end_effector), c, msg.message));
}

void VisualServoNode::on_book(const book_features_hand_t& msg) {
  BookObservation o;
  o.utime = msg.utime;
  o.found = msg.found;
  o.failure_reason = msg.failure_reason;
  o.rank_from_right = msg.rank_from_right;
  o.r_px = Eigen::Vector2d(msg.r_px[0], msg.r_px[1]);
  o.slope_rad = msg.slope_rad;
  o.width_px = std::isfinite(msg.book_width_px) ? msg.book_width_px : 0.0;
  std::vector<ForeEdgeCandidate> candidates;
  for (const auto& c : msg.candidates) candidates.push_back({c.corner_r_px[0], c.width_px, c.accepted != 0});
  if (msg.found) set_next_fore_edge(candidates, &o);
  if (msg.found && (!o.r_px.allFinite() || !std::isfinite(o.slope_rad))) {
    reject(settings_.book_features_channel, "found=true but r_px or slope_rad is not finite");
    return;
  }
  emit(session_.on_book(o));
}

void VisualServoNode::on_stripe(const stripe_features_t& msg) {
  StripeObservation o;
  o.found = msg.found;
  o.end_found = msg.end_found;
  o.end_px = Eigen::Vector2d(msg.end_px[0], msg.end_px[1]);
  o.line_start_px = Eigen::Vector2d(msg.centre_line_px[0], msg.centre_line_px[1]);
  o.line_end_px = Eigen::Vector2d(msg.centre_line_px[2], msg.centre_line_px[3]);
  if ((msg.end_found && !o.end_px.allFinite()) ||
      (msg.found && (!o.line_start_px.allFinite() || !o.line_end_px.allFinite()))) {
    reject(settings_.stripe_features_channel, "found/end_found set but the pixel coordinates are not finite");
    return;
  }
  emit(session_.on_stripe(msg.utime, o, msg.failure_reason));
}

}  // namespace bookgrasp
