#include "services/coordinator/library_cycle.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <limits>

namespace bookgrasp {
namespace {

constexpr int kArmIdle = 0;
constexpr int kArmExecuting = 1;
constexpr double kForeignMotionSettleS = 0.3;    ///< still this long after stopping a predecessor's motion
constexpr double kPlanStartToleranceRad = 0.01;  ///< a plan whose start the arm has left by more is made again
                                                 ///< (the driver accepts 0.03 rad)
constexpr int kArmStopped = 2;
constexpr int kArmFault = 3;
constexpr int kServoBookCorner = 1;
constexpr int kServoStripeEnd = 2;
constexpr int kServoConverged = 2;
constexpr int kServoRunning = 1;
constexpr int kServoIdle = 0;

std::string mm(double m) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.1f mm", m * 1000);
  return buf;
}

std::string servo_state_name(int s) {
  switch (s) {
    case 0:
      return "IDLE";
    case 1:
      return "RUNNING";
    case 2:
      return "CONVERGED";
    case 3:
      return "FEATURE_LOST";
    case 4:
      return "TIMEOUT";
    case 5:
      return "FAILED";
    case 6:
      return "CANCELLED";
  }
  return "state " + std::to_string(s);
}

CycleRequest make_request(CycleRequest::Kind k) {
  CycleRequest r;
  r.kind = k;
  return r;
}

bool in(CycleState s, std::initializer_list<CycleState> set) {
  return std::find(set.begin(), set.end(), s) != set.end();
}

/// Largest |a_i - b_i|; infinity when the sizes differ.
double max_joint_difference(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return std::numeric_limits<double>::infinity();
  double m = 0;
  for (size_t i = 0; i < a.size(); ++i) m = std::max(m, std::fabs(a[i] - b[i]));
  return m;
}

}  // namespace

std::string cycle_state_name(CycleState s) {
  switch (s) {
    case CycleState::kStart:
      return "START";
    case CycleState::kWaitMarkers:
      return "WAIT_MARKERS";
    case CycleState::kBackOut:
      return "BACK_OUT";
    case CycleState::kPark:
      return "PARK";
    case CycleState::kWaitP1Check:
      return "WAIT_P1_CHECK";
    case CycleState::kMoveToStripeStart:
      return "MOVE_TO_STRIPE_START";
    case CycleState::kServoStripe:
      return "SERVO_STRIPE";
    case CycleState::kWaitPsCheck:
      return "WAIT_PS_CHECK";
    case CycleState::kMoveToBwhStart:
      return "MOVE_TO_BWH_START";
    case CycleState::kServoBook:
      return "SERVO_BOOK";
    case CycleState::kWaitDecision:
      return "WAIT_DECISION";
    case CycleState::kMoveToPreGrasp:
      return "MOVE_TO_PRE_GRASP";
    case CycleState::kOpenForGrasp:
      return "OPEN_FOR_GRASP";
    case CycleState::kInsert:
      return "INSERT";
    case CycleState::kCloseGripper:
      return "CLOSE_GRIPPER";
    case CycleState::kExtract:
      return "EXTRACT";
    case CycleState::kMoveToHolder:
      return "MOVE_TO_HOLDER";
    case CycleState::kPlaceOnHolder:
      return "PLACE_ON_HOLDER";
    case CycleState::kReleaseOnHolder:
      return "RELEASE_ON_HOLDER";
    case CycleState::kRetreatFromHolder:
      return "RETREAT_FROM_HOLDER";
    case CycleState::kParkForUser:
      return "PARK_FOR_USER";
    case CycleState::kWaitUser:
      return "WAIT_USER";
    case CycleState::kWaitBookTaken:
      return "WAIT_BOOK_TAKEN";
    case CycleState::kMoveToHolderPreGrasp:
      return "MOVE_TO_HOLDER_PRE_GRASP";
    case CycleState::kOpenForHolderGrasp:
      return "OPEN_FOR_HOLDER_GRASP";
    case CycleState::kApproachHolder:
      return "APPROACH_HOLDER";
    case CycleState::kGraspFromHolder:
      return "GRASP_FROM_HOLDER";
    case CycleState::kBackOutFromHolder:
      return "BACK_OUT_FROM_HOLDER";
    case CycleState::kLiftFromHolder:
      return "LIFT_FROM_HOLDER";
    case CycleState::kMoveToLowerShelf:
      return "MOVE_TO_LOWER_SHELF";
    case CycleState::kPlaceOnLowerShelf:
      return "PLACE_ON_LOWER_SHELF";
    case CycleState::kReleaseOnLowerShelf:
      return "RELEASE_ON_LOWER_SHELF";
    case CycleState::kRetreatFromLowerShelf:
      return "RETREAT_FROM_LOWER_SHELF";
    case CycleState::kDone:
      return "DONE";
    case CycleState::kAborted:
      return "ABORTED";
  }
  return "?";
}

namespace {
CycleState state_from_name(const std::string& n) {
  for (int i = 0; i <= static_cast<int>(CycleState::kAborted); ++i)
    if (cycle_state_name(static_cast<CycleState>(i)) == n) return static_cast<CycleState>(i);
  return CycleState::kStart;
}
}  // namespace

CycleSettings CycleSettings::from_config(const Config& root) {
  CycleSettings s;
  s.geometry = CycleGeometry::from_config(root.child("geometry"));
  s.park_joints = root.get_vector("park_joints_deg", 7);
  for (double& q : s.park_joints) q *= M_PI / 180.0;
  const Config t = root.child("timeouts");
  s.markers_timeout_s = t.get_double("markers_s", 0.1, 600);
  s.decision_timeout_s = t.get_double("decision_s", 0.1, 600);
  s.servo_timeout_s = t.get_double("servo_s", 0.1, 600);
  s.plan_timeout_s = t.get_double("plan_s", 0.1, 600);
  s.motion_margin_s = t.get_double("motion_margin_s", 0.1, 600);
  s.gripper_timeout_s = t.get_double("gripper_s", 0.1, 600);
  s.user_timeout_s = t.get_double("user_s", 0, 1e6);
  s.auto_done_after_s = root.get_double("user.auto_done_after_s", 0, 1e6);
  s.max_attempts_per_book = root.get_int("retries.max_attempts_per_book", 1, 100);
  s.max_step_retries = root.get_int("retries.max_step_retries", 0, 100);
  s.hand_over_unplaceable = root.get<bool>("retries.hand_over_unplaceable");
  const Config p = root.child("planning");
  s.planner = p.get<std::string>("planner");
  s.plan_time_budget_s = p.get_double("time_budget_s", 0.01, 120);
  s.plan_position_tolerance_m = p.get_double("position_tolerance_m", 1e-5, 0.1);
  s.plan_orientation_tolerance_rad = p.get_double("orientation_tolerance_rad", 1e-5, 1.0);
  s.held_book_depth_m = p.get_double("held_book_depth_m", 0.01, 1.0);
  s.placed_books_as_obstacles = p.get<bool>("placed_books_as_obstacles");
  s.placed_book_padding_m = p.get_double("placed_book_padding_m", 0.0, 0.05);
  const Config a = root.child("arm");
  s.heartbeat_period_s = a.get_double("heartbeat_period_s", 0.005, 0.1);
  s.linear_max_speed = a.get_double("linear_max_speed_mps", 0.001, 0.15);
  s.linear_max_angular_speed = a.get_double("linear_max_angular_speed_rps", 0.001, 0.6);
  s.linear_gain = a.get_double("linear_gain", 0.1, 20);
  s.linear_position_tolerance = a.get_double("linear_position_tolerance_m", 1e-5, 0.02);
  s.linear_orientation_tolerance = a.get_double("linear_orientation_tolerance_rad", 1e-5, 0.2);
  s.stall_s = a.get_double("stall_s", 0.05, 10);
  s.stall_distance = a.get_double("stall_distance_m", 1e-5, 0.05);
  s.limit_stop_place = a.get_double("limit_stop_place_m", 0.0, 0.05);
  const Config g = root.child("gripper");
  s.gripper_open_width = g.get_double("open_width_m", 0.005, 0.2);
  s.gripper_open_tolerance = g.get_double("open_tolerance_m", 1e-5, 0.02);
  s.gripper_speed = g.get_double("speed_mps", 0.001, 1.0);
  s.gripper_force = g.get_double("force_n", 1, 500);
  s.gripper_settle_s = g.get_double("settle_s", 0, 5);
  s.gripper_settle_tolerance = g.get_double("settle_tolerance_m", 1e-6, 0.01);
  s.min_book_width = g.get_double("min_book_width_m", 0.0, 0.05);
  s.empty_stripe_margin = root.get_double("empty_shelf.stripe_margin_m", 0.0, 0.5);
  s.s_min = root.get_double("empty_shelf.s_min_m", 0.0, 0.2);
  return s;
}

LibraryCycle::LibraryCycle(CycleSettings settings, std::optional<TaskProgress> resume) : s_(std::move(settings)) {
  if (resume) {
    progress_ = *resume;
    resume_from_ = state_from_name(progress_.last_state);
  } else {
    progress_.lower_next_right_y = s_.geometry.lower_first_right_y;
  }
  message_ = resume ? "resuming: book " + std::to_string(progress_.books_moved) + " is on/in the " +
                          book_place_name(progress_.place) + " (was " + progress_.last_state + ")"
                    : "starting";
}

bool LibraryCycle::take_progress_changed() {
  const bool c = progress_changed_;
  progress_changed_ = false;
  return c;
}

bool LibraryCycle::take_status_changed() {
  const bool c = status_changed_;
  status_changed_ = false;
  return c;
}

CycleStatus LibraryCycle::status() const {
  CycleStatus st;
  st.state = cycle_state_name(state_);
  st.books_moved = progress_.books_moved;
  st.current_book = progress_.books_moved;
  const bool current = !progress_.finished && state_ != CycleState::kDone;
  st.books_total = progress_.books_moved + (current ? 1 : 0);
  st.attempt = attempt_;
  st.failures = progress_.failures;
  st.message = message_;
  return st;
}

int64_t LibraryCycle::next_id() {
  // Unique across restarts: ids never fall behind message time.
  last_id_ = std::max(last_id_ + 1, now_);
  return last_id_;
}

void LibraryCycle::persist() {
  progress_.last_state = cycle_state_name(state_);
  progress_changed_ = true;
}

Eigen::Isometry3d LibraryCycle::cart_frame() const {
  return cart_grasp_frame(*cart_marker_, s_.geometry);
}
Eigen::Isometry3d LibraryCycle::holder_frame() const {
  return holder_support_frame(*holder_marker_, s_.geometry);
}
std::vector<std::pair<std::string, OrientedBox>> LibraryCycle::placed_book_obstacles() const {
  std::vector<std::pair<std::string, OrientedBox>> boxes;
  if (!s_.placed_books_as_obstacles) return boxes;
  const CycleGeometry& g = s_.geometry;
  for (const MovedBook& b : progress_.moved) {
    if (b.handed_over || !std::isfinite(b.lower_right_y)) continue;
    // A progress file from before the height was kept: as tall as the lower shelf takes (none if it takes any).
    const double height = std::isfinite(b.height) && b.height > 0 ? b.height : lower_shelf_max_book_height(g);
    if (!std::isfinite(height)) continue;
    OrientedBox box = lower_shelf_book_box(cart_frame(), b.lower_right_y, b.width, height, s_.held_book_depth_m, g);
    box.size += Eigen::Vector3d::Constant(2 * s_.placed_book_padding_m);
    boxes.emplace_back("lower_shelf_book_" + std::to_string(b.index), box);
  }
  return boxes;
}

double LibraryCycle::held_box_height() const {
  return std::max(0.0, progress_.gp_grasp.x());
}
double LibraryCycle::held_box_depth() const {
  if (progress_.place != BookPlace::kInGripperFromShelf) return s_.held_book_depth_m;
  return s_.held_book_depth_m + std::max(0.0, s_.geometry.insertion_depth - inserted_depth());
}
double LibraryCycle::tcp_height() const {
  return tcp_height_on_book(progress_.gp_grasp, s_.geometry);
}
double LibraryCycle::holder_tcp_height() const {
  return progress_.place == BookPlace::kInGripperFromHolder ? holder_regrasp_height(tcp_height(), s_.geometry)
                                                            : tcp_height();
}

void LibraryCycle::advance_time(int64_t utime) {
  if (utime > now_) now_ = utime;
}

void LibraryCycle::set_deadline(double seconds) {
  deadline_ = seconds > 0 ? now_ + static_cast<int64_t>(seconds * 1e6) : -1;
}

void LibraryCycle::check_timeout() {
  if (deadline_ < 0 || now_ < deadline_ || state_ == CycleState::kDone || state_ == CycleState::kAborted) return;
  deadline_ = -1;
  const std::string what = cycle_state_name(state_);
  if (state_ == CycleState::kWaitMarkers) {
    // A restarted coordinator whose view of a tag the held book (or the stopped arm) hides: the cart and the holder
    // stood still through the task, so the poses persisted before the restart stand in (kill test, 2026-12-06).
    const bool cart_from_progress = !cart_marker_ && progress_.cart_marker_in_base;
    const bool holder_from_progress = !holder_marker_ && progress_.holder_marker_in_base;
    if (!cart_marker_) cart_marker_ = progress_.cart_marker_in_base;
    if (!holder_marker_) holder_marker_ = progress_.holder_marker_in_base;
    if ((cart_from_progress || holder_from_progress) && cart_marker_ && holder_marker_) {
      message_ = std::string("resuming with the ") +
                 (cart_from_progress && holder_from_progress ? "cart and holder marker poses"
                  : cart_from_progress                       ? "cart marker pose"
                                                             : "holder marker pose") +
                 " persisted before the restart: the tag was not seen within " + std::to_string(s_.markers_timeout_s) +
                 " s (the held book or the arm in front of it?)";
      status_changed_ = true;
      set_deadline(s_.markers_timeout_s);
      return;
    }
    if (cart_marker_ && holder_marker_)
      abort("timeout in WAIT_MARKERS: the arm is still executing a motion the coordinator did not start, " +
            std::string("and did not stop on ARM_COMMAND STOP within ") + std::to_string(s_.markers_timeout_s) + " s");
    else
      abort("timeout in WAIT_MARKERS: cart and holder markers not both seen within " +
            std::to_string(s_.markers_timeout_s) + " s (is marker_detector running, are the tags in view?)");
    return;
  }
  if (state_ == CycleState::kWaitUser || state_ == CycleState::kWaitBookTaken) {
    const bool user = state_ == CycleState::kWaitUser;
    abort("timeout in " + what + ": no " + (user ? "\"done\" from the user" : "\"taken\" from the librarian") +
          " within " + std::to_string(s_.user_timeout_s) + " s");
    return;
  }
  if (motion_.kind == MotionKind::kPlanned && motion_.planning) {
    fail("timeout in " + what + ": no PLAN_RESULT within " + std::to_string(s_.plan_timeout_s) + " s");
  } else if (motion_.kind != MotionKind::kNone) {
    if (motion_.executing || motion_.kind == MotionKind::kLinear)
      out_.push_back(make_request(CycleRequest::Kind::kArmStop));
    fail("timeout in " + what + ": the motion did not finish in time");
  } else {
    fail("timeout in " + what);
  }
}

// ---- motions ----

void LibraryCycle::start_planned_joints(const std::vector<double>& goal) {
  motion_ = Motion{};
  motion_.kind = MotionKind::kPlanned;
  motion_.joints_goal = true;
  motion_.goal_joints = goal;
  issue_plan();
}

void LibraryCycle::start_planned_pose(const Eigen::Isometry3d& goal, bool holding,
                                      std::vector<Eigen::Isometry3d> then) {
  motion_ = Motion{};
  motion_.kind = MotionKind::kPlanned;
  motion_.goal = goal;
  motion_.holding = holding;
  motion_.then = std::move(then);
  issue_plan();
}

void LibraryCycle::issue_plan() {
  if (!motion_.planning) set_deadline(s_.plan_timeout_s);
  motion_.planning = true;
  motion_.plan_id = -1;
  // A plan starts where the arm is: not from a moving arm (a visual servo's last commands, a
  // stopped motion still coasting), whose state has changed by the time the trajectory arrives
  // (the driver refuses a trajectory that does not start at the current state). Issued at the
  // first arm state that is not EXECUTING (drive_motion), within the planning deadline.
  if (!arm_ || arm_->state == kArmExecuting) return;
  CycleRequest r;
  r.kind = CycleRequest::Kind::kPlan;
  r.id = next_id();
  motion_.plan_id = r.id;
  r.joints_goal = motion_.joints_goal;
  r.goal_joints = motion_.goal_joints;
  r.pose = motion_.goal;
  r.start_joints = arm_->joints;
  motion_.plan_start = arm_->joints;
  r.holding_book = motion_.holding;
  r.then_poses = motion_.then;
  if (motion_.holding) r.book_size = Eigen::Vector3d(progress_.book_width, held_box_height(), held_box_depth());
  r.obstacles = placed_book_obstacles();
  out_.push_back(r);
}

void LibraryCycle::start_linear(std::vector<Eigen::Isometry3d> waypoints, double guard) {
  motion_ = Motion{};
  motion_.kind = MotionKind::kLinear;
  motion_.waypoints = std::move(waypoints);
  motion_.guard = guard;
  motion_.command_id = next_id();
  double length = 0;
  Eigen::Vector3d from = arm_ ? arm_->end_effector.translation() : motion_.waypoints.front().translation();
  for (const auto& w : motion_.waypoints) {
    length += (w.translation() - from).norm();
    from = w.translation();
  }
  set_deadline(length / s_.linear_max_speed + s_.motion_margin_s);
}

PlateOpening LibraryCycle::book_opening() const {
  return narrow_after_more_than_the_book_
             ? plate_opening_after_more_than_the_book(fore_edges_, s_.gripper_open_width, s_.geometry)
             : plate_opening(fore_edges_, s_.gripper_open_width, s_.geometry);
}

PlateGrasp LibraryCycle::plate_grasp() const {
  return plate_grasp_clear_of_right_panel(book_opening(), progress_.gp_grasp, s_.gripper_open_width, s_.geometry);
}

PlateOpening LibraryCycle::grasp_opening() const {
  return plate_grasp().opening;
}

CycleGeometry LibraryCycle::grasp_geometry() const {
  const PlateGrasp p = plate_grasp();
  CycleGeometry g = s_.geometry;
  g.grasp_offset_y = p.opening.offset_y;
  g.insertion_depth = p.insertion_depth;
  return g;
}

double LibraryCycle::inserted_depth() const {
  return std::isfinite(progress_.grasp_insertion_depth) ? progress_.grasp_insertion_depth
                                                        : grasp_geometry().insertion_depth;
}

void LibraryCycle::start_gripper(bool grasp, double open_width) {
  motion_ = Motion{};
  motion_.kind = grasp ? MotionKind::kGripperGrasp : MotionKind::kGripperOpen;
  motion_.open_width = open_width > 0 ? open_width : s_.gripper_open_width;
  CycleRequest r;
  r.kind = grasp ? CycleRequest::Kind::kGripperGrasp : CycleRequest::Kind::kGripperMove;
  r.id = next_id();
  r.width = grasp ? 0.0 : motion_.open_width;
  r.force = s_.gripper_force;
  r.speed = s_.gripper_speed;
  out_.push_back(r);
  set_deadline(s_.gripper_timeout_s);
}

void LibraryCycle::drive_motion(const ArmEvent& e) {
  switch (motion_.kind) {
    case MotionKind::kNone:
      return;
    case MotionKind::kPlanned: {
      if (motion_.planning && motion_.plan_id < 0) {
        issue_plan();
        return;
      }
      if (!motion_.executing) return;
      if (e.active_command_id == motion_.command_id) {
        if (e.state == kArmIdle) {
          motion_done();
          return;
        }
        if (e.state == kArmStopped || e.state == kArmFault) {
          fail("the arm stopped during " + cycle_state_name(state_) + ": " + e.message);
          return;
        }
      }
      if (static_cast<double>(now_ - last_command_utime_) >= s_.heartbeat_period_s * 1e6) {
        CycleRequest hb;
        hb.kind = CycleRequest::Kind::kHeartbeat;
        hb.id = motion_.command_id;
        out_.push_back(hb);
        last_command_utime_ = now_;
      }
      return;
    }
    case MotionKind::kLinear: {
      const Eigen::Isometry3d& target = motion_.waypoints[motion_.waypoint];
      const Eigen::Vector3d ep = target.translation() - e.end_effector.translation();
      if (e.active_command_id == motion_.command_id && (e.state == kArmStopped || e.state == kArmFault) &&
          motion_.executing) {
        // A guarded place stopped by the driver (a joint limit) right above the place pose: the book is there.
        if (e.state == kArmStopped && motion_.guard > 0 && motion_.waypoint + 1 == motion_.waypoints.size() &&
            ep.norm() < s_.limit_stop_place) {
          message_ = "the arm stopped " + mm(ep.norm()) + " before the place pose (" + e.message + "): placed there";
          motion_done();
          return;
        }
        fail("the arm stopped during the straight move of " + cycle_state_name(state_) + ": " + e.message);
        return;
      }
      const Eigen::AngleAxisd er(target.linear() * e.end_effector.linear().transpose());
      if (ep.norm() < s_.linear_position_tolerance && std::abs(er.angle()) < s_.linear_orientation_tolerance) {
        if (++motion_.waypoint >= motion_.waypoints.size()) {
          out_.push_back(make_request(CycleRequest::Kind::kArmStop));
          motion_done();
        }
        return;
      }
      // A guarded place: the book met its support before the TCP reached the pose (it slid down in the plates).
      if (motion_.guard > 0 && motion_.executing && motion_.waypoint + 1 == motion_.waypoints.size() &&
          ep.norm() < motion_.guard) {
        const Eigen::Vector3d at = e.end_effector.translation();
        if (motion_.stall_since < 0 || (at - motion_.stall_from).norm() > s_.stall_distance) {
          motion_.stall_from = at;
          motion_.stall_since = now_;
        } else if (static_cast<double>(now_ - motion_.stall_since) >= s_.stall_s * 1e6) {
          message_ = "the book met its support " + mm(ep.norm()) +
                     " before the place pose (slid down in the plates): "
                     "placed there";
          out_.push_back(make_request(CycleRequest::Kind::kArmStop));
          motion_done();
          return;
        }
      }
      if (motion_.executing && static_cast<double>(now_ - last_command_utime_) < s_.heartbeat_period_s * 1e6) return;
      Eigen::Vector3d v = s_.linear_gain * ep;
      if (v.norm() > s_.linear_max_speed) v *= s_.linear_max_speed / v.norm();
      Eigen::Vector3d w = s_.linear_gain * er.angle() * er.axis();
      if (w.norm() > s_.linear_max_angular_speed) w *= s_.linear_max_angular_speed / w.norm();
      CycleRequest r;
      r.kind = CycleRequest::Kind::kTwist;
      r.id = motion_.command_id;
      r.twist << v, w;
      out_.push_back(r);
      motion_.executing = true;
      last_command_utime_ = now_;
      return;
    }
    case MotionKind::kGripperOpen:
    case MotionKind::kGripperGrasp: {
      const double w = e.gripper_width;
      if (motion_.settle_start < 0 || std::abs(w - motion_.settle_width) > s_.gripper_settle_tolerance) {
        motion_.settle_start = now_;
        motion_.settle_width = w;
      }
      const bool settled = static_cast<double>(now_ - motion_.settle_start) >= s_.gripper_settle_s * 1e6;
      if (!settled) return;
      if (motion_.kind == MotionKind::kGripperOpen) {
        if (w >= motion_.open_width - s_.gripper_open_tolerance) motion_done();
        return;
      }
      if (e.gripper_contact || w < s_.min_book_width) handle_gripper_result(w, e.gripper_contact);
      return;
    }
  }
}

void LibraryCycle::handle_gripper_result(double width, bool contact) {
  if (!contact || width < s_.min_book_width) {
    fail("nothing grasped in " + cycle_state_name(state_) + ": the gripper closed to " + mm(width) +
         (contact ? "" : " without contact"));
    return;
  }
  if (state_ == CycleState::kCloseGripper && holds_more_than_the_book(width, fore_edges_, s_.geometry)) {
    // The plates hold the neighbour too (its side within the opening): lifting now takes two books. Open, back out
    // and try again with the plates opened only to the book.
    narrow_after_more_than_the_book_ = true;
    fail("the plates closed to " + mm(width) + " on a fore-edge " + mm(fore_edges_.front_width) +
         " wide: more than the book between them (grasp.more_than_the_book_m " + mm(s_.geometry.more_than_the_book) +
         "); the next attempt opens them to the book only");
    return;
  }
  if (state_ == CycleState::kCloseGripper) {
    progress_.place = BookPlace::kInGripperFromShelf;
    progress_.have_book_data = true;
    progress_.book_width = width;
    message_ = "book " + std::to_string(progress_.books_moved) + " grasped, width " + mm(width);
  } else {
    progress_.place = BookPlace::kInGripperFromHolder;
    message_ = "book " + std::to_string(progress_.books_moved) + " taken from the holder";
  }
  motion_done();
}

bool LibraryCycle::book_lost_from_plates() {
  if (!arm_ || arm_->gripper_contact || arm_->gripper_width >= s_.min_book_width) return false;
  // The plates closed on nothing while they carried the book (a grasp too near its top edge): it fell. Where it
  // lies is unknown; carrying on would place and release empty plates and count a book that is not there.
  abort("book " + std::to_string(progress_.books_moved) + " is not in the gripper after " + cycle_state_name(state_) +
        " (no contact, plates at " + std::to_string(arm_->gripper_width * 1000.0) +
        " mm): it fell out; find it, correct the progress file, restart");
  return true;
}

void LibraryCycle::motion_done() {
  motion_ = Motion{};
  after_motion();
}

// What follows each state once its motion (or wait) finished.
void LibraryCycle::after_motion() {
  switch (state_) {
    case CycleState::kBackOut:
      succeed(CycleState::kPark);
      return;
    case CycleState::kPark:
      succeed(progress_.finished ? CycleState::kDone : CycleState::kWaitP1Check);
      return;
    case CycleState::kMoveToStripeStart:
      succeed(CycleState::kServoStripe);
      return;
    case CycleState::kMoveToBwhStart:
      succeed(CycleState::kServoBook);
      return;
    case CycleState::kMoveToPreGrasp:
      succeed(CycleState::kOpenForGrasp);
      return;
    case CycleState::kOpenForGrasp:
      succeed(CycleState::kInsert);
      return;
    case CycleState::kInsert:
      succeed(CycleState::kCloseGripper);
      return;
    case CycleState::kCloseGripper:
      succeed(CycleState::kExtract);
      return;
    case CycleState::kExtract:
      if (book_lost_from_plates()) return;
      succeed(CycleState::kMoveToHolder);
      return;
    case CycleState::kMoveToHolder:
      if (book_lost_from_plates()) return;
      succeed(CycleState::kPlaceOnHolder);
      return;
    case CycleState::kPlaceOnHolder:
      succeed(CycleState::kReleaseOnHolder);
      return;
    case CycleState::kReleaseOnHolder:
      progress_.place = BookPlace::kOnHolder;
      message_ = "book " + std::to_string(progress_.books_moved) + " on the holder";
      succeed(CycleState::kRetreatFromHolder);
      return;
    case CycleState::kRetreatFromHolder:
      succeed(CycleState::kParkForUser);
      return;
    case CycleState::kParkForUser:
      // A book the lower shelf could not take was catalogued already: it waits for the librarian, not the user.
      succeed(progress_.hand_over_reason.empty() ? CycleState::kWaitUser : CycleState::kWaitBookTaken);
      return;
    case CycleState::kMoveToHolderPreGrasp:
      succeed(CycleState::kOpenForHolderGrasp);
      return;
    case CycleState::kOpenForHolderGrasp:
      succeed(CycleState::kApproachHolder);
      return;
    case CycleState::kApproachHolder:
      succeed(CycleState::kGraspFromHolder);
      return;
    case CycleState::kGraspFromHolder:
      succeed(CycleState::kLiftFromHolder);
      return;
    case CycleState::kBackOutFromHolder:
      // A book left to the librarian (leave_on_holder) is not grasped again: park and wait for "taken".
      succeed(progress_.hand_over_reason.empty() ? CycleState::kMoveToHolderPreGrasp : CycleState::kParkForUser);
      return;
    case CycleState::kLiftFromHolder:
      if (book_lost_from_plates()) return;
      succeed(CycleState::kMoveToLowerShelf);
      return;
    case CycleState::kMoveToLowerShelf:
      if (book_lost_from_plates()) return;
      succeed(CycleState::kPlaceOnLowerShelf);
      return;
    case CycleState::kPlaceOnLowerShelf:
      if (book_lost_from_plates()) return;
      succeed(CycleState::kReleaseOnLowerShelf);
      return;
    case CycleState::kReleaseOnLowerShelf:
      book_done(false);
      succeed(CycleState::kRetreatFromLowerShelf);
      return;
    case CycleState::kRetreatFromLowerShelf:
      succeed(CycleState::kPark);
      return;
    default:
      return;
  }
}

// ---- transitions ----

void LibraryCycle::book_done(bool handed_over) {
  const CycleGeometry& g = s_.geometry;
  MovedBook b;
  b.index = progress_.books_moved;
  b.width = progress_.book_width;
  b.gp_y = progress_.gp_grasp.y();
  b.lower_right_y = handed_over ? std::numeric_limits<double>::quiet_NaN() : progress_.lower_next_right_y;
  b.handed_over = handed_over;
  b.height = progress_.gp_grasp.x();
  progress_.moved.push_back(b);
  progress_.books_moved += 1;
  if (!handed_over)
    progress_.lower_next_right_y = next_lower_right_y(progress_.lower_next_right_y, progress_.book_width, g);
  else
    progress_.lower_next_right_y += lower_slot_shift_;  // the slot this book tried first, for the next one
  lower_slot_shift_ = 0.0;
  progress_.place = BookPlace::kUpperShelf;
  progress_.have_book_data = false;
  progress_.grasp_insertion_depth = std::numeric_limits<double>::quiet_NaN();
  progress_.hand_over_reason.clear();
  const std::string where = handed_over ? " taken off the holder by the librarian" : " on the lower shelf";
  // Rule (a): the room left of this book, up to the shelf's left end, cannot hold an admissible book.
  const double room = b.gp_y - b.width - g.shelf_left_y;
  if (room < s_.s_min) {
    progress_.finished = true;
    message_ = "book " + std::to_string(b.index) + where + "; upper shelf empty: " + mm(room) + " left of it < S_min " +
               mm(s_.s_min);
  } else {
    message_ = "book " + std::to_string(b.index) + where;
  }
  attempt_ = 1;
  step_retries_ = 0;
  retrying_ = CycleState::kStart;
  rerouting_ = false;
  narrow_after_more_than_the_book_ = false;
}

void LibraryCycle::succeed(CycleState next) {
  if (retrying_ == CycleState::kStart || state_ == retrying_) {
    step_retries_ = 0;
    retrying_ = CycleState::kStart;
  }
  enter(next);
}

void LibraryCycle::enter(CycleState s) {
  state_ = s;
  entry_utime_ = now_;
  deadline_ = -1;
  motion_ = Motion{};
  status_changed_ = true;
  const CycleGeometry& g = s_.geometry;
  switch (s) {
    case CycleState::kStart:
    case CycleState::kDone:
    case CycleState::kAborted:
      break;
    case CycleState::kWaitMarkers:
      set_deadline(s_.markers_timeout_s);
      break;
    case CycleState::kBackOut: {
      out_.push_back(make_request(CycleRequest::Kind::kGripperMove));
      out_.back().id = next_id();
      // Not wider than for the grasp (the plates are among the books), but open: after a grasp on more than the book
      // the next opening is narrower than the plates are now.
      out_.back().width =
          std::min(s_.gripper_open_width, std::max(grasp_opening().width, (arm_ ? arm_->gripper_width : 0.0) + 0.01));
      out_.back().force = s_.gripper_force;
      out_.back().speed = s_.gripper_speed;
      const Eigen::Isometry3d here = arm_->end_effector;
      // Back to where the pre-grasp was (deeper for a front pushed back).
      const double back = pre_grasp_back_off(progress_.gp_grasp.z(), g) + inserted_depth();
      start_linear({move_along_own_axes(here, Eigen::Vector3d(0, 0, -back))});
      break;
    }
    case CycleState::kPark:
    case CycleState::kParkForUser:
      start_planned_joints(s_.park_joints);
      break;
    case CycleState::kWaitP1Check:
      stripe_done_this_attempt_ = rerouting_;
      rerouting_ = false;
      early_decision_.reset();
      set_deadline(s_.decision_timeout_s);
      break;
    case CycleState::kMoveToStripeStart:
      start_planned_pose(stripe_start_pose(cart_frame(), g), false);
      break;
    case CycleState::kServoStripe: {
      CycleRequest r;
      r.kind = CycleRequest::Kind::kServo;
      r.id = next_id();
      stripe_request_ = r.id;
      r.servo_mode = kServoStripeEnd;
      r.pose = arm_ ? arm_->end_effector : stripe_start_pose(cart_frame(), g);
      r.fixed_depth = g.stripe_fixed_depth;
      r.timeout_s = s_.servo_timeout_s;
      out_.push_back(r);
      early_decision_.reset();
      set_deadline(s_.servo_timeout_s + s_.decision_timeout_s);
      break;
    }
    case CycleState::kWaitPsCheck:
      stripe_done_this_attempt_ = true;
      set_deadline(s_.decision_timeout_s);
      if (early_decision_) {
        const DecisionEvent d = *early_decision_;
        early_decision_.reset();
        handle_ps_check(d);
      }
      break;
    case CycleState::kMoveToBwhStart:
      start_planned_pose(bwh_start_pose(cart_frame(), bwh_start_, g), false);
      break;
    case CycleState::kServoBook: {
      CycleRequest r;
      r.kind = CycleRequest::Kind::kServo;
      r.id = next_id();
      servo_request_ = r.id;
      fore_edges_ = servo_fore_edges_ = ForeEdges{};
      r.servo_mode = kServoBookCorner;
      r.pose = arm_ ? arm_->end_effector : bwh_start_pose(cart_frame(), bwh_start_, g);
      r.rank = rank_;
      // The servo keeps the start's distance to the books (the elbow's limit nearer the robot) and takes the corner
      // on the book's front: P1.z when P1 is valid (the fore-edges stand 0-2 cm behind the shelf's edge; with the hand
      // camera above the TCP a front 1 cm further than assumed put P2 ~6 mm above the true corner).
      r.fixed_depth = servo_standoff(bwh_front_z_, g);
      r.timeout_s = s_.servo_timeout_s;
      out_.push_back(r);
      early_decision_.reset();
      set_deadline(s_.servo_timeout_s + s_.decision_timeout_s);
      break;
    }
    case CycleState::kWaitDecision:
      set_deadline(s_.decision_timeout_s);
      if (early_decision_) {
        const DecisionEvent d = *early_decision_;
        early_decision_.reset();
        handle_grasp_decision(d);
      }
      break;
    case CycleState::kMoveToPreGrasp: {
      // INSERT and EXTRACT follow: the planner picks a posture from which the arm can make them.
      const CycleGeometry gw = grasp_geometry();
      const PlateOpening opening = grasp_opening();
      const double shift = book_opening().offset_y - opening.offset_y;
      const double over = palm_over_right_panel(opening, progress_.gp_grasp.y(), s_.geometry);
      const double shallower = g.insertion_depth - gw.insertion_depth;
      if (std::isfinite(servo_fore_edges_.front_width) && fore_edges_.front_width != servo_fore_edges_.front_width)
        message_ += "; the corner servo's fore-edge " + mm(servo_fore_edges_.front_width) + " and the next, " +
                    mm(servo_fore_edges_.neighbour_width) + ", touch (" +
                    mm(servo_fore_edges_.neighbour_offset - servo_fore_edges_.front_width) +
                    " apart < grasp.split_fore_edge_gap_m): one fore-edge " + mm(fore_edges_.front_width) + " wide";
      if (shallower > 1e-4)
        message_ += "; the plates go " + mm(gw.insertion_depth) + " beyond GP, " + mm(shallower) +
                    " less deep than grasp.insertion_depth_m: the palm stays in front of the right side panel";
      else if (over > 1e-4)  // not a rounding error's 1e-17 of a move that just clears
        message_ += "; the palm comes " + mm(over) + " nearer the right side panel than grasp.right_panel_clearance_m" +
                    " allows, with the plates " + mm(shift) + " further left: INSERT may meet the panel";
      else if (shift > 0)
        message_ += "; plates and palm " + mm(shift) + " further left, clear of the right side panel";
      const Eigen::Isometry3d grasp = grasp_pose(gp_base_, gw);
      std::vector<Eigen::Isometry3d> then{grasp};
      for (const Eigen::Isometry3d& p : extract_moves(grasp, cart_frame(), tcp_height(),
                                                      moves_front_z(progress_.gp_grasp.z(), g) + gw.insertion_depth, g))
        then.push_back(p);
      start_planned_pose(pre_grasp_pose(gp_base_, progress_.gp_grasp.z(), gw), false, std::move(then));
      break;
    }
    case CycleState::kOpenForGrasp:
      start_gripper(false, grasp_opening().width);
      break;
    case CycleState::kOpenForHolderGrasp:
    case CycleState::kReleaseOnHolder:
      start_gripper(false);
      break;
    case CycleState::kReleaseOnLowerShelf:
      // Not wider than the book needs: the right plate stands in the gap to the book placed before.
      start_gripper(false, lower_release_width(progress_.book_width, g));
      break;
    case CycleState::kInsert: {
      const CycleGeometry gw = grasp_geometry();
      progress_.grasp_insertion_depth = gw.insertion_depth;  // persisted below: EXTRACT comes out as far
      start_linear({grasp_pose(gp_base_, gw)});
      break;
    }
    case CycleState::kCloseGripper:
    case CycleState::kGraspFromHolder:
      start_gripper(true);
      break;
    case CycleState::kExtract: {
      start_linear(extract_moves(arm_->end_effector, cart_frame(), tcp_height(),
                                 moves_front_z(progress_.gp_grasp.z(), g) + inserted_depth(), g));
      break;
    }
    case CycleState::kMoveToHolder: {
      if (const double deeper = held_box_depth() - s_.held_book_depth_m; deeper > 1e-4)
        message_ += "; the planner's box for the book " + mm(deeper) +
                    " deeper than held_book_depth_m: the plates went in that much less deep";
      // PLACE_ON_HOLDER and RETREAT_FROM_HOLDER follow.
      // A book going back to the holder (return_to_holder) sits lower in the plates: its grasp from the holder's.
      std::vector<Eigen::Isometry3d> then = holder_place_moves(holder_frame(), holder_tcp_height(), g);
      then.push_back(move_along_own_axes(then.back(), Eigen::Vector3d(0, 0, -g.holder_retreat)));
      start_planned_pose(holder_pre_place_pose(holder_frame(), holder_tcp_height(), g), true, std::move(then));
      break;
    }
    case CycleState::kPlaceOnHolder:
      start_linear(holder_place_moves(holder_frame(), holder_tcp_height(), g), g.holder_place_guard);
      break;
    case CycleState::kApproachHolder:
      start_linear({holder_place_pose(holder_frame(), holder_regrasp_height(tcp_height(), g), g)});
      break;
    case CycleState::kRetreatFromHolder:
    case CycleState::kBackOutFromHolder:
      start_linear({move_along_own_axes(arm_->end_effector, Eigen::Vector3d(0, 0, -g.holder_retreat))});
      break;
    case CycleState::kWaitUser:
      user_event_sent_ = false;
      set_deadline(s_.user_timeout_s);
      message_ = "book " + std::to_string(progress_.books_moved) + " on the holder: waiting for the user's \"done\"";
      break;
    case CycleState::kWaitBookTaken:
      set_deadline(s_.user_timeout_s);
      if (!progress_.hand_over_reason.empty()) {
        message_ = "book " + std::to_string(progress_.books_moved) +
                   " is back on the holder: the lower shelf could not take it (" + progress_.hand_over_reason +
                   "); take it off and send \"taken\"";
        break;
      }
      message_ = "book " + std::to_string(progress_.books_moved) + " is " + mm(held_box_height()) +
                 " tall: the lower shelf takes books up to " + mm(lower_shelf_max_book_height(g)) +
                 " (lower_shelf.gap_to_upper_shelf_m - 2 x book_clearance_m); it stays on the holder: take it off "
                 "and send \"taken\"";
      break;
    case CycleState::kMoveToHolderPreGrasp:
      // Every way to the grasp from the holder (the user's "done", a resumed task) passes here.
      if (held_box_height() > lower_shelf_max_book_height(g)) {
        enter(CycleState::kWaitBookTaken);
        return;
      }
      {
        // APPROACH_HOLDER and LIFT_FROM_HOLDER follow.
        const double h = holder_regrasp_height(tcp_height(), g);
        const Eigen::Isometry3d regrasp = holder_place_pose(holder_frame(), h, g);
        std::vector<Eigen::Isometry3d> then{regrasp};
        for (const Eigen::Isometry3d& p : holder_lift_moves(holder_frame(), h, g)) then.push_back(p);
        start_planned_pose(move_along_own_axes(regrasp, Eigen::Vector3d(0, 0, -g.holder_retreat)), false,
                           std::move(then));
        break;
      }
    case CycleState::kLiftFromHolder:
      start_linear(holder_lift_moves(holder_frame(), holder_regrasp_height(tcp_height(), g), g));
      break;
    case CycleState::kMoveToLowerShelf: {
      const double left_after = progress_.lower_next_right_y - progress_.book_width;
      if (left_after < g.lower_left_y) {
        return_to_holder("the lower shelf is full: book " + std::to_string(progress_.books_moved) + " (" +
                         mm(progress_.book_width) + ") does not fit right of " + mm(g.lower_left_y));
        return;
      }
      // PLACE_ON_LOWER_SHELF and RETREAT_FROM_LOWER_SHELF follow.
      const double held = height_held_from_holder(tcp_height(), g);
      const Eigen::Isometry3d place =
          lower_place_pose(cart_frame(), progress_.lower_next_right_y, progress_.book_width, held, g);
      start_planned_pose(lower_pre_place_pose(cart_frame(), progress_.lower_next_right_y, progress_.book_width, held,
                                              held_box_height(), g),
                         true, {place, move_along_own_axes(place, Eigen::Vector3d(0, 0, -g.lower_retreat))});
      break;
    }
    case CycleState::kPlaceOnLowerShelf:
      start_linear({lower_place_pose(cart_frame(), progress_.lower_next_right_y, progress_.book_width,
                                     height_held_from_holder(tcp_height(), g), g)},
                   g.lower_place_guard);
      break;
    case CycleState::kRetreatFromLowerShelf:
      start_linear({move_along_own_axes(arm_->end_effector, Eigen::Vector3d(0, 0, -g.lower_retreat))});
      break;
  }
  if (s == CycleState::kDone) {
    progress_.finished = true;
    const auto handed =
        std::count_if(progress_.moved.begin(), progress_.moved.end(), [](const MovedBook& b) { return b.handed_over; });
    message_ =
        "upper shelf done: " + std::to_string(progress_.books_moved) + " books moved" +
        (handed > 0
             ? " (" + std::to_string(handed) +
                   " of them left to the librarian on the holder: too tall for the lower shelf, or not placeable "
                   "there)"
             : "") +
        (message_.empty() ? "" : " (" + message_ + ")");
  }
  persist();
}

void LibraryCycle::fail(const std::string& reason) {
  progress_.failures += 1;
  message_ = reason;
  const bool before_grasp = in(
      state_, {CycleState::kWaitP1Check, CycleState::kMoveToStripeStart, CycleState::kServoStripe,
               CycleState::kWaitPsCheck, CycleState::kMoveToBwhStart, CycleState::kServoBook, CycleState::kWaitDecision,
               CycleState::kMoveToPreGrasp, CycleState::kOpenForGrasp, CycleState::kInsert, CycleState::kCloseGripper});
  // A cancel also opens a new attempt in the arbiter (its P1 is no longer frozen).
  if (before_grasp || in(state_, {CycleState::kServoStripe, CycleState::kServoBook, CycleState::kWaitDecision}))
    out_.push_back(make_request(CycleRequest::Kind::kServoCancel));
  if (before_grasp) {
    if (attempt_ >= s_.max_attempts_per_book) {
      abort("book " + std::to_string(progress_.books_moved) + ": " + std::to_string(attempt_) +
            " attempts failed (retries.max_attempts_per_book), last: " + reason);
      return;
    }
    attempt_ += 1;
    rerouting_ = false;
    message_ = "attempt " + std::to_string(attempt_) + " at book " + std::to_string(progress_.books_moved) +
               " after: " + reason;
    const bool inside = in(state_, {CycleState::kInsert, CycleState::kCloseGripper});
    step_retries_ = 0;
    retrying_ = CycleState::kStart;
    enter(inside ? CycleState::kBackOut : CycleState::kPark);
    return;
  }
  if (step_retries_ >= s_.max_step_retries) {
    const std::string why = (retrying_ == CycleState::kStart ? cycle_state_name(state_) : cycle_state_name(retrying_)) +
                            " failed " + std::to_string(step_retries_ + 1) +
                            " times (retries.max_step_retries), last: " + reason;
    step_retries_ = 0;
    retrying_ = CycleState::kStart;
    if (in(state_, {CycleState::kMoveToLowerShelf, CycleState::kPlaceOnLowerShelf}))
      return_to_holder(why);  // the lower shelf cannot take the book
    else if (progress_.place == BookPlace::kOnHolder)
      leave_on_holder(why);  // the book cannot be taken from the holder again
    else
      abort(why + "; the book is on/in the " + book_place_name(progress_.place));
    return;
  }
  if (retrying_ == CycleState::kStart) retrying_ = state_;
  step_retries_ += 1;
  message_ = "retry " + std::to_string(step_retries_) + " of " + cycle_state_name(state_) + " after: " + reason;
  // A missed grasp on the holder: straight out (the planner does not plan from between the holder's plates:
  // "start is in collision", the deployed demo's third book), then come back from the pre-grasp pose. A place on
  // the lower shelf that stopped (a joint limit on the straight move, far_cart seed 5005) is planned again from the
  // pre-place: the same straight move from where it stopped would stop there again.
  CycleState again = state_;
  if (state_ == CycleState::kGraspFromHolder) again = CycleState::kBackOutFromHolder;
  if (state_ == CycleState::kPlaceOnLowerShelf) {
    again = CycleState::kMoveToLowerShelf;
    // Further left the arm reaches further down (the planner's "no goal solution from which the straight moves stay
    // within the joint limits" at base y -0.20, seed 5005); a slot left of the shelf's end hands the book over.
    if (s_.geometry.lower_retry_shift > 0) {
      progress_.lower_next_right_y -= s_.geometry.lower_retry_shift;
      lower_slot_shift_ += s_.geometry.lower_retry_shift;
      progress_changed_ = true;
      message_ += "; the slot moves " + mm(s_.geometry.lower_retry_shift) + " left";
    }
  }
  enter(again);
}

bool LibraryCycle::begin_hand_over(const std::string& why) {
  if (!s_.hand_over_unplaceable || !progress_.hand_over_reason.empty()) {
    abort(why + "; the book is on/in the " + book_place_name(progress_.place) +
          (s_.hand_over_unplaceable ? "" : " (retries.hand_over_unplaceable is off)"));
    return false;
  }
  progress_.hand_over_reason = why;
  step_retries_ = 0;
  retrying_ = CycleState::kStart;
  return true;
}

void LibraryCycle::return_to_holder(const std::string& why) {
  if (!begin_hand_over(why)) return;
  message_ = "book " + std::to_string(progress_.books_moved) + " goes back onto the holder for the librarian: " + why;
  enter(CycleState::kMoveToHolder);
}

void LibraryCycle::leave_on_holder(const std::string& why) {
  if (!begin_hand_over(why)) return;
  message_ = "book " + std::to_string(progress_.books_moved) + " stays on the holder for the librarian: " + why;
  // Out of the holder first where the plates may be around the book; then park and wait for "taken".
  const bool at_book = in(state_, {CycleState::kApproachHolder, CycleState::kGraspFromHolder});
  enter(at_book ? CycleState::kBackOutFromHolder : CycleState::kParkForUser);
}

void LibraryCycle::abort(const std::string& reason) {
  out_.push_back(make_request(CycleRequest::Kind::kServoCancel));
  out_.push_back(make_request(CycleRequest::Kind::kArmStop));
  const std::string where = cycle_state_name(state_);
  state_ = CycleState::kAborted;
  deadline_ = -1;
  motion_ = Motion{};
  message_ = "aborted in " + where + ": " + reason;
  status_changed_ = true;
  progress_.last_state = where;  // resume from where it stopped
  progress_changed_ = true;
}

CycleState LibraryCycle::resume_target() const {
  if (progress_.finished) return CycleState::kDone;
  const CycleState was = resume_from_;
  switch (progress_.place) {
    case BookPlace::kUpperShelf:
      return in(was, {CycleState::kInsert, CycleState::kCloseGripper}) ? CycleState::kBackOut : CycleState::kPark;
    case BookPlace::kInGripperFromShelf:
      if (in(was, {CycleState::kCloseGripper, CycleState::kExtract})) return CycleState::kExtract;
      if (in(was, {CycleState::kPlaceOnHolder})) return CycleState::kPlaceOnHolder;
      return CycleState::kMoveToHolder;
    case BookPlace::kOnHolder:
      if (in(was, {CycleState::kRetreatFromHolder})) return CycleState::kRetreatFromHolder;
      if (in(was, {CycleState::kWaitBookTaken})) return CycleState::kWaitBookTaken;  // the arm is parked
      if (in(was, {CycleState::kApproachHolder, CycleState::kGraspFromHolder, CycleState::kBackOutFromHolder}))
        return CycleState::kBackOutFromHolder;
      return CycleState::kParkForUser;
    case BookPlace::kInGripperFromHolder:
      if (!progress_.hand_over_reason.empty())  // on its way back to the holder for the librarian
        return in(was, {CycleState::kPlaceOnHolder}) ? CycleState::kPlaceOnHolder : CycleState::kMoveToHolder;
      if (in(was, {CycleState::kGraspFromHolder, CycleState::kLiftFromHolder})) return CycleState::kLiftFromHolder;
      if (in(was, {CycleState::kPlaceOnLowerShelf})) return CycleState::kPlaceOnLowerShelf;
      return CycleState::kMoveToLowerShelf;
  }
  return CycleState::kPark;
}

// ---- events ----

std::vector<CycleRequest> LibraryCycle::on_arm(const ArmEvent& e) {
  out_.clear();
  advance_time(e.utime);
  arm_ = e;
  if (state_ == CycleState::kStart) {
    out_.push_back(make_request(CycleRequest::Kind::kServoCancel));
    out_.back().id = next_id();
    // A (re)started coordinator does not own a motion the arm may still be executing (its killed
    // predecessor's, until the driver's heartbeat timeout): stop it, and plan nothing from a moving arm.
    if (e.state == kArmExecuting) {
      out_.push_back(make_request(CycleRequest::Kind::kArmStop));
      message_ = "stopping the arm's unfinished motion before resuming";
      stopping_foreign_motion_ = true;
      last_foreign_stop_utime_ = now_;
      arm_quiet_since_ = -1;
    }
    enter(CycleState::kWaitMarkers);
  }
  if (state_ == CycleState::kWaitMarkers && stopping_foreign_motion_) {
    // The motion may have been a visual servo's: commands already in flight can start the arm again
    // after the STOP. Go on only once the arm has stayed still for kForeignMotionSettleS; STOP again
    // (at most every kForeignMotionSettleS) while it moves.
    if (e.state == kArmExecuting) {
      arm_quiet_since_ = -1;
      if (now_ - last_foreign_stop_utime_ >= static_cast<int64_t>(kForeignMotionSettleS * 1e6)) {
        out_.push_back(make_request(CycleRequest::Kind::kArmStop));
        last_foreign_stop_utime_ = now_;
      }
    } else if (arm_quiet_since_ < 0) {
      arm_quiet_since_ = now_;
    }
  }
  const bool arm_settled =
      !stopping_foreign_motion_ ||
      (arm_quiet_since_ >= 0 && now_ - arm_quiet_since_ >= static_cast<int64_t>(kForeignMotionSettleS * 1e6));
  if (state_ == CycleState::kWaitMarkers) {
    if (cart_marker_ && holder_marker_ && e.state != kArmExecuting && arm_settled) {
      const bool holding =
          progress_.place == BookPlace::kInGripperFromShelf || progress_.place == BookPlace::kInGripperFromHolder;
      if (holding && !e.gripper_contact) {
        abort("book " + std::to_string(progress_.books_moved) +
              " should be in the gripper (progress file: " + book_place_name(progress_.place) +
              ") but the gripper reports no contact: find the book, correct "
              "the progress file, restart");
      } else {
        succeed(resume_target());
      }
    }
  } else if (state_ == CycleState::kWaitUser) {
    if (s_.auto_done_after_s > 0 && !user_event_sent_ &&
        static_cast<double>(now_ - entry_utime_) >= s_.auto_done_after_s * 1e6) {
      CycleRequest r;
      r.kind = CycleRequest::Kind::kUserEvent;
      r.text = "done";
      r.detail = "sent by the coordinator after user.auto_done_after_s (demo)";
      out_.push_back(r);
      user_event_sent_ = true;
      message_ = "user \"done\" (automatic)";
      succeed(CycleState::kMoveToHolderPreGrasp);
    }
  } else if (!(state_ == CycleState::kServoStripe && stripe_left_limit_passed())) {
    drive_motion(e);
  }
  check_timeout();
  return out_;
}

bool LibraryCycle::stripe_left_limit_passed() {
  const CycleGeometry& g = s_.geometry;
  const double y = (cart_frame().inverse() * arm_->end_effector.translation()).y();
  if (y >= g.stripe_left_limit_y) return false;
  // The servo moves left only along a visible stripe (or towards an end it tracks there): no book stands right of
  // here. Further left the gripper would meet the holder beside the cart.
  out_.push_back(make_request(CycleRequest::Kind::kServoCancel));
  out_.push_back(make_request(CycleRequest::Kind::kArmStop));
  const std::string where = "the stripe servo reached its left limit (geometry.servo.stripe_left_limit_y_m " +
                            mm(g.stripe_left_limit_y) + ", " + mm(g.stripe_left_limit_y - g.shelf_left_y) +
                            " from the shelf's left end; further left the gripper meets the book holder)";
  if (p1_check_y_) {
    fail(where + " without a stripe end, but BwS saw a book at Y " + mm(*p1_check_y_) +
         ": its stripe end is out of the servo's reach");
    return true;
  }
  // Books lying flat (fallen when their neighbours went) hide neither the stripe nor stand as BwS fronts: they stay.
  message_ = where +
             ": no standing book right of it, and BwS sees none: no book left that the arm can take (books "
             "lying flat, if any, are left for the librarian)";
  progress_.finished = true;
  succeed(CycleState::kPark);
  return true;
}

std::vector<CycleRequest> LibraryCycle::on_markers(const MarkersEvent& e) {
  out_.clear();
  advance_time(e.utime);
  if (e.cart) cart_marker_ = progress_.cart_marker_in_base = e.cart;  // written with the next state's progress
  if (e.holder) holder_marker_ = progress_.holder_marker_in_base = e.holder;
  check_timeout();
  return out_;
}

void LibraryCycle::handle_p1_check(const DecisionEvent& d) {
  p1_check_y_.reset();
  if (d.p1_present && std::isfinite(d.p1_grasp.y())) p1_check_y_ = d.p1_grasp.y();
  if (d.outcome == "NEED_PS" || (!d.p1_present && !stripe_done_this_attempt_)) {
    message_ = d.outcome == "NEED_PS" ? "no PS yet: BSwH to the stripe end"
                                      : "BwS found no book: BSwH checks whether the stripe is free";
    succeed(CycleState::kMoveToStripeStart);
    return;
  }
  start_bwh_from(d);
}

void LibraryCycle::start_bwh_from(const DecisionEvent& d) {
  bwh_start_ = d.gp_grasp;
  const CycleGeometry& g = s_.geometry;
  // The corner servo's image target and so P2 depend on the front's depth. The arbiter's P1 check gives it as
  // gp_grasp's Z: P1.z when valid, else the depth GP.z will take (a stereo plane left of PS, the invalid P1's,
  // or the model's); book_front_z only when it gave none.
  bwh_front_z_ = std::isfinite(d.gp_grasp.z()) ? d.gp_grasp.z() : g.book_front_z;
  rank_ = 0;
  message_ = d.reason;
  succeed(CycleState::kMoveToBwhStart);
}

void LibraryCycle::handle_ps_check(const DecisionEvent& d) {
  if (!d.ps_present) {
    fail("the arbiter has no PS after the stripe servo converged: " + d.reason);
    return;
  }
  const double from_left = d.ps_grasp.y() - s_.geometry.shelf_left_y;
  if (from_left <= s_.empty_stripe_margin) {
    message_ = "stripe end " + mm(from_left) + " from the shelf's left end: no book occludes the stripe";
    progress_.finished = true;
    succeed(CycleState::kPark);
    return;
  }
  if (d.outcome != "P1_VALID" && d.outcome != "P1_INVALID") {
    fail("unexpected arbiter answer after the stripe servo: " + d.reason);
    return;
  }
  start_bwh_from(d);
}

void LibraryCycle::handle_grasp_decision(const DecisionEvent& d) {
  if (d.outcome == "GRASP" && d.valid) {
    gp_base_ = d.gp_base;
    progress_.gp_grasp = d.gp_grasp;
    progress_.grasp_insertion_depth = std::numeric_limits<double>::quiet_NaN();  // set at INSERT
    message_ = d.reason;
    succeed(CycleState::kMoveToPreGrasp);
  } else if (d.outcome == "NEXT_REGION") {
    rank_ = d.next_rank;
    message_ = d.reason;
    succeed(CycleState::kMoveToBwhStart);
  } else if (d.outcome == "P1_LED_ASTRAY" || d.outcome == "RAISE_BWH_START" || d.outcome == "START_FROM_P1") {
    // Not a failed attempt: BwH centred a neighbour's corner, and the arbiter's next P1 check sends BwH from PS
    // (P1_LED_ASTRAY: BwS's P1 took it there), from higher above PS (RAISE_BWH_START: a tall right-most book) or from
    // the P1 that stood between (START_FROM_P1: a tall right-most book leaning left). It
    // answers each once per PS, so this cannot repeat without bound. The servo is cancelled as after a failure.
    out_.push_back(make_request(CycleRequest::Kind::kServoCancel));
    rerouting_ = true;
    message_ = d.reason + " (attempt " + std::to_string(attempt_) + " goes on)";
    succeed(CycleState::kPark);
  } else {
    fail("arbiter: " + d.reason);
  }
}

std::vector<CycleRequest> LibraryCycle::on_decision(const DecisionEvent& d) {
  out_.clear();
  advance_time(d.utime);
  const bool check = d.outcome == "P1_VALID" || d.outcome == "P1_INVALID" || d.outcome == "NEED_PS";
  switch (state_) {
    case CycleState::kWaitP1Check:
      if (check && d.utime >= entry_utime_ && d.request_id == 0) handle_p1_check(d);
      break;
    case CycleState::kServoStripe:
      if (d.request_id == stripe_request_) early_decision_ = d;
      break;
    case CycleState::kWaitPsCheck:
      if (d.request_id == stripe_request_) handle_ps_check(d);
      break;
    case CycleState::kServoBook:
      if (d.request_id == servo_request_) early_decision_ = d;
      break;
    case CycleState::kWaitDecision:
      if (d.request_id == servo_request_) handle_grasp_decision(d);
      break;
    default:
      break;
  }
  check_timeout();
  return out_;
}

std::vector<CycleRequest> LibraryCycle::on_servo(const ServoEvent& e) {
  out_.clear();
  advance_time(e.utime);
  const bool terminal = e.state != kServoRunning && e.state != kServoIdle;
  if (state_ == CycleState::kServoStripe && e.request_id == stripe_request_ && terminal) {
    if (e.state == kServoConverged)
      succeed(CycleState::kWaitPsCheck);
    else
      fail("stripe servo ended " + servo_state_name(e.state) + (e.message.empty() ? "" : ": " + e.message));
  } else if (state_ == CycleState::kServoBook && e.request_id == servo_request_ && terminal) {
    if (e.state == kServoConverged) {
      servo_fore_edges_ = {e.front_width_m, e.neighbour_offset_m, e.neighbour_width_m};
      fore_edges_ = join_split_fore_edge(servo_fore_edges_, s_.geometry);
    }
    // Converged or not, the arbiter decides (a failed BwH servo is its NO_GRASP).
    succeed(CycleState::kWaitDecision);
  }
  check_timeout();
  return out_;
}

std::vector<CycleRequest> LibraryCycle::on_plan(const PlanEvent& e) {
  out_.clear();
  advance_time(e.utime);
  if (motion_.kind == MotionKind::kPlanned && motion_.planning && e.request_id == motion_.plan_id) {
    if (!e.success) {
      fail("planning for " + cycle_state_name(state_) + " failed: " + e.message);
    } else if (arm_ && max_joint_difference(arm_->joints, motion_.plan_start) > kPlanStartToleranceRad) {
      // The arm moved while the plan was made: its trajectory no longer starts where the arm is.
      issue_plan();
    } else {
      motion_.planning = false;
      motion_.executing = true;
      CycleRequest r;
      r.kind = CycleRequest::Kind::kExecutePlan;
      r.id = next_id();
      r.plan_id = e.request_id;
      motion_.command_id = r.id;
      out_.push_back(r);
      last_command_utime_ = now_;
      set_deadline(e.duration_s + s_.motion_margin_s);
    }
  }
  check_timeout();
  return out_;
}

std::vector<CycleRequest> LibraryCycle::on_user(const UserEvent& e) {
  out_.clear();
  advance_time(e.utime);
  if (e.event == "abort" && state_ != CycleState::kAborted && state_ != CycleState::kDone) {
    abort("operator abort" + (e.detail.empty() ? std::string("") : ": " + e.detail));
  } else if (e.event == "done" && state_ == CycleState::kWaitUser) {
    message_ = "user \"done\"" + (e.detail.empty() ? std::string("") : ": " + e.detail);
    succeed(CycleState::kMoveToHolderPreGrasp);
  } else if (e.event == "taken" && state_ == CycleState::kWaitBookTaken) {
    // Not "done": the coordinator's own demo "done" for WAIT_USER comes back on the bus once it is in this state.
    book_done(true);
    succeed(CycleState::kPark);
  }
  check_timeout();
  return out_;
}

}  // namespace bookgrasp
