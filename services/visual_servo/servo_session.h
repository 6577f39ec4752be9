#pragma once
/// @file
/// One visual-servoing task at a time, in message time: a request starts it,
/// feature measurements drive the corner (IBVS) or stripe (PBVS) servo, arm
/// states give the clock and the end-effector pose; out come velocity/stop
/// commands and progress reports. Pure: plain structs in and out, no LCM.
///
/// Timing (all message time, the largest utime seen on any input):
///  - every usable measurement gives a new CARTESIAN_VELOCITY command;
///  - while running, the current command is repeated at least every
///    command_period_s (the arm driver stops without a command/heartbeat);
///  - no usable measurement for stale_feature_s: the command becomes zero
///    velocity (the arm holds still, waiting);
///  - no usable measurement for feature_lost_timeout_s: STOP, FEATURE_LOST with
///    the detector's reason;
///  - the task's timeout: STOP, TIMEOUT; converged: STOP, CONVERGED with the
///    end-effector pose at the converging image's capture time.

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "services/visual_servo/book_corner_servo.h"
#include "services/visual_servo/corner_triangulation.h"
#include "services/visual_servo/hand_eye_geometry.h"
#include "services/visual_servo/stripe_end_servo.h"

namespace bookgrasp {

/// Task kinds (numbers as servo_request_t modes).
enum class ServoMode { kCancel = 0, kBookCorner = 1, kStripeEnd = 2 };
/// Task states (numbers as servo_status_t states).
enum class ServoState {
  kIdle = 0,
  kRunning = 1,
  kConverged = 2,
  kFeatureLost = 3,
  kTimeout = 4,
  kFailed = 5,
  kCancelled = 6
};

/// Name of a state ("IDLE", "RUNNING", ...).
std::string servo_state_name(ServoState s);

/// Timing and start checks of a task (from configuration).
struct ServoSessionParams {
  double feature_lost_timeout_s = 0.6;     ///< no usable measurement this long -> STOP, FEATURE_LOST
  double stale_feature_s = 0.25;           ///< no usable measurement this long -> zero velocity
  double command_period_s = 0.05;          ///< repeat the command at least this often
  double default_timeout_s = 20.0;         ///< when the request gives timeout_s <= 0
  double max_start_error_m = 0.02;         ///< TCP this far from the request's start_pose -> FAILED
  double default_corner_standoff_m = 0.2;  ///< TCP to book front when the request gives fixed_depth_m <= 0
  double default_stripe_standoff_m = 0.5;  ///< TCP to rear board when the request gives fixed_depth_m <= 0
  double pose_history_s = 1.0;             ///< end-effector poses kept to look up the pose at capture time
  /// Not in the paper: R located in 3D from the corner servo's views at convergence (corner_triangulation.h).
  CornerTriangulationParams corner_triangulation;
};

/// A start/cancel request (servo_request_t without LCM).
struct ServoRequest {
  int64_t utime = 0;
  int64_t request_id = 0;
  ServoMode mode = ServoMode::kCancel;
  std::optional<Eigen::Isometry3d> start_pose;  ///< checked against the arm if given
  double standoff_m = 0;                        ///< fixed_depth_m: TCP to the observed plane (<= 0: configured default)
  int rank_from_right = 0;                      ///< BwH rank the features must carry
  double timeout_s = 0;                         ///< <= 0: configured default
};

/// A BwH measurement (book_features_hand_t fields the servo uses).
struct BookObservation {
  int64_t utime = 0;
  bool found = false;
  std::string failure_reason;
  int rank_from_right = 0;
  Eigen::Vector2d r_px = Eigen::Vector2d::Zero();
  double slope_rad = 0;
  double width_px = 0;  ///< the selected fore-edge's width at its top (book_width_px); <= 0 = not given
  /// The next fore-edge to the left (BwH's accepted candidate with the largest corner x left of R): how many
  /// pixels its upper-right corner lies left of R, and its width; <= 0 = none seen.
  double neighbour_offset_px = 0;
  double neighbour_width_px = 0;
};

/// A BwH candidate as the servo reads it (book_candidate_t without LCM).
struct ForeEdgeCandidate {
  double corner_x_px = 0;  ///< its upper-right corner's column
  double width_px = 0;     ///< its width in columns
  bool accepted = false;   ///< BwH accepted it as a book
};

/// Sets `obs`'s neighbour_offset_px and neighbour_width_px from the accepted candidate whose corner lies nearest left
/// of R (more than a pixel left of it); leaves them 0 when there is none or R is not finite.
void set_next_fore_edge(const std::vector<ForeEdgeCandidate>& candidates, BookObservation* obs);

/// A command for the arm driver.
struct ServoCommand {
  int64_t utime = 0;
  bool stop = false;                          ///< STOP (else CARTESIAN_VELOCITY in the gripper frame)
  GripperTwist twist = GripperTwist::Zero();  ///< velocity command
  std::string reason;                         ///< why (stop)
};

/// A progress report (servo_status_t without LCM).
struct ServoReport {
  int64_t utime = 0;
  int64_t request_id = 0;
  ServoMode mode = ServoMode::kCancel;
  ServoState state = ServoState::kIdle;
  int iterations = 0;
  Eigen::Vector2d error_px = Eigen::Vector2d::Zero();
  double slope_error_rad = 0;
  std::optional<Eigen::Isometry3d> converged_pose;  ///< P2 or PS (CONVERGED only); P2 is the TCP pose at the
                                                    ///< last image raised by book_corner.target_above_tcp_m
  /// BOOK_CORNER CONVERGED only: R triangulated from the task's views, when they allowed it (else the
  /// message says why not).
  std::optional<TriangulatedCorner> corner;
  /// BOOK_CORNER CONVERGED with `corner`: the fore-edge's width in metres, the median over the task's views of
  /// width_px x (R's depth in that view's camera) / fx; 0 when R was not triangulated or no view gave a width.
  double front_width_m = 0;
  /// BOOK_CORNER CONVERGED with `corner`: the fore-edge left of the target's, measured like front_width_m: how far
  /// its right edge lies left of R, and its width (m); 0 when no view saw it.
  double neighbour_offset_m = 0;
  double neighbour_width_m = 0;
  std::string message;
};

/// What one input produced.
struct SessionOutput {
  std::vector<ServoCommand> commands;
  std::vector<ServoReport> reports;
};

/// Arm driver state as the session needs it.
enum class ArmCondition { kIdle, kExecuting, kStopped, kFault };

/// The servo task state machine.
class ServoSession {
 public:
  ServoSession(const HandEyeGeometry& geometry, const ServoSessionParams& session, const BookCornerServoParams& corner,
               const StripeEndServoParams& stripe);

  /// Starts (BOOK_CORNER, STRIPE_END) or cancels a task. A new task replaces a running one (reported CANCELLED).
  SessionOutput on_request(const ServoRequest& request);
  /// An arm state: the clock, the TCP pose in base, and the driver's condition and message.
  SessionOutput on_arm_state(int64_t utime, const Eigen::Isometry3d& tcp_in_base, ArmCondition condition,
                             const std::string& arm_message);
  /// A BwH measurement.
  SessionOutput on_book(const BookObservation& obs);
  /// A BSwH measurement; `failure_reason` is the detector's text when nothing usable was seen.
  SessionOutput on_stripe(int64_t utime, const StripeObservation& obs, const std::string& failure_reason);

  /// True while a task runs.
  bool running() const { return running_; }
  /// Mode of the current (or last) task.
  ServoMode mode() const { return mode_; }
  /// The geometry.
  const HandEyeGeometry& geometry() const { return geo_; }
  /// Message time now (largest utime seen).
  int64_t now_utime() const { return now_; }

 private:
  /// What BwH measured across the fore-edges in one view (<= 0: not measured).
  struct ViewExtents {
    double width_px = 0, neighbour_offset_px = 0, neighbour_width_px = 0;
  };
  /// The median of `pixels(view)` x (depth of the corner in that view's camera) / fx over the views that saw R at
  /// the triangulated corner (`corner.agreeing`: R detected on another book on the way measured that book's
  /// fore-edge, far_cart seed 5345) where `pixels` is > 0: a length across the fore-edges at R's depth (m); 0 = none.
  double metres_at(const TriangulatedCorner& corner, double (*pixels)(const ViewExtents&)) const;
  void advance(int64_t utime, SessionOutput* out);
  void finish(ServoState state, const std::string& message, SessionOutput* out,
              const std::optional<Eigen::Isometry3d>& pose = std::nullopt);
  void command(const GripperTwist& twist, SessionOutput* out);
  ServoReport report(ServoState state, const std::string& message) const;
  std::optional<Eigen::Isometry3d> pose_at(int64_t utime) const;
  /// The TCP's motion from the pose at `capture_utime` to now, in the gripper frame at capture:
  /// (x, y) in metres and the rotation about z in radians. Zero without a pose history.
  Eigen::Vector3d moved_since(int64_t capture_utime) const;
  bool accept_measurement_time(int64_t utime);

  HandEyeGeometry geo_;
  ServoSessionParams p_;
  BookCornerServo corner_;
  StripeEndServo stripe_;

  int64_t now_ = INT64_MIN;
  bool have_arm_ = false;
  Eigen::Isometry3d tcp_ = Eigen::Isometry3d::Identity();
  std::deque<std::pair<int64_t, Eigen::Isometry3d>> history_;

  bool running_ = false;
  ServoMode mode_ = ServoMode::kCancel;
  int64_t request_id_ = 0;
  int rank_ = 0;
  double standoff_ = 0;
  int64_t start_utime_ = 0;
  int64_t deadline_utime_ = 0;
  int64_t last_good_utime_ = 0;        ///< message time when the last good measurement arrived
  bool measured_since_start_ = false;  ///< a measurement of an image taken after the start arrived
  int64_t last_measurement_utime_ = INT64_MIN;
  int64_t last_command_utime_ = INT64_MIN;
  bool arm_executing_seen_ = false;
  bool holding_ = false;
  Eigen::Vector3d start_position_ = Eigen::Vector3d::Zero();
  GripperTwist twist_ = GripperTwist::Zero();
  int iterations_ = 0;
  Eigen::Vector2d error_px_ = Eigen::Vector2d::Zero();
  double slope_error_ = 0;
  std::string last_lost_reason_;
  std::vector<CornerSighting> sightings_;  ///< the corner task's views of R (camera pose at capture, pixel)
  std::vector<ViewExtents> sighting_extents_;  ///< what BwH measured across the fore-edges in each of sightings_
};

}  // namespace bookgrasp
