#include "services/arbiter/arbiter_node.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "common/grasp_frame.h"
#include "common/pose_conversion.h"

namespace bookgrasp {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

/// Two stripe ends this near (base, m) are the same book's: the stripe servo measures one end again within ~0.2 mm
/// (far_cart seed 5144), the next book's lies a book's width (>= 12 mm) away.
constexpr double kSameStripeEndM = 0.003;

bool same_stripe_end(const std::optional<Eigen::Vector3d>& remembered, const Eigen::Vector3d& ps) {
  return remembered && (*remembered - ps).norm() <= kSameStripeEndM;
}

std::string mm(double metres) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.1f mm", metres * 1000.0);
  return buf;
}

std::string mm3(const Eigen::Vector3d& p) {
  char buf[96];
  std::snprintf(buf, sizeof(buf), "(%.1f, %.1f, %.1f) mm", p.x() * 1000, p.y() * 1000, p.z() * 1000);
  return buf;
}

void put(double (&dst)[3], const Eigen::Vector3d& v) {
  for (int i = 0; i < 3; ++i) dst[i] = v[i];
}

void put_nan(double (&dst)[3]) {
  for (double& d : dst) d = kNan;
}

validation_step_t to_msg(const ValidationStep& s, int64_t utime) {
  validation_step_t m;
  m.utime = utime;
  m.rule = s.rule;
  m.value_m = s.value;
  m.tolerance_m = s.tolerance;
  m.passed = s.passed;
  m.decision = s.decision;
  return m;
}

bool finite3(const double (&v)[3]) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

}  // namespace

ArbiterSettings ArbiterSettings::from_config(const Config& root) {
  ArbiterSettings s;
  const Config ch = root.child("channels");
  s.channels.book_corner_stereo = ch.get<std::string>("book_corner_stereo");
  s.channels.servo_status = ch.get<std::string>("servo_status");
  s.channels.servo_request = ch.get<std::string>("servo_request");
  s.channels.markers = ch.get<std::string>("markers");
  s.channels.arm_state = ch.get<std::string>("arm_state");
  s.channels.detector_switch = ch.get<std::string>("detector_switch");
  s.channels.grasp_point = ch.get<std::string>("grasp_point");
  s.follow_logical_channel = root.get<std::string>("follow.logical_channel");
  s.follow_implementation = root.get<std::string>("follow.implementation");
  if (s.follow_implementation.empty())
    throw ConfigError(root.source() + ": " + root.path_of("follow.implementation") +
                      " is empty: name the BOOK_CORNER_STEREO implementation to follow (e.g. god)");
  s.tolerances.p1_ps_y = root.get_double("tolerances.p1_ps_y_m", 0.0001, 0.2);
  s.tolerances.y = root.get_double("tolerances.y_m", 0.0001, 0.2);
  s.tolerances.x = root.get_double("tolerances.x_m", 0.0001, 0.2);
  s.tolerances.max_rank = root.get_int("tolerances.max_rank", 1, 50);
  s.tolerances.p1_over_other_book = root.get<bool>("tolerances.p1_over_other_book");
  s.tolerances.p1_p2_agreement_over_ps = root.get<bool>("tolerances.p1_p2_agreement_over_ps");
  s.tolerances.invalid_p1_depth_range = root.get_double("tolerances.invalid_p1_depth_range_m", 0.0, 0.36);
  s.tolerances.use_hand_corner = root.get<bool>("hand_corner.enabled");
  s.tolerances.hand_corner_max_y_from_p2 = root.get_double("hand_corner.max_y_from_p2_m", 0.0, 0.1);
  s.tolerances.p2_ps_y = root.get_double("tolerances.p2_measured_ps_y_m", 0.0, 0.2);
  s.tolerances.raised_bwh_start_x = root.get_double("tolerances.raised_bwh_start_m", 0.0, 0.3);
  s.tolerances.raise_over_neighbour_corner = root.get<bool>("tolerances.raise_over_neighbour_corner");
  s.tolerances.invalid_p1_over_p2 = root.get<bool>("tolerances.invalid_p1_over_p2");
  s.tolerances.start_from_p1_right_of_measured_ps = root.get<bool>("tolerances.start_from_p1_right_of_measured_ps");
  s.use_stereo_front = root.get<bool>("stereo_front.enabled");
  const std::vector<double> band = root.get_vector("stereo_front.probe_left_of_ps_m", 2);
  if (!(band[0] >= 0 && band[0] < band[1] && band[1] <= 0.1))
    throw ConfigError(root.source() + ": " + root.path_of("stereo_front.probe_left_of_ps_m") +
                      " must be [near, far] with 0 <= near < far <= 0.1 (metres left of PS)");
  s.stereo_front.near_left = band[0];
  s.stereo_front.far_left = band[1];
  s.stereo_front.max_tilt = root.get_double("stereo_front.max_tilt_deg", 0.0, 89.0) * M_PI / 180.0;
  s.stereo_front.min_top = root.get_double("stereo_front.min_top_m", -0.1, 0.5);
  const std::vector<double> zr = root.get_vector("stereo_front.depth_range_m", 2);
  if (!(std::isfinite(zr[0]) && std::isfinite(zr[1]) && zr[0] < zr[1]))
    throw ConfigError(root.source() + ": " + root.path_of("stereo_front.depth_range_m") +
                      " must be [min, max] with min < max (grasp-frame Z, metres)");
  s.stereo_front.min_z = zr[0];
  s.stereo_front.max_z = zr[1];
  s.size_limits.l_max = root.get_double("gripper.l_max_m", 0.005, 0.5);
  s.size_limits.tcp_offset_y =
      root.get_double("gripper.tcp_offset_y_m", -s.size_limits.l_max / 2, s.size_limits.l_max / 2);
  s.cart_marker_role = root.get<std::string>("cart.marker_role");
  const std::vector<double> o = root.get_vector("cart.grasp_origin_in_marker_m", 3);
  s.grasp_origin_in_marker = Eigen::Vector3d(o[0], o[1], o[2]);
  if (!s.grasp_origin_in_marker.allFinite() || s.grasp_origin_in_marker.norm() > 5.0)
    throw ConfigError(root.source() + ": " + root.path_of("cart.grasp_origin_in_marker_m") +
                      " must be finite and within 5 m of the marker");
  s.book_front_z = root.get_double("cart.book_front_z_m", -1.0, 1.0);
  s.align_with_book_slope = root.get<bool>("gp.align_with_book_slope");
  s.max_slope_rad = root.get_double("gp.max_slope_deg", 0.0, 45.0) * M_PI / 180.0;
  s.width_settle_s = root.get_double("book_width.settle_s", 0.0, 10.0);
  s.width_settle_tolerance = root.get_double("book_width.settle_tolerance_m", 0.00001, 0.01);
  s.width_open_margin = root.get_double("book_width.open_margin_m", 0.0, 0.05);
  s.width_abandon_open = root.get_double("book_width.abandoned_open_m", 0.0005, 0.05);
  s.width_abandon_within = root.get_double("book_width.abandoned_within_m", 0.001, 0.5);
  s.p1_arm_still_s = root.get_double("p1.arm_still_s", 0.0, 60.0);
  s.p1_arm_still_joint_speed = root.get_double("p1.arm_still_joint_speed_rad_s", 0.0001, 10.0);
  return s;
}

ArbiterNode::ArbiterNode(const Config& root)
    : ArbiterNode(root.get<std::string>("service.name"), root.get<std::string>("service.implementation"),
                  ArbiterSettings::from_config(root)) {}

ArbiterNode::ArbiterNode(const std::string& service, const std::string& implementation, ArbiterSettings settings)
    : Component(service, implementation), s_(std::move(settings)), follow_(s_.follow_implementation) {
  subscribe(s_.channels.book_corner_stereo, &ArbiterNode::on_book_corner);
  subscribe(s_.channels.servo_status, &ArbiterNode::on_servo_status);
  subscribe(s_.channels.servo_request, &ArbiterNode::on_servo_request);
  subscribe(s_.channels.markers, &ArbiterNode::on_markers);
  subscribe(s_.channels.arm_state, &ArbiterNode::on_arm_state);
  subscribe(s_.channels.detector_switch, &ArbiterNode::on_switch);
}

Eigen::Vector3d ArbiterNode::to_grasp(const Eigen::Vector3d& p_base) const { return frame_->inverse() * p_base; }
Eigen::Vector3d ArbiterNode::to_base(const Eigen::Vector3d& p_grasp) const { return *frame_ * p_grasp; }

void ArbiterNode::open_attempt() {
  frozen_ = false;
  frozen_p1_.reset();
  frozen_regions_.clear();
  attempt_check_dy_.reset();
}

void ArbiterNode::on_markers(const marker_detections_t& msg) {
  for (const marker_t& m : msg.markers) {
    if (m.role != s_.cart_marker_role) continue;
    if (!is_valid_pose(m.pose_in_base)) {
      reject(s_.channels.markers, "cart marker " + std::to_string(m.id) + " has an invalid pose_in_base (NaN or not a unit quaternion)");
      return;
    }
    const Eigen::Isometry3d t = pose_to_isometry(m.pose_in_base);
    // AprilTag frame: z points into the tag, i.e. into the cart's rear board.
    Eigen::Isometry3d g;
    try {
      g = grasp_frame_in_base(t.linear().col(2), Eigen::Vector3d::Zero());
    } catch (const std::invalid_argument& e) {
      reject(s_.channels.markers, std::string("cart marker is not upright (its normal is vertical): ") + e.what());
      return;
    }
    g.translation() = t.translation() + g.linear() * s_.grasp_origin_in_marker;
    frame_ = g;
    return;
  }
}

void ArbiterNode::on_switch(const detector_switch_t& msg) {
  if (msg.logical_channel != s_.follow_logical_channel) return;
  if (msg.implementation.empty()) {
    reject(s_.channels.detector_switch, "switch for " + msg.logical_channel + " names no implementation");
    return;
  }
  const std::string before = follow_;
  follow_ = msg.implementation;
  switch_note_ = "switched from '" + before + "' at utime " + std::to_string(msg.utime) +
                 (msg.reason.empty() ? "" : " (" + msg.reason + ")");
  // A P1 of the previous implementation is not used for a new attempt.
  if (!frozen_) {
    latest_p1_.reset();
    have_p1_msg_ = false;
  }
  // Visible in SERVICE_STATUS.last_error (the runtime has no other free-text field).
  report_error("detector switch: now following " + s_.follow_logical_channel + " implementation '" + follow_ +
               "', " + switch_note_);
}

void ArbiterNode::on_book_corner(const book_corner_stereo_t& msg) {
  if (msg.implementation != follow_) return;  // another implementation: not followed now
  if (msg.found && !finite3(msg.p1_base)) {
    reject(s_.channels.book_corner_stereo, "found = true but p1_base is not finite");
    return;
  }
  if (s_.p1_arm_still_s > 0 && last_arm_motion_utime_ &&
      double(msg.utime - *last_arm_motion_utime_) < s_.p1_arm_still_s * 1e6) {
    ++p1_skipped_arm_moving_;  // the arm moved at or just before this frame: it may be in the view
    return;
  }
  have_p1_msg_ = true;
  latest_regions_ = msg.regions;
  if (msg.found)
    latest_p1_ = Eigen::Vector3d(msg.p1_base[0], msg.p1_base[1], msg.p1_base[2]);
  else
    latest_p1_.reset();
  if (!frozen_) publish_p1_check(msg.utime, 0);
}

void ArbiterNode::on_servo_request(const servo_request_t& msg) {
  if (msg.mode != servo_request_t::CANCEL && msg.mode != servo_request_t::BOOK_CORNER &&
      msg.mode != servo_request_t::STRIPE_END) {
    reject(s_.channels.servo_request, "unknown servo mode " + std::to_string(static_cast<int>(msg.mode)));
    return;
  }
  if (msg.mode == servo_request_t::CANCEL) {
    open_attempt();
    return;
  }
  if (msg.mode == servo_request_t::BOOK_CORNER && msg.rank_from_right < 0) {
    reject(s_.channels.servo_request, "rank_from_right " + std::to_string(msg.rank_from_right) + " is negative");
    return;
  }
  if (!frozen_) {
    frozen_ = true;
    frozen_p1_ = latest_p1_;
    frozen_regions_ = latest_regions_;
  }
  if (msg.mode == servo_request_t::BOOK_CORNER) {
    // The coordinator started BwH where the last P1 check said: if that check judged the attempt's P1, its
    // verdict holds for the attempt's decisions.
    if (!attempt_check_dy_ && last_check_ && frozen_p1_ && ps_ && last_check_->p1_base == *frozen_p1_ &&
        last_check_->ps_base == *ps_)
      attempt_check_dy_ = last_check_->dy;
    rank_of_request_[msg.request_id] = msg.rank_from_right;
    while (rank_of_request_.size() > 64) rank_of_request_.erase(rank_of_request_.begin());
  }
}

void ArbiterNode::on_servo_status(const servo_status_t& msg) {
  if (msg.mode != servo_request_t::BOOK_CORNER && msg.mode != servo_request_t::STRIPE_END) return;
  const bool converged = msg.state == servo_status_t::CONVERGED;
  const bool failed = msg.state == servo_status_t::FEATURE_LOST || msg.state == servo_status_t::TIMEOUT ||
                      msg.state == servo_status_t::FAILED;
  if (!converged && !failed) return;
  if (converged && !is_valid_pose(msg.converged_pose)) {
    reject(s_.channels.servo_status, "CONVERGED status of request " + std::to_string(msg.request_id) +
                                         " has an invalid converged_pose (NaN or not a unit quaternion)");
    return;
  }
  if (msg.request_id == last_decided_request_) return;  // repeated status of a request already answered
  if (msg.mode == servo_request_t::STRIPE_END) {
    if (!converged) return;  // the coordinator handles a failed stripe servo
    last_decided_request_ = msg.request_id;
    const pose_t& p = msg.converged_pose;
    ps_ = Eigen::Vector3d(p.position[0], p.position[1], p.position[2]);
    ps_measured_ = true;
    publish_p1_check(msg.utime, msg.request_id);
    return;
  }
  decide(msg);
}

grasp_point_t ArbiterNode::base_message(int64_t utime, int64_t request_id) const {
  grasp_point_t m;
  m.utime = utime;
  m.request_id = request_id;
  m.valid = false;
  put_nan(m.gp_grasp);
  put_nan(m.p1_grasp);
  put_nan(m.p2_grasp);
  put_nan(m.ps_grasp);
  m.gp_base = isometry_to_pose(Eigen::Isometry3d::Identity(), "base", "gripper", utime);
  m.slope_rad = 0;
  m.p1_used = false;
  m.p2_used = false;
  m.num_steps = 0;
  return m;
}

namespace {
void finish(grasp_point_t* m, const std::string& follow, const std::string& switch_note) {
  validation_step_t src;
  src.utime = m->utime;
  src.rule = "P1 source";
  src.value_m = 0;
  src.tolerance_m = 0;
  src.passed = true;
  src.decision = "BOOK_CORNER_STEREO implementation '" + follow + "'" + (switch_note.empty() ? "" : ", " + switch_note);
  m->steps.insert(m->steps.begin(), src);
  m->num_steps = static_cast<int32_t>(m->steps.size());
  m->reason += " [P1 from '" + follow + "']";
}
}  // namespace

void ArbiterNode::publish_p1_check(int64_t utime, int64_t request_id) {
  last_check_.reset();
  if (!frame_) {
    report_error("P1 check skipped: no cart marker seen yet, the grasp frame is unknown");
    return;
  }
  grasp_point_t m = base_message(utime, request_id);
  const std::optional<Eigen::Vector3d>& p1b = frozen_ ? frozen_p1_ : latest_p1_;
  std::optional<Eigen::Vector3d> p1;
  if (p1b) p1 = to_grasp(*p1b);
  if (p1) put(m.p1_grasp, *p1);
  if (!ps_) {
    m.reason = "NEED_PS: no PS known (first run or arbiter restarted): run BSwH to the stripe end";
    m.steps.push_back(to_msg({"PS", kNan, kNan, false, "no PS to validate P1 against"}, utime));
    finish(&m, follow_, switch_note_);
    publish(s_.channels.grasp_point, m);
    return;
  }
  const CombinationInputs in = common_inputs();
  put(m.ps_grasp, in.ps);
  if (p1b && in.p1->allFinite()) last_check_ = P1Check{*p1b, *ps_, in.p1->y() - in.ps.y()};
  const CombinationResult r = validate_p1(in, s_.tolerances);
  for (const ValidationStep& st : r.steps) m.steps.push_back(to_msg(st, utime));
  if (!r.p1_valid) {  // the depth the corner servo assumes (GP.z will take the same), as gp_grasp's Z
    ValidationStep z_step = r.front_depth_step;
    z_step.rule = "front depth for BwH";
    m.steps.push_back(to_msg(z_step, utime));
  }
  m.p1_used = r.p1_valid;
  put(m.gp_grasp, r.bwh_start);
  Eigen::Isometry3d start = *frame_;
  start.translation() = to_base(r.bwh_start);
  m.gp_base = isometry_to_pose(start, "base", "gripper", utime);
  m.reason = std::string(r.p1_valid ? "P1_VALID: " : "P1_INVALID: ") +
             (r.steps.empty() ? std::string("") : r.steps.back().decision);
  if (!r.p1_valid) m.reason += "; servo front depth " + mm(r.bwh_start.z());
  finish(&m, follow_, switch_note_);
  publish(s_.channels.grasp_point, m);
}

void ArbiterNode::decide(const servo_status_t& msg) {
  last_decided_request_ = msg.request_id;
  grasp_point_t m = base_message(msg.utime, msg.request_id);
  const bool converged = msg.state == servo_status_t::CONVERGED;
  if (!frame_ || !ps_) {
    m.reason = !frame_ ? "NO_GRASP: no cart marker seen: the grasp frame is unknown"
                       : "NO_GRASP: no PS known: run BSwH to the stripe end first";
    m.steps.push_back(to_msg({"inputs", kNan, kNan, false, m.reason.substr(10)}, msg.utime));
    finish(&m, follow_, switch_note_);
    publish(s_.channels.grasp_point, m);
    open_attempt();
    return;
  }
  CombinationInputs in = common_inputs();
  in.p1_ps_dy_at_bwh_start = attempt_check_dy_;
  const auto rank_it = rank_of_request_.find(msg.request_id);
  in.p2_rank = rank_it == rank_of_request_.end() ? 0 : rank_it->second;
  double slope = 0;
  if (converged) {
    const Eigen::Isometry3d p2 = pose_to_isometry(msg.converged_pose);
    in.p2 = to_grasp(p2.translation());
    put(m.p2_grasp, *in.p2);
    if (msg.corner_triangulated)
      in.hand_corner = to_grasp(Eigen::Vector3d(msg.corner_base[0], msg.corner_base[1], msg.corner_base[2]));
    const Eigen::Vector3d xg = frame_->linear().transpose() * p2.linear().col(0);
    slope = std::atan2(xg.y(), xg.x());
  }
  if (in.p1) put(m.p1_grasp, *in.p1);
  put(m.ps_grasp, in.ps);
  m.slope_rad = slope;

  CombinationResult r = combine(in, s_.tolerances);
  if (!converged && !r.steps.empty())
    r.steps.back().decision += " (servo state " + std::to_string(static_cast<int>(msg.state)) +
                               (msg.message.empty() ? "" : ": " + msg.message) + ")";
  m.p1_used = r.p1_valid;
  const std::string last = r.steps.empty() ? std::string("") : r.steps.back().decision;
  switch (r.outcome) {
    case GraspOutcome::kGrasp: {
      Eigen::Matrix3d rot = frame_->linear();
      const bool use_slope = s_.align_with_book_slope && std::abs(slope) <= s_.max_slope_rad;
      if (use_slope) rot = rot * Eigen::AngleAxisd(slope, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      r.steps.push_back({"GP slope", slope, s_.max_slope_rad, use_slope || !s_.align_with_book_slope,
                         !s_.align_with_book_slope ? "GP keeps the grasp-frame orientation (alignment off)"
                         : use_slope ? "gripper aligned with the book slope from BwH"
                                     : "servo slope beyond gp.max_slope_deg: not trusted, grasp-frame orientation kept"});
      Eigen::Isometry3d gp = Eigen::Isometry3d::Identity();
      gp.linear() = rot;
      gp.translation() = to_base(r.gp);
      m.gp_base = isometry_to_pose(gp, "base", "gripper", msg.utime);
      put(m.gp_grasp, r.gp);
      m.valid = true;
      m.p2_used = true;
      m.reason = "GRASP: GP = " + mm3(r.gp) + " in the grasp frame (" + (r.p1_valid ? "P1 valid" : "P1 not used") + ")";
      width_pending_ = true;
      width_request_ = msg.request_id;
      last_gp_grasp_ = r.gp;
      last_ps_grasp_ = in.ps;
      corner_at_ps_.reset();
      if (r.hand_corner_used) corner_at_ps_ = CornerAtPs{*ps_, in.hand_corner->z()};
      last_frame_ = *frame_;
      settle_start_utime_ = -1;
      open_attempt();
      break;
    }
    case GraspOutcome::kNextRegion:
      m.reason = "NEXT_REGION rank " + std::to_string(r.next_rank) + ": " + last;
      break;
    case GraspOutcome::kP1LedAstray:
      m.reason = "P1_LED_ASTRAY: " + last;
      p1_astray_at_ps_ = ps_;
      open_attempt();
      break;
    case GraspOutcome::kRaiseBwhStart:
      m.reason = "RAISE_BWH_START: " + last;
      raised_at_ps_ = ps_;
      raised_over_corner_ = to_base(*in.p2);
      open_attempt();
      break;
    case GraspOutcome::kStartFromP1:
      m.reason = "START_FROM_P1: " + last;
      p1_between_at_ps_ = ps_;
      open_attempt();
      break;
    case GraspOutcome::kNoGrasp:
      m.reason = "NO_GRASP: " + last;
      if (!in.p2 && bwh_started_from_p1_right_of_ps(r)) p1_right_failed_at_ps_ = ps_;
      open_attempt();
      break;
  }
  for (const ValidationStep& st : r.steps) m.steps.push_back(to_msg(st, msg.utime));
  finish(&m, follow_, switch_note_);
  publish(s_.channels.grasp_point, m);
}

CombinationInputs ArbiterNode::common_inputs() const {
  CombinationInputs in;
  const std::optional<Eigen::Vector3d>& p1b = frozen_ ? frozen_p1_ : latest_p1_;
  if (p1b) in.p1 = to_grasp(*p1b);
  in.ps = to_grasp(*ps_);
  in.ps_measured = ps_measured_;
  in.p1_led_astray = same_stripe_end(p1_astray_at_ps_, *ps_);
  in.bwh_start_raised = same_stripe_end(raised_at_ps_, *ps_);
  if (in.bwh_start_raised && raised_over_corner_) in.neighbour_corner_x = to_grasp(*raised_over_corner_).x();
  in.p1_between = same_stripe_end(p1_between_at_ps_, *ps_);
  in.p1_right_start_failed = same_stripe_end(p1_right_failed_at_ps_, *ps_);
  if (corner_at_ps_ && corner_at_ps_->ps == *ps_) in.earlier_corner_z = corner_at_ps_->z;
  in.front_z_fallback = s_.book_front_z;
  in.stereo_front_z = stereo_front_z(in.ps);
  return in;
}

std::optional<double> ArbiterNode::stereo_front_z(const Eigen::Vector3d& ps_grasp) const {
  if (!s_.use_stereo_front || !frame_) return std::nullopt;
  const std::vector<plane_region_t>& regions = frozen_ ? frozen_regions_ : latest_regions_;
  const Eigen::Matrix3d to_grasp_axes = frame_->linear().transpose();
  std::vector<FrontPlane> planes;
  planes.reserve(regions.size());
  for (const plane_region_t& g : regions) {
    // A region with a non-finite field is no plane to measure (and would leave a box of its finite corners).
    if (!finite3(g.normal_base) || !std::isfinite(g.offset_m) || !finite3(g.extent_min_base) ||
        !finite3(g.extent_max_base))
      continue;
    FrontPlane p;
    const Eigen::Vector3d n(g.normal_base[0], g.normal_base[1], g.normal_base[2]);
    p.normal = to_grasp_axes * n;
    p.offset = g.offset_m - n.dot(frame_->translation());  // n . (R p_g + t) = offset
    const Eigen::Vector3d lo(g.extent_min_base[0], g.extent_min_base[1], g.extent_min_base[2]);
    const Eigen::Vector3d hi(g.extent_max_base[0], g.extent_max_base[1], g.extent_max_base[2]);
    p.min = Eigen::Vector3d::Constant(INFINITY);
    p.max = Eigen::Vector3d::Constant(-INFINITY);
    for (int c = 0; c < 8; ++c) {  // the base box's corners in the grasp frame, then their box
      const Eigen::Vector3d corner((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(), (c & 4) ? hi.z() : lo.z());
      const Eigen::Vector3d q = to_grasp(corner);
      p.min = p.min.cwiseMin(q);
      p.max = p.max.cwiseMax(q);
    }
    p.pixels = g.pixel_count;
    planes.push_back(p);
  }
  return front_depth_left_of(planes, ps_grasp, s_.stereo_front);
}

void ArbiterNode::on_arm_state(const arm_state_t& msg) {
  if (!std::isfinite(msg.gripper_width_m)) {
    reject(s_.channels.arm_state, "gripper_width_m is not finite");
    return;
  }
  bool moving = msg.state == arm_state_t::EXECUTING;
  for (double v : msg.velocities) moving = moving || !(std::abs(v) <= s_.p1_arm_still_joint_speed);
  if (moving && (!last_arm_motion_utime_ || msg.utime > *last_arm_motion_utime_)) last_arm_motion_utime_ = msg.utime;
  if (width_taken_) {
    const Eigen::Vector3d tcp = pose_to_isometry(msg.end_effector).translation();
    if ((tcp - width_taken_->tcp).norm() > s_.width_abandon_within) {
      width_taken_.reset();  // the book left with the TCP: BW stands
    } else if (msg.gripper_width_m > width_taken_->bw + s_.width_abandon_open) {
      // The plates opened where they closed: the grasp was given up (the coordinator backs out), so the book is still
      // on the shelf and PS goes back.
      ps_ = width_taken_->ps_before;
      ps_measured_ = width_taken_->ps_before_measured;
      grasp_point_t m = base_message(msg.utime, width_taken_->request_id);
      if (ps_) put(m.ps_grasp, last_frame_.inverse() * *ps_);
      m.valid = false;
      m.reason = "PS_RESTORED: the plates opened to " + mm(msg.gripper_width_m) + " where they had closed to " +
                 mm(width_taken_->bw) + ": the grasp was given up, PS is the one before that BW";
      width_taken_.reset();
      finish(&m, follow_, switch_note_);
      publish(s_.channels.grasp_point, m);
    }
  }
  if (!width_pending_) return;
  // The width is read while the arm executes no motion (the plates close on the book after the insertion); during
  // one, a plate touching a neighbour on the way in is not a grasp (far_cart seed 2003: 36.7 mm taken as the width
  // of an 18 mm book while the narrowed plates went in). Not the joint speeds: the arm still settles from the
  // insertion while the plates close, and the coordinator's own settle then ended the close first, so no width was
  // read at all.
  if (msg.state == arm_state_t::EXECUTING || !msg.gripper_contact || msg.gripper_width_m <= 0) {
    settle_start_utime_ = -1;
    return;
  }
  const double w = msg.gripper_width_m;
  if (w >= s_.size_limits.l_max - s_.width_open_margin) {  // open plates touching something: not the book yet
    settle_start_utime_ = -1;
    return;
  }
  if (settle_start_utime_ < 0 || std::abs(w - settle_start_width_) > s_.width_settle_tolerance ||
      msg.utime < settle_start_utime_) {
    settle_start_utime_ = msg.utime;
    settle_start_width_ = w;
    if (s_.width_settle_s > 0) return;
  }
  if (static_cast<double>(msg.utime - settle_start_utime_) < s_.width_settle_s * 1e6) return;

  width_pending_ = false;
  const double bw = w;
  grasp_point_t m = base_message(msg.utime, width_request_);
  const ValidationStep check = check_book_width(bw, s_.size_limits);
  m.steps.push_back(to_msg(check, msg.utime));
  put(m.gp_grasp, last_gp_grasp_);
  Eigen::Isometry3d gp = last_frame_;
  gp.translation() = last_frame_ * last_gp_grasp_;
  m.gp_base = isometry_to_pose(gp, "base", "gripper", msg.utime);
  const bool usable = bw <= s_.size_limits.l_max;
  width_taken_ = WidthTaken{width_request_, bw, pose_to_isometry(msg.end_effector).translation(), ps_, ps_measured_};
  ps_measured_ = false;
  if (usable) {
    const Eigen::Vector3d next = next_ps(last_ps_grasp_, last_gp_grasp_, bw);
    ps_ = last_frame_ * next;
    put(m.ps_grasp, next);
    m.steps.push_back(to_msg({"PS.y = GP.y - BW", next.y(), 0.0, true,
                              "next PS.y = " + mm(last_gp_grasp_.y()) + " - " + mm(bw) + " = " + mm(next.y())},
                             msg.utime));
  } else {
    ps_.reset();
    m.steps.push_back(to_msg({"PS.y = GP.y - BW", kNan, 0.0, false,
                              "plate distance beyond L_max: PS dropped, run BSwH again for the next book"},
                             msg.utime));
  }
  m.valid = check.passed;
  m.p2_used = true;
  m.reason = "BOOK_WIDTH: BW = " + mm(bw) + " from the gripper plates; " + check.decision;
  finish(&m, follow_, switch_note_);
  publish(s_.channels.grasp_point, m);
}

}  // namespace bookgrasp
