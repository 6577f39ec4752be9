#pragma once
/// @file
/// The library task as an explicit state machine (paper Sections 1-5): events
/// in (arm state, markers, arbiter decisions, servo and planner answers, user
/// events), requests out (servo, plan, arm and gripper commands). No LCM, no
/// clock: time is the utime of the events (message time).
///
/// One book: park -> BwS (the arbiter's P1 check) -> [BSwH stripe servo when
/// the arbiter has no PS or BwS found nothing] -> move to the BwH start (P1 or
/// PS) -> BwH servo (rank 0, then rank+1 on NEXT_REGION) -> GRASP -> pre-grasp
/// -> open -> insert -> close -> extract -> holder pre-place -> place -> release
/// -> retreat -> park -> wait for the user's "done" -> holder pre-grasp -> open
/// -> approach -> grasp -> lift -> lower-shelf pre-place -> place -> release ->
/// retreat -> park -> next book.
///
/// The upper shelf is empty when (a) after a book, the room left of it
/// (GP.y - BW - shelf left end) is narrower than the narrowest admissible book
/// S_min, or (b) the stripe servo ends within `empty_stripe_margin` of the
/// shelf's left end, i.e. no book occludes the stripe. BSwH runs whenever BwS
/// finds no book, so (b) confirms an empty shelf that BwS reports.
///
/// Failures before the book is in the gripper start a new attempt at the same
/// book (back out if inside the shelf, park, BwS again), at most
/// `max_attempts_per_book`; failures of a step with a book in the gripper or on
/// the holder repeat that step at most `max_step_retries` times. Beyond either
/// bound, or on the user event "abort", the cycle aborts cleanly: servo
/// cancelled, arm stopped, gripper left as it is (a held book stays held),
/// progress persisted with where the book is.

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "common/config.h"
#include "services/coordinator/cycle_geometry.h"
#include "services/coordinator/task_progress.h"

namespace bookgrasp {

/// Timeouts, retries and motion parameters of the cycle.
struct CycleSettings {
  CycleGeometry geometry;
  std::vector<double> park_joints;  ///< rad; the arm out of the stereo view
  // timeouts, seconds of message time
  double markers_timeout_s = 10;
  double decision_timeout_s = 10;
  double servo_timeout_s = 30;
  double plan_timeout_s = 10;
  double motion_margin_s = 5;  ///< added to a trajectory's or straight move's nominal duration
  double gripper_timeout_s = 5;
  double user_timeout_s = 0;     ///< 0 = wait for "done" forever
  double auto_done_after_s = 0;  ///< >0: send "done" after this long in WAIT_USER (demo)
  // retries
  int max_attempts_per_book = 3;
  int max_step_retries = 2;
  /// Not in the paper: a book the lower shelf cannot take (its move there still fails after the step retries, or
  /// the shelf is full) goes back onto the holder for the librarian (WAIT_BOOK_TAKEN) instead of aborting the task.
  bool hand_over_unplaceable = true;
  // planner
  std::string planner;  ///< "" = the planner's default
  double plan_time_budget_s = 2;
  double plan_position_tolerance_m = 0.002;
  double plan_orientation_tolerance_rad = 0.02;
  double held_book_depth_m = 0.25;  ///< depth assumed for a held book (collision model)
  /// Not in the paper: every plan carries the books placed on the lower shelf as boxes (`held_book_depth_m` deep),
  /// so a planned move does not sweep the arm or the held book through them.
  bool placed_books_as_obstacles = true;
  /// ... each box this much larger on every side than the book measured (its place and the moves past it are a few mm
  /// off the plan).
  double placed_book_padding_m = 0.0;
  // arm commands
  double heartbeat_period_s = 0.05;       ///< <= 0.1 s: the driver stops after 0.5 s without
  double linear_max_speed = 0.05;         ///< m/s for straight moves
  double linear_max_angular_speed = 0.3;  ///< rad/s
  double linear_gain = 2.0;               ///< 1/s, proportional gain of straight moves
  double linear_position_tolerance = 0.001;
  double linear_orientation_tolerance = 0.01;
  double stall_s = 1.0;           ///< a guarded place's TCP moving less than stall_distance for this long has stalled
  double stall_distance = 0.001;  ///< metres
  /// A guarded place that the arm driver stops (a joint limit) with the TCP this close to the place pose is done.
  double limit_stop_place = 0.01;
  // gripper
  double gripper_open_width = 0.06;
  double gripper_open_tolerance = 0.002;
  double gripper_speed = 0.05;
  double gripper_force = 60;
  double gripper_settle_s = 0.2;
  double gripper_settle_tolerance = 0.0005;
  double min_book_width = 0.005;  ///< closed below this = nothing grasped
  // emptiness
  double empty_stripe_margin = 0.02;
  double s_min = 0.015;  ///< narrowest admissible book (paper 4.1: L_max/4)
  /// Reads everything but the `service:` and `channels:` sections; throws ConfigError naming a bad key.
  static CycleSettings from_config(const Config& root);
};

/// The arm driver's report.
struct ArmEvent {
  int64_t utime = 0;
  std::vector<double> joints;
  Eigen::Isometry3d end_effector = Eigen::Isometry3d::Identity();  ///< gripper TCP in base
  double gripper_width = 0;
  bool gripper_contact = false;
  int state = 0;  ///< arm_state_t IDLE/EXECUTING/STOPPED/FAULT
  int64_t active_command_id = 0;
  std::string message;
};

/// Marker poses in base (latest frame; a missing one keeps the last seen).
struct MarkersEvent {
  int64_t utime = 0;
  std::optional<Eigen::Isometry3d> cart;
  std::optional<Eigen::Isometry3d> holder;
};

/// An arbiter decision (GRASP_POINT).
struct DecisionEvent {
  int64_t utime = 0;
  int64_t request_id = 0;
  std::string outcome;  ///< first word of the reason: P1_VALID, GRASP, NEXT_REGION, ...
  int next_rank = 0;    ///< NEXT_REGION
  bool valid = false;
  bool p1_present = false;  ///< p1_grasp finite
  Eigen::Vector3d p1_grasp = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());  ///< P1 (grasp)
  Eigen::Isometry3d gp_base = Eigen::Isometry3d::Identity();
  Eigen::Vector3d gp_grasp = Eigen::Vector3d::Zero();
  bool ps_present = false;
  Eigen::Vector3d ps_grasp = Eigen::Vector3d::Zero();
  std::string reason;
};

/// A visual-servoing status.
struct ServoEvent {
  int64_t utime = 0;
  int64_t request_id = 0;
  int mode = 0;   ///< servo_request_t mode
  int state = 0;  ///< servo_status_t state
  double front_width_m = 0;  ///< BOOK_CORNER CONVERGED: the fore-edge's width from the servo (0 = not measured)
  double neighbour_offset_m = 0;  ///< ... how far left of R the next fore-edge's right edge lies (0 = not seen)
  double neighbour_width_m = 0;   ///< ... the next fore-edge's width (0 = not seen)
  std::string message;
};

/// A planner answer.
struct PlanEvent {
  int64_t utime = 0;
  int64_t request_id = 0;
  bool success = false;
  std::string message;
  double duration_s = 0;  ///< of the trajectory
};

/// A user or operator event ("done", "abort").
struct UserEvent {
  int64_t utime = 0;
  std::string event;
  std::string detail;
};

/// One thing the node must send.
struct CycleRequest {
  enum class Kind {
    kServo,         ///< SERVO_REQUEST (mode, pose = start, rank, fixed_depth, timeout)
    kServoCancel,   ///< SERVO_REQUEST CANCEL
    kPlan,          ///< PLAN_REQUEST (joints or pose goal, holding_book, book_size)
    kExecutePlan,   ///< ARM_COMMAND TRAJECTORY with the trajectory of plan `plan_id`
    kTwist,         ///< ARM_COMMAND CARTESIAN_VELOCITY in base
    kArmStop,       ///< ARM_COMMAND STOP
    kHeartbeat,     ///< ARM_COMMAND HEARTBEAT
    kGripperMove,   ///< GRIPPER_COMMAND MOVE to width
    kGripperGrasp,  ///< GRIPPER_COMMAND GRASP
    kUserEvent,     ///< USER_EVENT (the demo's own "done")
  };
  Kind kind = Kind::kHeartbeat;
  int64_t id = 0;  ///< request / command id
  int servo_mode = 0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  int rank = 0;
  double fixed_depth = 0;
  double timeout_s = 0;
  bool joints_goal = false;
  std::vector<double> start_joints;
  std::vector<double> goal_joints;
  bool holding_book = false;
  Eigen::Vector3d book_size = Eigen::Vector3d::Zero();  ///< width, height, depth
  std::vector<Eigen::Isometry3d> then_poses;            ///< kPlan, pose goal: the straight moves after it (base)
  /// kPlan: boxes in base the planner avoids for this plan (the books placed on the lower shelf), with their names.
  std::vector<std::pair<std::string, OrientedBox>> obstacles;
  int64_t plan_id = 0;
  Eigen::Matrix<double, 6, 1> twist = Eigen::Matrix<double, 6, 1>::Zero();
  double width = 0;
  double force = 0;
  double speed = 0;
  std::string text;
  std::string detail;
};

/// The states of the cycle.
enum class CycleState {
  kStart,
  kWaitMarkers,
  kBackOut,
  kPark,
  kWaitP1Check,
  kMoveToStripeStart,
  kServoStripe,
  kWaitPsCheck,
  kMoveToBwhStart,
  kServoBook,
  kWaitDecision,
  kMoveToPreGrasp,
  kOpenForGrasp,
  kInsert,
  kCloseGripper,
  kExtract,
  kMoveToHolder,
  kPlaceOnHolder,
  kReleaseOnHolder,
  kRetreatFromHolder,
  kParkForUser,
  kWaitUser,
  /// Not in the paper: the book is taller than the lower shelf takes (lower_shelf_max_book_height), or the lower
  /// shelf could not take it (hand_over_unplaceable): it stays on the holder until the librarian takes it off and
  /// sends USER_EVENT "taken"; then the next book.
  kWaitBookTaken,
  kMoveToHolderPreGrasp,
  kOpenForHolderGrasp,
  kApproachHolder,
  kGraspFromHolder,
  kBackOutFromHolder,  ///< after a missed grasp from the holder: straight out, then the pre-grasp again
  kLiftFromHolder,
  kMoveToLowerShelf,
  kPlaceOnLowerShelf,
  kReleaseOnLowerShelf,
  kRetreatFromLowerShelf,
  kDone,
  kAborted,
};

/// Upper-case name of a state ("WAIT_P1_CHECK", ...), as in TASK_STATUS.state.
std::string cycle_state_name(CycleState s);

/// What TASK_STATUS says.
struct CycleStatus {
  std::string state;
  int books_total = 0;  ///< books known so far: moved + the current one
  int books_moved = 0;
  int current_book = 0;  ///< index of the book being handled (= books_moved)
  int attempt = 0;       ///< attempt at the current book, 1-based
  int failures = 0;
  std::string message;
};

/// The state machine.
class LibraryCycle {
 public:
  /// Starts fresh, or resumes from `resume` (a persisted progress).
  LibraryCycle(CycleSettings settings, std::optional<TaskProgress> resume);

  /// Event handlers. Each returns the requests to send, in order.
  std::vector<CycleRequest> on_arm(const ArmEvent& e);
  std::vector<CycleRequest> on_markers(const MarkersEvent& e);
  std::vector<CycleRequest> on_decision(const DecisionEvent& e);
  std::vector<CycleRequest> on_servo(const ServoEvent& e);
  std::vector<CycleRequest> on_plan(const PlanEvent& e);
  std::vector<CycleRequest> on_user(const UserEvent& e);

  /// Current state.
  CycleState state() const { return state_; }
  /// The persisted part.
  const TaskProgress& progress() const { return progress_; }
  /// Set when the progress changed since the last call (the node then writes the file). Clears the flag.
  bool take_progress_changed();
  /// Set when the status changed since the last call. Clears the flag.
  bool take_status_changed();
  /// For TASK_STATUS.
  CycleStatus status() const;
  /// Message time: the latest event utime.
  int64_t now() const { return now_; }

 private:
  enum class MotionKind { kNone, kPlanned, kLinear, kGripperOpen, kGripperGrasp };
  struct Motion {
    MotionKind kind = MotionKind::kNone;
    bool joints_goal = false;
    std::vector<double> goal_joints;
    Eigen::Isometry3d goal = Eigen::Isometry3d::Identity();
    bool holding = false;
    std::vector<Eigen::Isometry3d> then;  ///< the straight moves the state after this planned one makes
    int64_t plan_id = -1;
    std::vector<double> plan_start;  ///< the joints the pending plan starts from
    int64_t command_id = -1;
    bool planning = false;
    bool executing = false;
    std::vector<Eigen::Isometry3d> waypoints;
    size_t waypoint = 0;
    double guard = 0;  ///< last waypoint: a stall within this of it ends the move (a place)
    Eigen::Vector3d stall_from = Eigen::Vector3d::Zero();
    int64_t stall_since = -1;
    int64_t settle_start = -1;
    double settle_width = 0;
    double open_width = 0;  ///< kGripperOpen: the commanded plate gap
  };

  void advance_time(int64_t utime);
  void enter(CycleState s);
  void succeed(CycleState next);
  void fail(const std::string& reason);
  void abort(const std::string& reason);
  void check_timeout();
  void set_deadline(double seconds);
  void start_planned_joints(const std::vector<double>& goal);
  /// A planned move to `goal`; `then`: the straight moves that follow it (the planner picks a goal posture from
  /// which they stay within the joint limits).
  void start_planned_pose(const Eigen::Isometry3d& goal, bool holding, std::vector<Eigen::Isometry3d> then = {});
  /// Straight moves through `waypoints`; `guard` > 0: the arm stalling within it of the last one ends the move.
  void start_linear(std::vector<Eigen::Isometry3d> waypoints, double guard = 0);
  /// Closes the plates (grasp) or opens them to `open_width` (<= 0: the full opening).
  void start_gripper(bool grasp, double open_width = 0);
  /// This attempt's plate opening for the book (plate_opening() with the corner servo's fore-edges).
  PlateOpening book_opening() const;
  /// This attempt's grasp clear of the right side panel: book_opening() at a shallower insertion or moved left
  /// (plate_grasp_clear_of_right_panel()).
  PlateGrasp plate_grasp() const;
  /// plate_grasp()'s opening.
  PlateOpening grasp_opening() const;
  /// The geometry with this attempt's plate_grasp() offset and insertion depth.
  CycleGeometry grasp_geometry() const;
  /// How far beyond GP the plates went at this book's last INSERT (TaskProgress::grasp_insertion_depth), or
  /// grasp_geometry()'s depth when it is not known (before INSERT, or after a restart from an older file).
  double inserted_depth() const;
  void issue_plan();
  void drive_motion(const ArmEvent& e);
  /// After a move that carries the book: if the plates closed on nothing (no contact, narrower than
  /// min_book_width), aborts naming the state ("book N is not in the gripper after STATE") and returns true.
  bool book_lost_from_plates();
  /// SERVO_STRIPE: true (and the cycle moved on) once the TCP has passed geometry.stripe_left_limit_y leftwards.
  bool stripe_left_limit_passed();
  void motion_done();
  /// The current book's cycle is over (on the lower shelf, or `handed_over` to the librarian): records it in the
  /// progress, advances the lower shelf's next slot for a placed book, and decides whether the upper shelf is empty.
  void book_done(bool handed_over);
  void after_motion();
  CycleState resume_target() const;
  void persist();
  int64_t next_id();
  Eigen::Isometry3d cart_frame() const;
  /// The books on the lower shelf as boxes in base (`placed_books_as_obstacles`), named "lower_shelf_book_<index>".
  std::vector<std::pair<std::string, OrientedBox>> placed_book_obstacles() const;
  Eigen::Isometry3d holder_frame() const;
  double tcp_height() const;
  /// TCP height above the held book's bottom for the holder's place poses: tcp_height() for a book from the upper
  /// shelf, the grasp from the holder's (holder_regrasp_height) for one going back to the holder.
  double holder_tcp_height() const;
  /// The lower shelf cannot take the held book (`why`): with hand_over_unplaceable it goes back onto the holder
  /// for the librarian (MOVE_TO_HOLDER ... WAIT_BOOK_TAKEN), else the task aborts with the book held.
  void return_to_holder(const std::string& why);
  /// Starts leaving the current book to the librarian for `why` (hand_over_reason, retry count cleared). Without
  /// hand_over_unplaceable, or when the book is already being handed over, aborts instead and returns false.
  bool begin_hand_over(const std::string& why);
  /// The book on the holder cannot be grasped again (`why`, its retries used up): with hand_over_unplaceable it stays
  /// there for the librarian (out of the holder, PARK_FOR_USER, WAIT_BOOK_TAKEN), else the task aborts.
  void leave_on_holder(const std::string& why);
  /// Height of the book the planner is told about while it is held (GP.x).
  double held_box_height() const;
  /// Depth of that book: held_book_depth_m, and while the book comes from the upper shelf, as much more as its grasp
  /// went less deep than grasp.insertion_depth_m. The planner's box puts the fore-edge held_book.behind_tcp_m (the
  /// nominal insertion) behind the TCP; after a shallower grasp the book's far end reaches that much further ahead.
  double held_box_depth() const;
  /// BwH from the P1 check's or PS check's answer: its start point (P1 or PS) and the book front's Z.
  void start_bwh_from(const DecisionEvent& d);
  void handle_p1_check(const DecisionEvent& d);
  void handle_ps_check(const DecisionEvent& d);
  void handle_grasp_decision(const DecisionEvent& d);
  void handle_gripper_result(double width, bool contact);

  CycleSettings s_;
  TaskProgress progress_;
  CycleState state_ = CycleState::kStart;
  CycleState resume_from_ = CycleState::kStart;  ///< the state persisted when the process stopped
  int64_t now_ = 0;
  int64_t entry_utime_ = 0;
  int64_t deadline_ = -1;  ///< -1 = none
  int64_t last_id_ = 0;
  int64_t last_command_utime_ = 0;
  std::optional<ArmEvent> arm_;
  std::optional<Eigen::Isometry3d> cart_marker_;
  std::optional<Eigen::Isometry3d> holder_marker_;
  Motion motion_;
  std::vector<CycleRequest> out_;
  int attempt_ = 1;
  int step_retries_ = 0;
  /// How far (grasp Y) the current book's lower-shelf slot was moved left by retries of its place
  /// (geometry.lower_retry_shift); given back when the book is handed over instead. Not persisted: a coordinator
  /// restarted in between keeps the moved slot for the next book.
  double lower_slot_shift_ = 0.0;
  /// The step whose failure the retries count (kStart = none). Only its own success resets step_retries_: a retry of
  /// GRASP_FROM_HOLDER passes through BACK_OUT_FROM_HOLDER .. APPROACH_HOLDER, whose successes must not reset it.
  CycleState retrying_ = CycleState::kStart;
  /// The stripe end was measured in this attempt, or the attempt re-routes BwH (P1_LED_ASTRAY, RAISE_BWH_START,
  /// START_FROM_P1) at a measured PS: a P1 check without P1 starts BwH instead of checking the stripe again.
  bool stripe_done_this_attempt_ = false;
  bool rerouting_ = false;  ///< the arbiter answered a re-route; the next WAIT_P1_CHECK keeps the stripe as measured
  std::optional<double> p1_check_y_;  ///< the grasp Y of P1 at this attempt's P1 check, when BwS found a book
  int64_t stripe_request_ = -1;
  int64_t servo_request_ = -1;
  int rank_ = 0;
  Eigen::Vector3d bwh_start_ = Eigen::Vector3d::Zero();
  double bwh_front_z_ =
      0.0;  ///< grasp Z of the book's front for the corner servo: P1.z when P1 is valid, else the model's
  std::optional<DecisionEvent> early_decision_;  ///< a decision that arrived before its servo status
  Eigen::Isometry3d gp_base_ = Eigen::Isometry3d::Identity();
  ForeEdges fore_edges_;        ///< this attempt's fore-edges (0 = not measured), a split page face joined
  ForeEdges servo_fore_edges_;  ///< ... as the corner servo reported them
  /// An earlier grasp of this book closed on more than it (geometry.more_than_the_book): open only so far now.
  bool narrow_after_more_than_the_book_ = false;
  bool user_event_sent_ = false;
  bool stopping_foreign_motion_ = false;  ///< started with the arm executing a motion it did not command
  int64_t last_foreign_stop_utime_ = 0;   ///< when that motion was last sent a STOP
  int64_t arm_quiet_since_ = -1;          ///< since when the arm has not been executing (-1: it is)
  std::string message_;
  bool progress_changed_ = false;
  bool status_changed_ = true;
};

}  // namespace bookgrasp
