#include "services/visual_servo/servo_session.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace bookgrasp {

namespace {
int64_t seconds_to_us(double s) {
  return static_cast<int64_t>(std::llround(s * 1e6));
}
std::string fmt(const char* f, double a, double b = 0, double c = 0) {
  char buf[256];
  std::snprintf(buf, sizeof(buf), f, a, b, c);
  return buf;
}
}  // namespace

std::string servo_state_name(ServoState s) {
  switch (s) {
    case ServoState::kIdle:
      return "IDLE";
    case ServoState::kRunning:
      return "RUNNING";
    case ServoState::kConverged:
      return "CONVERGED";
    case ServoState::kFeatureLost:
      return "FEATURE_LOST";
    case ServoState::kTimeout:
      return "TIMEOUT";
    case ServoState::kFailed:
      return "FAILED";
    case ServoState::kCancelled:
      return "CANCELLED";
  }
  return "?";
}

ServoSession::ServoSession(const HandEyeGeometry& geometry, const ServoSessionParams& session,
                           const BookCornerServoParams& corner, const StripeEndServoParams& stripe)
    : geo_(geometry), p_(session), corner_(geometry, corner), stripe_(geometry, stripe) {}

ServoReport ServoSession::report(ServoState state, const std::string& message) const {
  ServoReport r;
  r.utime = now_;
  r.request_id = request_id_;
  r.mode = mode_;
  r.state = state;
  r.iterations = iterations_;
  r.error_px = error_px_;
  r.slope_error_rad = slope_error_;
  r.message = message;
  return r;
}

void ServoSession::command(const GripperTwist& twist, SessionOutput* out) {
  twist_ = twist;
  ServoCommand c;
  c.utime = now_;
  c.twist = twist;
  out->commands.push_back(c);
  last_command_utime_ = now_;
}

void ServoSession::finish(ServoState state, const std::string& message, SessionOutput* out,
                          const std::optional<Eigen::Isometry3d>& pose) {
  if (!running_) return;
  running_ = false;
  twist_.setZero();
  ServoCommand c;
  c.utime = now_;
  c.stop = true;
  c.reason = "visual_servo: " + servo_state_name(state) + ": " + message;
  out->commands.push_back(c);
  ServoReport r = report(state, message);
  r.converged_pose = pose;
  out->reports.push_back(r);
}

std::optional<Eigen::Isometry3d> ServoSession::pose_at(int64_t utime) const {
  if (history_.empty()) return std::nullopt;
  // The last pose at or before `utime`; the oldest one if all are later.
  for (auto it = history_.rbegin(); it != history_.rend(); ++it)
    if (it->first <= utime) return it->second;
  return history_.front().second;
}

void ServoSession::advance(int64_t utime, SessionOutput* out) {
  if (utime > now_) now_ = utime;
  if (!running_) return;
  if (now_ >= deadline_utime_) {
    finish(ServoState::kTimeout,
           fmt("no convergence within %.2f s (message time) after %.0f iterations",
               (deadline_utime_ - start_utime_) * 1e-6, iterations_),
           out);
    return;
  }
  // Times since the last good measurement ARRIVED (message time), not since its image was taken: the
  // camera -> detector pipeline of separate processes has a latency (0.05-0.25 s on a quiet machine,
  // ~0.7 s when it is loaded); the stripe servo's law subtracts the motion since capture. Until
  // the first image taken after the start has arrived, the pose history's length is allowed on top.
  const double since_good = (now_ - last_good_utime_) * 1e-6;
  const double lost_limit_s = p_.feature_lost_timeout_s + (measured_since_start_ ? 0.0 : p_.pose_history_s);
  if (now_ - last_good_utime_ > seconds_to_us(lost_limit_s)) {
    std::string why;
    if (!last_lost_reason_.empty())
      why = last_lost_reason_;
    else if (measured_since_start_)
      why = fmt("no feature measurement arrived for %.2f s (camera or detector stalled or too slow?)", since_good);
    else
      why =
          fmt("no feature measurement of an image taken after the start arrived within %.2f s "
              "(camera or detector down or too slow?)",
              lost_limit_s);
    finish(ServoState::kFeatureLost,
           fmt("feature lost for %.2f s (feature_lost_timeout_s %.2f): ", since_good, p_.feature_lost_timeout_s) + why,
           out);
    return;
  }
  const bool stale = now_ - last_good_utime_ > seconds_to_us(p_.stale_feature_s);
  if (stale && !holding_) {
    holding_ = true;
    command(GripperTwist::Zero(), out);
    return;
  }
  if (last_command_utime_ == INT64_MIN || now_ - last_command_utime_ >= seconds_to_us(p_.command_period_s))
    command(stale ? GripperTwist::Zero() : twist_, out);
}

SessionOutput ServoSession::on_request(const ServoRequest& request) {
  SessionOutput out;
  if (request.mode == ServoMode::kCancel) {
    if (running_) {
      finish(ServoState::kCancelled, "cancelled by request " + std::to_string(request.request_id), &out);
    } else {
      ServoReport r = report(ServoState::kIdle, "cancel: no task running");
      r.request_id = request.request_id;
      out.reports.push_back(r);
    }
    return out;
  }
  if (running_) finish(ServoState::kCancelled, "replaced by request " + std::to_string(request.request_id), &out);
  mode_ = request.mode;
  request_id_ = request.request_id;
  iterations_ = 0;
  error_px_.setZero();
  slope_error_ = 0;
  if (!have_arm_) {
    running_ = true;
    finish(ServoState::kFailed, "no ARM_STATE received yet: start the arm driver before servoing", &out);
    return out;
  }
  if (request.start_pose) {
    const double d = (request.start_pose->translation() - tcp_.translation()).norm();
    if (d > p_.max_start_error_m) {
      running_ = true;
      finish(ServoState::kFailed,
             fmt("the TCP is %.3f m from start_pose (max_start_error_m %.3f): move the arm there first (planner), "
                 "or send start_pose with an empty frame to start where it is",
                 d, p_.max_start_error_m),
             &out);
      return out;
    }
  }
  const bool corner = mode_ == ServoMode::kBookCorner;
  standoff_ = request.standoff_m > 0 ? request.standoff_m
                                     : (corner ? p_.default_corner_standoff_m : p_.default_stripe_standoff_m);
  rank_ = request.rank_from_right;
  start_utime_ = now_;
  deadline_utime_ = now_ + seconds_to_us(request.timeout_s > 0 ? request.timeout_s : p_.default_timeout_s);
  last_good_utime_ = now_;
  last_measurement_utime_ = now_;
  measured_since_start_ = false;
  last_command_utime_ = INT64_MIN;
  arm_executing_seen_ = false;
  holding_ = false;
  last_lost_reason_.clear();
  sightings_.clear();
  sighting_extents_.clear();
  start_position_ = tcp_.translation();
  twist_.setZero();
  corner_.reset();
  stripe_.reset();
  running_ = true;
  out.reports.push_back(report(ServoState::kRunning, std::string("started ") + (corner ? "BOOK_CORNER" : "STRIPE_END") +
                                                         fmt(" at standoff %.3f m", standoff_)));
  return out;
}

SessionOutput ServoSession::on_arm_state(int64_t utime, const Eigen::Isometry3d& tcp_in_base, ArmCondition condition,
                                         const std::string& arm_message) {
  SessionOutput out;
  have_arm_ = true;
  tcp_ = tcp_in_base;
  history_.emplace_back(utime, tcp_in_base);
  while (!history_.empty() && history_.front().first < utime - seconds_to_us(p_.pose_history_s)) history_.pop_front();
  if (utime > now_) now_ = utime;
  if (running_) {
    if (condition == ArmCondition::kExecuting && last_command_utime_ != INT64_MIN) arm_executing_seen_ = true;
    if (condition == ArmCondition::kFault || (condition == ArmCondition::kStopped && arm_executing_seen_)) {
      finish(ServoState::kFailed, "the arm driver stopped: " + arm_message, &out);
      return out;
    }
  }
  advance(utime, &out);
  return out;
}

bool ServoSession::accept_measurement_time(int64_t utime) {
  if (!running_) return false;
  if (utime < start_utime_) return false;                                 // image taken before the task started
  if (utime <= last_measurement_utime_ && iterations_ > 0) return false;  // repeated / out of order
  last_measurement_utime_ = utime;
  measured_since_start_ = true;
  return true;
}

Eigen::Vector3d ServoSession::moved_since(int64_t capture_utime) const {
  const auto at_capture = pose_at(capture_utime);
  if (!at_capture) return Eigen::Vector3d::Zero();
  const Eigen::Matrix3d r = at_capture->linear();
  const Eigen::Vector3d d = r.transpose() * (tcp_.translation() - at_capture->translation());
  const Eigen::Matrix3d turned = r.transpose() * tcp_.linear();
  return Eigen::Vector3d(d.x(), d.y(), std::atan2(turned(1, 0), turned(0, 0)));
}

void set_next_fore_edge(const std::vector<ForeEdgeCandidate>& candidates, BookObservation* obs) {
  const double r = obs->r_px.x();
  const ForeEdgeCandidate* next = nullptr;
  for (const auto& c : candidates)
    if (c.accepted && std::isfinite(c.corner_x_px) && std::isfinite(c.width_px) && c.width_px > 0 &&
        c.corner_x_px < r - 1.0 && (!next || c.corner_x_px > next->corner_x_px))
      next = &c;
  if (!next) return;
  obs->neighbour_offset_px = r - next->corner_x_px;
  obs->neighbour_width_px = next->width_px;
}

double ServoSession::metres_at(const TriangulatedCorner& corner, double (*pixels)(const ViewExtents&)) const {
  std::vector<double> widths;
  for (size_t i : corner.agreeing) {
    if (i >= sightings_.size()) continue;
    const double depth = (sightings_[i].camera_in_base.inverse() * corner.point).z();
    const double px = pixels(sighting_extents_[i]);
    if (px > 0 && depth > 0) widths.push_back(px * depth / geo_.intrinsics().fx);
  }
  if (widths.empty()) return 0.0;
  std::nth_element(widths.begin(), widths.begin() + static_cast<long>(widths.size() / 2), widths.end());
  return widths[widths.size() / 2];
}

SessionOutput ServoSession::on_book(const BookObservation& obs) {
  SessionOutput out;
  advance(obs.utime, &out);
  if (!running_ || mode_ != ServoMode::kBookCorner) return out;
  if (obs.rank_from_right != rank_) return out;  // answers an older rank request
  if (!accept_measurement_time(obs.utime)) return out;
  if (!obs.found || !obs.r_px.allFinite() || !std::isfinite(obs.slope_rad)) {
    last_lost_reason_ = "BwH: " + (obs.failure_reason.empty() ? std::string("no book found") : obs.failure_reason);
    out.reports.push_back(report(ServoState::kRunning, "feature not seen: " + last_lost_reason_));
    return out;
  }
  const CornerServoStep s = corner_.step(obs.r_px, obs.slope_rad, standoff_, moved_since(obs.utime));
  ++iterations_;
  error_px_ = s.error_px;
  slope_error_ = s.slope_error_rad;
  last_good_utime_ = now_;  // arrival (message time), see advance()
  holding_ = false;
  const std::optional<Eigen::Isometry3d> at_capture = pose_at(obs.utime);
  if (at_capture) {
    sightings_.push_back({*at_capture * geo_.camera_in_gripper(), obs.r_px});
    sighting_extents_.push_back({obs.width_px, obs.neighbour_offset_px, obs.neighbour_width_px});
  }
  if (s.converged) {
    std::string why;
    const std::optional<TriangulatedCorner> corner =
        triangulate_corner(sightings_, geo_.intrinsics(), p_.corner_triangulation, &why);
    std::string message =
        fmt("R within %.2f px of the target (%.1f, %.1f)", s.error_px.norm(), s.target_px.x(), s.target_px.y());
    double front_width = 0, neighbour_offset = 0, neighbour_width = 0;
    if (corner) {
      const Eigen::Vector3d in_tcp = at_capture ? at_capture->inverse() * corner->point : Eigen::Vector3d::Zero();
      message += fmt("; R triangulated %.1f mm ahead of the TCP", in_tcp.z() * 1e3) +
                 fmt(" from %.0f views over %.1f mm", corner->sightings, corner->baseline_m * 1e3);
      front_width = metres_at(*corner, [](const ViewExtents& v) { return v.width_px; });
      if (front_width > 0) message += fmt("; fore-edge %.1f mm wide", front_width * 1e3);
      neighbour_offset = metres_at(*corner, [](const ViewExtents& v) { return v.neighbour_offset_px; });
      neighbour_width = metres_at(*corner, [](const ViewExtents& v) { return v.neighbour_width_px; });
      if (neighbour_offset > 0 && neighbour_width > 0)
        message +=
            fmt("; the next fore-edge %.1f mm left of R, %.1f mm wide", neighbour_offset * 1e3, neighbour_width * 1e3);
    } else {
      message += "; R not triangulated: " + why;
    }
    // P2: the pose with its TCP at R's height, i.e. the pose at capture raised by target_above_tcp_m.
    std::optional<Eigen::Isometry3d> p2 = at_capture;
    const double above = corner_.params().target_above_tcp_m;
    if (p2 && above != 0.0) {
      p2 = *p2 * Eigen::Translation3d(above, 0.0, 0.0);
      message += fmt("; P2 is the TCP raised by %.1f mm (book_corner.target_above_tcp_m)", above * 1e3);
    }
    finish(ServoState::kConverged, message, &out, p2);
    if (!out.reports.empty()) {
      out.reports.back().corner = corner;
      out.reports.back().front_width_m = front_width;
      out.reports.back().neighbour_offset_m = neighbour_offset;
      out.reports.back().neighbour_width_m = neighbour_width;
    }
    return out;
  }
  command(s.twist, &out);
  out.reports.push_back(report(ServoState::kRunning, "tracking R"));
  return out;
}

SessionOutput ServoSession::on_stripe(int64_t utime, const StripeObservation& obs, const std::string& failure_reason) {
  SessionOutput out;
  advance(utime, &out);
  if (!running_ || mode_ != ServoMode::kStripeEnd) return out;
  if (!accept_measurement_time(utime)) return out;
  const double travelled = (tcp_.translation() - start_position_).norm();
  const StripeServoStep s = stripe_.step(obs, standoff_, travelled, moved_since(utime).head<2>());
  if (s.failed) {
    finish(ServoState::kFeatureLost, s.note, &out);
    return out;
  }
  if (!s.measured) {
    last_lost_reason_ = "BSwH: " + (failure_reason.empty() ? s.note : failure_reason);
    out.reports.push_back(report(ServoState::kRunning, "feature not seen: " + last_lost_reason_));
    return out;
  }
  ++iterations_;
  error_px_ = s.error_px;
  slope_error_ = 0;
  last_good_utime_ = now_;  // arrival (message time), see advance()
  holding_ = false;
  if (s.converged) {
    finish(ServoState::kConverged,
           fmt("stripe end within (%.1f, %.1f) mm of the TCP axis", s.error_m.x() * 1e3, s.error_m.y() * 1e3), &out,
           pose_at(utime));
    return out;
  }
  command(s.twist, &out);
  out.reports.push_back(report(ServoState::kRunning, s.note));
  return out;
}

}  // namespace bookgrasp
