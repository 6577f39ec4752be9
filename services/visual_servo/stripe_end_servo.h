#pragma once
/// @file
/// Position-based visual servoing along the black stripe (paper Section 2.3):
/// from station A (in front of the cart marker) the TCP moves along the stripe
/// at a fixed standoff from the cart's rear board until the stripe's end (where
/// the right-most book hides it) is straight ahead of the TCP (station B). The
/// TCP position there gives PS (x = up and y = right in the grasp frame; the
/// depth is the predefined standoff).
///
/// Two phases:
///  - SEARCH: constant speed along the gripper y axis, the height corrected on
///    the stripe's centre line when it is seen. Direction: towards the end side
///    (end_side_direction) when the stripe is seen running out of the image on
///    that side, else search_direction (the stripe hidden behind books). With
///    require_occlusion the robot starts on the far side of the books (the
///    cart marker is on the left of the default cart) and first has to pass
///    behind books: an end is accepted only after the stripe was hidden at the
///    target column at least once, and only when it lies at or beyond the
///    target column in the search direction (so the end of the stripe segment
///    left of the book row, or a side panel, is never taken). Without it (the
///    coordinator's station A on the right part of the stripe, where only the
///    segment right of the books can be seen) the first end seen is tracked.
///  - TRACK: the end is back-projected onto the board plane (z_gripper =
///    standoff) and the TCP moves towards it with a proportional law,
///    saturated. Converged when the metric error is within tolerance for
///    converged_frames consecutive measurements.
/// Orientation is kept (no rotation).

#include <string>

#include <Eigen/Core>

#include "services/visual_servo/hand_eye_geometry.h"

namespace bookgrasp {

/// Parameters of the stripe servo (from configuration).
struct StripeEndServoParams {
  double gain = 1.0;               ///< 1/s on the metric position error (TRACK)
  double max_linear_speed = 0.05;  ///< m/s while tracking
  double search_speed = 0.1;       ///< m/s along the stripe while searching
  int search_direction = +1;  ///< while the stripe is hidden: +1 = gripper +y (right as seen from the robot), -1 = left
  int end_side_direction = -1;            ///< where the end lies from a visible segment whose end is outside the image
                                          ///< (BSwH end_side: left = -1, right = +1)
  bool require_occlusion = true;          ///< accept an end only after the stripe was hidden at the target column
  double converged_x_m = 0.0015;          ///< |error up| below this ...
  double converged_y_m = 0.0015;          ///< ... and |error right| below this ...
  int converged_frames = 3;               ///< ... on this many consecutive measurements
  double max_search_distance_m = 1.0;     ///< give up the search after this much travel
  double min_track_speed = 0.0;           ///< TRACK: an axis outside its tolerance moves at least this fast (m/s), so
                                          ///< the arm does not stall just outside the tolerance (0 = pure P law)
  double occlusion_min_segment_px = 0.0;  ///< with require_occlusion: an end is accepted only on a visible segment at
                                          ///< least this long (shorter ones are the stripe seen through gaps between
                                          ///< books on the way past them)
  bool compensate_capture_delay = true;   ///< TRACK: the twist acts on the measured error minus the TCP's motion since
                                          ///< the image was taken (the end is fixed on the board); false = on the
                                          ///< measured error alone, which overshoots when images arrive late
  int track_lost_frames = 0;              ///< TRACK: the end missing on this many consecutive observations -> back to
                                          ///< SEARCH (an end seen through a gap between books disappears as the
                                          ///< camera moves); 0 = never (the session reports FEATURE_LOST)
};

/// What BSwH saw in one image (the fields of stripe_features_t the servo uses).
struct StripeObservation {
  bool found = false;                                       ///< a stripe segment is visible
  bool end_found = false;                                   ///< its end is inside the image
  Eigen::Vector2d end_px = Eigen::Vector2d::Zero();         ///< stripe end
  Eigen::Vector2d line_start_px = Eigen::Vector2d::Zero();  ///< centre line, left end of the visible segment
  Eigen::Vector2d line_end_px = Eigen::Vector2d::Zero();    ///< centre line, right end
};

/// Phase of the stripe servo.
enum class StripePhase { kSearch = 0, kTrack = 1 };

/// One control step.
struct StripeServoStep {
  GripperTwist twist = GripperTwist::Zero();            ///< command, gripper frame
  StripePhase phase = StripePhase::kSearch;             ///< phase after this step
  Eigen::Vector2d target_px = Eigen::Vector2d::Zero();  ///< where the end is driven
  Eigen::Vector2d error_px = Eigen::Vector2d::Zero();   ///< end - target (0 while searching without an end)
  Eigen::Vector2d error_m = Eigen::Vector2d::Zero();    ///< end on the board plane, gripper (x up, y right), m
  bool measured = true;    ///< the observation was usable (false: the end was lost while tracking)
  bool converged = false;  ///< thresholds met for converged_frames
  bool failed = false;     ///< the search travelled max_search_distance_m without an end
  std::string note;        ///< what happened (for SERVO_STATUS.message)
};

/// The stripe servo's state machine.
class StripeEndServo {
 public:
  StripeEndServo(const HandEyeGeometry& geometry, const StripeEndServoParams& params);

  /// Back to SEARCH, occlusion not seen, convergence count 0.
  void reset();
  /// One step for observation `obs`, the board `standoff_m` ahead of the TCP,
  /// after `travelled_m` of TCP travel since the start. `moved_since_capture_m`: how far the TCP has
  /// moved (gripper x up, y right) between the image's capture and now; with compensate_capture_delay
  /// TRACK's twist acts on the error that is left now, while convergence is judged on the image.
  StripeServoStep step(const StripeObservation& obs, double standoff_m, double travelled_m,
                       const Eigen::Vector2d& moved_since_capture_m = Eigen::Vector2d::Zero());

  /// Current phase.
  StripePhase phase() const { return phase_; }
  /// True once the stripe was hidden at the target column.
  bool occlusion_seen() const { return occlusion_seen_; }
  /// The parameters.
  const StripeEndServoParams& params() const { return p_; }

 private:
  HandEyeGeometry geo_;
  StripeEndServoParams p_;
  StripePhase phase_ = StripePhase::kSearch;
  bool occlusion_seen_ = false;
  int in_tolerance_ = 0;
  int missing_in_track_ = 0;
};

}  // namespace bookgrasp
