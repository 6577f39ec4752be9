#include "services/visual_servo/stripe_end_servo.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "services/visual_servo/book_corner_servo.h"

namespace bookgrasp {

StripeEndServo::StripeEndServo(const HandEyeGeometry& geometry, const StripeEndServoParams& params)
    : geo_(geometry), p_(params) {}

void StripeEndServo::reset() {
  phase_ = StripePhase::kSearch;
  occlusion_seen_ = false;
  in_tolerance_ = 0;
  missing_in_track_ = 0;
}

StripeServoStep StripeEndServo::step(const StripeObservation& obs, double standoff_m, double travelled_m,
                                     const Eigen::Vector2d& moved_since_capture_m) {
  StripeServoStep out;
  out.target_px = geo_.target_pixel(standoff_m);
  const double ut = out.target_px.x();

  if (phase_ == StripePhase::kSearch) {
    const bool covers_target = obs.found && ut >= std::min(obs.line_start_px.x(), obs.line_end_px.x()) - 1.0 &&
                               ut <= std::max(obs.line_start_px.x(), obs.line_end_px.x()) + 1.0;
    if (!covers_target) occlusion_seen_ = true;
    // An end is the left end of the right-most visible segment (BSwH, end_side left). Before
    // the books have hidden the stripe (require_occlusion), ends are ignored: they may be a
    // side panel or the end of the segment left of the book row.
    const bool armed = occlusion_seen_ || !p_.require_occlusion;
    bool accept = false;
    if (obs.end_found && armed) {
      // Searching towards +y (right) from the left of the books, the wanted end comes in from the right.
      accept = !p_.require_occlusion || p_.search_direction < 0 || obs.end_px.x() >= ut - 1.0;
      if (p_.require_occlusion && std::abs(obs.line_end_px.x() - obs.line_start_px.x()) < p_.occlusion_min_segment_px)
        accept = false;
    }
    if (accept) {
      phase_ = StripePhase::kTrack;
      in_tolerance_ = 0;
      missing_in_track_ = 0;
    } else {
      if (travelled_m > p_.max_search_distance_m) {
        out.failed = true;
        char buf[160];
        std::snprintf(buf, sizeof(buf),
                      "no stripe end found after %.2f m of search along the stripe (max_search_distance_m %.2f)",
                      travelled_m, p_.max_search_distance_m);
        out.note = buf;
        return out;
      }
      GripperTwist t = GripperTwist::Zero();
      // The stripe seen without its end (it runs out of the image on the end side): the end is that
      // way (unless the search starts left of the books: require_occlusion). Otherwise keep the
      // configured search direction.
      const bool end_beyond_border = obs.found && !obs.end_found && !p_.require_occlusion;
      t(1) = p_.search_speed * (end_beyond_border ? p_.end_side_direction : p_.search_direction);
      if (obs.found) {
        // Keep the stripe's centre line at the target row (height of the TCP = stripe height).
        const Eigen::Vector2d a = obs.line_start_px, b = obs.line_end_px;
        const double dx = b.x() - a.x();
        const double v = std::abs(dx) > 1e-6 ? a.y() + (ut - a.x()) * (b.y() - a.y()) / dx : 0.5 * (a.y() + b.y());
        Eigen::Vector3d p;
        if (geo_.pixel_on_plane(Eigen::Vector2d(ut, v), standoff_m, &p)) {
          t(0) = std::clamp(p_.gain * p.x(), -p_.max_linear_speed, p_.max_linear_speed);
          out.error_px.y() = v - out.target_px.y();
        }
      }
      out.twist = t;
      out.phase = phase_;
      out.note = obs.end_found ? "searching: an end seen but not accepted yet (behind the search direction or "
                                 "before the books hid the stripe)"
                               : (obs.found ? "searching: stripe seen, no end" : "searching: stripe hidden");
      return out;
    }
  }

  // TRACK
  out.phase = phase_;
  if (!obs.end_found) {
    ++missing_in_track_;
    if (p_.track_lost_frames > 0 && missing_in_track_ >= p_.track_lost_frames) {
      // The end was not the stripe's end (seen through a gap, or a false detection): search on.
      phase_ = StripePhase::kSearch;
      in_tolerance_ = 0;
      missing_in_track_ = 0;
      StripeServoStep s = step(obs, standoff_m, travelled_m);
      s.note = "end lost while tracking, searching again; " + s.note;
      return s;
    }
    out.measured = false;
    in_tolerance_ = 0;
    out.note = obs.found ? "stripe seen but its end is outside the image" : "stripe not visible";
    return out;
  }
  missing_in_track_ = 0;
  out.error_px = obs.end_px - out.target_px;
  Eigen::Vector3d p;
  if (!geo_.pixel_on_plane(obs.end_px, standoff_m, &p)) {
    out.measured = false;
    out.note = "stripe end ray does not meet the board plane";
    return out;
  }
  out.error_m = p.head<2>();
  // The end is fixed on the board: what is left of the error now is the image's minus the motion since.
  const Eigen::Vector2d e = p_.compensate_capture_delay && moved_since_capture_m.allFinite()
                                ? Eigen::Vector2d(p.head<2>() - moved_since_capture_m)
                                : Eigen::Vector2d(p.head<2>());
  GripperTwist t = GripperTwist::Zero();
  t(0) = p_.gain * e.x();
  t(1) = p_.gain * e.y();
  const double tol[2] = {p_.converged_x_m, p_.converged_y_m};
  for (int k = 0; k < 2; ++k)
    if (std::abs(e(k)) > tol[k] && std::abs(t(k)) < p_.min_track_speed) t(k) = std::copysign(p_.min_track_speed, e(k));
  out.twist = saturate_twist(t, p_.max_linear_speed, 1.0);
  const bool ok = std::abs(p.x()) <= p_.converged_x_m && std::abs(p.y()) <= p_.converged_y_m;
  in_tolerance_ = ok ? in_tolerance_ + 1 : 0;
  out.converged = in_tolerance_ >= p_.converged_frames;
  out.note = "tracking the stripe end";
  return out;
}

}  // namespace bookgrasp
