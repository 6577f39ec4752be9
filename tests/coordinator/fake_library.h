#pragma once
/// @file
/// A scripted stand-in for everything around the coordinator's state machine
/// (tests only): an arm that executes planned trajectories in 1 s and
/// integrates Cartesian velocities, a gripper that closes on the book in front
/// of it, a planner, the two servo tasks and an arbiter that answers as the
/// paper's strategy would for books at known places. Faults can be scripted.
/// Books live in the grasp frame of the default scene's cart.

#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "services/coordinator/library_cycle.h"

namespace bookgrasp_test {

using bookgrasp::CycleRequest;
using bookgrasp::LibraryCycle;

/// A book on the upper shelf (grasp frame).
struct FakeBook {
  int id = 0;
  double width = 0.02;
  double height = 0.2;   ///< top above the upper shelf = P1.x
  double right_y = 0.3;  ///< right cover = P1.y
};

/// The cart grasp frame of the default scene, by hand: X = base z, Y = -base y, Z = base x,
/// origin (0.60, -0.05, 0.0).
inline Eigen::Isometry3d hand_grasp_frame() {
  Eigen::Isometry3d g = Eigen::Isometry3d::Identity();
  g.linear().col(0) = Eigen::Vector3d(0, 0, 1);
  g.linear().col(1) = Eigen::Vector3d(0, -1, 0);
  g.linear().col(2) = Eigen::Vector3d(1, 0, 0);
  g.translation() = Eigen::Vector3d(0.60, -0.05, 0.0);
  return g;
}

/// Cart marker of the default scene (AprilTag axes), base (0.959, 0.15, 0.37), facing the robot.
inline Eigen::Isometry3d cart_marker_pose() {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear().col(0) = Eigen::Vector3d(0, -1, 0);
  t.linear().col(1) = Eigen::Vector3d(0, 0, -1);
  t.linear().col(2) = Eigen::Vector3d(1, 0, 0);
  t.translation() = Eigen::Vector3d(0.959, 0.15, 0.37);
  return t;
}

/// A holder marker facing the robot at base (0.30, 0.40, 0.10): support frame = base axes at
/// (0.30 + 0.001, 0.40 - 0.12, 0.10 - 0.19) = (0.301, 0.28, -0.09).
inline Eigen::Isometry3d holder_marker_pose() {
  Eigen::Isometry3d t = cart_marker_pose();
  t.translation() = Eigen::Vector3d(0.30, 0.40, 0.10);
  return t;
}

/// The world around the cycle.
class FakeLibrary {
 public:
  explicit FakeLibrary(std::vector<FakeBook> books) : upper(books.begin(), books.end()) {
    ee.translation() = Eigen::Vector3d(0.1, 0.0, -0.2);
    park_pose = ee;
  }

  // ---- scripted faults (each consumed once) ----
  std::map<std::string, int> plan_failures;  ///< state name -> failures of the next plans there
  int next_region_once = 0;                  ///< BwH rank 0 answers NEXT_REGION this many times
  int no_grasp_once = 0;                     ///< BwH answers NO_GRASP this many times
  int reroute_once = 0;                      ///< BwH answers `reroute_outcome` this many times
  std::string reroute_outcome = "P1_LED_ASTRAY";  ///< or RAISE_BWH_START: both re-route BwH within the attempt
  bool p1_absent_after_reroute = false;      ///< the P1 check after a re-route has no P1 (BwS missed the book there)
  bool rerouted = false;                     ///< a re-route was answered and its P1 check not yet made
  int missed_grasps = 0;                     ///< the gripper closes on nothing this many times
  /// The next N closes on the shelf take the right-most book and the one left of it: the plates stop at both
  /// books' width (from the first's right cover to the second's left one)
  int double_grasps = 0;
  /// P1 checks answer P1_INVALID (a P1 2 cm off PS) with this as the arbiter's front depth for the corner servo
  /// (gp_grasp's Z; NaN = the arbiter knew none)
  std::optional<double> invalid_p1_front_z;
  int missed_holder_grasps = 0;              ///< ... on the holder (the book stays there)
  bool servo_silent = false;                 ///< servo never answers (timeouts)
  bool servo_measures_width = false;         ///< the corner servo's CONVERGED carries the right-most book's width
                                             ///< (and, with a book left of it, that book's offset and width)
  /// > 0 (with servo_measures_width): the right-most book's page face is split this far left of R by a dark page
  /// line: the servo reports a fore-edge this wide and the rest of it as the next fore-edge, touching
  double servo_splits_front_at = 0.0;
  /// Set: the corner servo's CONVERGED carries this fore-edge width (NaN: a malformed report) and its next fore-edge
  /// touching it, as wide
  std::optional<double> servo_front_width;
  /// > 0: the stripe servo never finds an end and moves the TCP left (grasp -Y) at this speed (m/s) until it is
  /// cancelled or the arm stopped (a free stripe running out of the image on the left)
  double stripe_runs_left_m_s = 0.0;
  bool user_answers = true;                  ///< sends "done" in WAIT_USER after 1 s
  bool librarian_answers = true;             ///< in WAIT_BOOK_TAKEN: takes the book off the holder, "taken" after 1 s
  int arm_moves_during_planning = 0;         ///< the next N plans: the joints move 0.05 rad before the answer
  int coast_after_servo_ticks = 0;           ///< after each servo answer the arm still EXECUTES this many ticks
  /// State name -> base z the TCP cannot go below in that state's straight moves (the held book stands on its
  /// support early: it slid down in the plates)
  std::map<std::string, double> floor_z;
  /// State name -> (point, d): the driver stops a straight move there once the TCP is within d of the point (base),
  /// as at a joint limit
  std::map<std::string, std::pair<Eigen::Vector3d, double>> limit_near;

  // ---- world ----
  std::deque<FakeBook> upper;
  std::optional<FakeBook> in_gripper;
  std::optional<FakeBook> on_holder;
  std::vector<std::pair<FakeBook, Eigen::Isometry3d>> lower;       ///< book, TCP at release
  std::vector<std::pair<FakeBook, Eigen::Isometry3d>> holder_drops;  ///< book, TCP at release on the holder
  std::vector<std::pair<FakeBook, Eigen::Isometry3d>> holder_grasps;  ///< book, TCP at the grasp from the holder
  std::vector<FakeBook> taken_by_librarian;                           ///< books taken off the holder in WAIT_BOOK_TAKEN
  Eigen::Isometry3d ee = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d park_pose;
  double width = 0.06;
  bool contact = false;
  int arm_state = 0;
  std::string arm_message;  ///< the driver's message with arm_state
  int64_t active = 0;
  int64_t t = 1000000;
  std::vector<std::string> states;          ///< visited states, consecutive duplicates collapsed
  std::vector<std::pair<std::string, Eigen::Vector3d>> tcp_path;  ///< state and TCP position every tick
  std::vector<CycleRequest> requests;       ///< every request seen
  std::vector<int> arm_state_at_request;    ///< arm_state when each of `requests` was made
  std::vector<std::string> requests_state;  ///< the cycle's state when each of `requests` was made
  std::vector<std::string> messages;        ///< the cycle's status messages, consecutive duplicates collapsed
  std::vector<double> joints = std::vector<double>(7, 0.0);  ///< reported joints
  std::vector<std::string> user_events_sent;
  std::optional<Eigen::Vector3d> ps;        ///< the fake arbiter's PS
  bool cart_tag_hidden = false;             ///< MARKERS without the cart tag (the held book in front of it)

  /// Advances 10 ms: an arm state (and markers every 100 ms) to `cycle`, answering its requests.
  void tick(LibraryCycle& cycle) {
    t += 10000;
    state_now_ = bookgrasp::cycle_state_name(cycle.state());
    integrate();
    tcp_path.emplace_back(bookgrasp::cycle_state_name(cycle.state()), ee.translation());
    if ((t / 10000) % 10 == 0 || !markers_sent_) {
      bookgrasp::MarkersEvent m;
      m.utime = t;
      if (!cart_tag_hidden) m.cart = cart_marker_pose();
      m.holder = holder_marker_pose();
      handle(cycle, cycle.on_markers(m));
      markers_sent_ = true;
    }
    bookgrasp::ArmEvent e;
    e.utime = t;
    e.joints = joints;
    e.end_effector = ee;
    e.gripper_width = width;
    e.gripper_contact = contact;
    e.state = arm_state;
    e.message = arm_message;
    e.active_command_id = active;
    // Answers held back from earlier ticks reach the cycle after this arm state.
    std::vector<std::function<std::vector<CycleRequest>()>> delayed;
    delayed.swap(delayed_);
    handle(cycle, cycle.on_arm(e));
    for (auto& d : delayed) handle(cycle, d());
    // The arbiter answers each stereo frame (5 Hz) while the cycle waits for a P1 check.
    if (cycle.state() == bookgrasp::CycleState::kWaitP1Check && (t / 10000) % 20 == 0) {
      handle(cycle, cycle.on_decision(p1_check(0)));
      if (cycle.state() != bookgrasp::CycleState::kWaitP1Check) rerouted = false;
    }
    const bool librarian = cycle.state() == bookgrasp::CycleState::kWaitBookTaken && librarian_answers;
    if ((cycle.state() == bookgrasp::CycleState::kWaitUser && user_answers) || librarian) {
      if (wait_user_since_ < 0) wait_user_since_ = t;
      if (t - wait_user_since_ >= 1000000) {
        if (librarian && on_holder) {
          taken_by_librarian.push_back(*on_holder);
          on_holder.reset();
        }
        bookgrasp::UserEvent u;
        u.utime = t;
        u.event = librarian ? "taken" : "done";
        handle(cycle, cycle.on_user(u));
        wait_user_since_ = -1;
      }
    }
  }

  /// Ticks until `stop` holds or `max_ticks` passed. Returns the ticks run.
  template <typename Pred>
  int run(LibraryCycle& cycle, Pred stop, int max_ticks = 400000) {
    for (int i = 0; i < max_ticks; ++i) {
      if (stop()) return i;
      tick(cycle);
    }
    return max_ticks;
  }

 private:
  std::string state_now_;  ///< the cycle's state at this tick
  struct Plan {
    bool joints = false;
    Eigen::Isometry3d goal;
  };

  void record(const LibraryCycle& c) {
    const std::string s = bookgrasp::cycle_state_name(c.state());
    if (states.empty() || states.back() != s) states.push_back(s);
    const std::string m = c.status().message;
    if (messages.empty() || messages.back() != m) messages.push_back(m);
  }

  void integrate() {
    if (coast_until_ > 0 && t >= coast_until_) {
      arm_state = 0;
      coast_until_ = 0;
    }
    if (arm_state == 1 && executing_plan_ && t >= plan_end_) {
      ee = plan_goal_;
      arm_state = 0;
      executing_plan_ = false;
    }
    if (arm_state == 1 && !executing_plan_) {
      const double dt = 0.01;
      ee.translation() += twist_.head<3>() * dt;
      if (const auto f = floor_z.find(state_now_); f != floor_z.end())
        ee.translation().z() = std::max(ee.translation().z(), f->second);
      if (const auto l = limit_near.find(state_now_);
          l != limit_near.end() && (ee.translation() - l->second.first).norm() < l->second.second) {
        twist_.setZero();
        arm_state = 2;
        arm_message = "Cartesian motion reached the limit of joint arm_2_joint: stopped";
      }
      const Eigen::Vector3d w = twist_.tail<3>();
      if (w.norm() > 1e-12) ee.linear() = Eigen::AngleAxisd(w.norm() * dt, w.normalized()).toRotationMatrix() * ee.linear();
    }
  }

  static constexpr double kP1FrontZ = 0.012;  ///< the books' fronts as BwS measures them (P1.z), grasp frame
  static constexpr double kModelFrontZ = 0.01;  ///< the arbiter's model plane (arbiter.yaml cart.book_front_z_m)
  bookgrasp::DecisionEvent p1_check(int64_t request_id) const {
    bookgrasp::DecisionEvent d;
    d.utime = t;
    d.request_id = request_id;
    d.p1_present = !upper.empty() && !(rerouted && p1_absent_after_reroute);
    if (d.p1_present) d.p1_grasp = Eigen::Vector3d(upper.front().height, upper.front().right_y, kP1FrontZ);
    d.ps_present = ps.has_value();
    if (ps) d.ps_grasp = *ps;
    if (!ps) {
      d.outcome = "NEED_PS";
    } else if (!upper.empty() && invalid_p1_front_z) {
      d.outcome = "P1_INVALID";
      d.gp_grasp = Eigen::Vector3d(ps->x(), ps->y(), *invalid_p1_front_z);
    } else if (d.p1_present) {
      d.outcome = "P1_VALID";
      d.gp_grasp = Eigen::Vector3d(upper.front().height, upper.front().right_y, kP1FrontZ);
    } else {
      d.outcome = "P1_INVALID";
      d.gp_grasp = Eigen::Vector3d(ps->x(), ps->y(), kModelFrontZ);
    }
    d.reason = d.outcome + ": fake arbiter";
    return d;
  }

  void handle(LibraryCycle& cycle, std::vector<CycleRequest> reqs) {
    record(cycle);
    std::vector<std::function<std::vector<CycleRequest>()>> later;
    for (const CycleRequest& r : reqs) {
      requests.push_back(r);
      arm_state_at_request.push_back(arm_state);
      const std::string state = bookgrasp::cycle_state_name(cycle.state());
      requests_state.push_back(state);
      switch (r.kind) {
        case CycleRequest::Kind::kPlan: {
          Plan p;
          p.joints = r.joints_goal;
          p.goal = r.joints_goal ? park_pose : r.pose;
          plans_[r.id] = p;
          bookgrasp::PlanEvent e;
          e.utime = t;
          e.request_id = r.id;
          auto it = plan_failures.find(state);
          if (it != plan_failures.end() && it->second > 0) {
            --it->second;
            e.success = false;
            e.message = "scripted planning failure";
          } else {
            e.success = true;
            e.duration_s = 1.0;
          }
          if (arm_moves_during_planning > 0) {
            --arm_moves_during_planning;
            joints[3] += 0.05;
            delayed_.push_back([&cycle, e] { return cycle.on_plan(e); });
            break;
          }
          later.push_back([&cycle, e] { return cycle.on_plan(e); });
          break;
        }
        case CycleRequest::Kind::kExecutePlan:
          active = r.id;
          arm_state = 1;
          executing_plan_ = true;
          plan_end_ = t + 1000000;
          plan_goal_ = plans_.at(r.plan_id).goal;
          break;
        case CycleRequest::Kind::kTwist:
          active = r.id;
          arm_state = 1;
          arm_message.clear();
          executing_plan_ = false;
          twist_ = r.twist;
          break;
        case CycleRequest::Kind::kArmStop:
          twist_.setZero();
          executing_plan_ = false;
          arm_state = 2;
          break;
        case CycleRequest::Kind::kGripperMove:
          width = r.width;
          contact = false;
          if (in_gripper && state == "RELEASE_ON_HOLDER") {
            on_holder = in_gripper;
            holder_drops.emplace_back(*in_gripper, ee);
            in_gripper.reset();
          } else if (in_gripper && state == "RELEASE_ON_LOWER_SHELF") {
            lower.emplace_back(*in_gripper, ee);
            in_gripper.reset();
          } else if (in_gripper && state == "BACK_OUT") {  // opened among the books: it stays on the shelf
            upper.push_front(*in_gripper);
            in_gripper.reset();
          }
          break;
        case CycleRequest::Kind::kGripperGrasp:
          if (state == "CLOSE_GRIPPER" && missed_grasps > 0) {
            --missed_grasps;
            width = 0.0;
            contact = false;
          } else if (state == "CLOSE_GRIPPER" && double_grasps > 0 && upper.size() > 1) {
            --double_grasps;
            in_gripper = upper.front();
            upper.pop_front();
            width = in_gripper->right_y - (upper.front().right_y - upper.front().width);
            contact = true;
          } else if (state == "CLOSE_GRIPPER" && !upper.empty()) {
            in_gripper = upper.front();
            upper.pop_front();
            width = in_gripper->width;
            contact = true;
            ps = Eigen::Vector3d(0.10, in_gripper->right_y - in_gripper->width, -0.10);  // PS.y = GP.y - BW
          } else if (state == "GRASP_FROM_HOLDER" && on_holder && missed_holder_grasps > 0) {
            --missed_holder_grasps;
            width = 0.0;
            contact = false;
          } else if (state == "GRASP_FROM_HOLDER" && on_holder) {
            holder_grasps.emplace_back(*on_holder, ee);
            in_gripper = on_holder;
            on_holder.reset();
            width = in_gripper->width;
            contact = true;
          } else {
            width = 0.0;
            contact = false;
          }
          break;
        case CycleRequest::Kind::kServo: {
          if (servo_silent) break;
          if (r.servo_mode == 2 && stripe_runs_left_m_s > 0) {
            active = r.id;
            arm_state = 1;
            executing_plan_ = false;
            twist_.setZero();
            twist_.head<3>() = hand_grasp_frame().linear() * Eigen::Vector3d(0, -stripe_runs_left_m_s, 0);
            break;
          }
          // With coasting, the servo's answers arrive after an arm state that shows the arm moving.
          auto& answers = coast_after_servo_ticks > 0 ? delayed_ : later;
          if (coast_after_servo_ticks > 0) {
            arm_state = 1;
            executing_plan_ = false;
            twist_.setZero();
            coast_until_ = t + 10000 * coast_after_servo_ticks;
          }
          bookgrasp::ServoEvent s;
          s.utime = t;
          s.request_id = r.id;
          s.mode = r.servo_mode;
          s.state = 2;  // CONVERGED
          if (r.servo_mode == 1 && servo_measures_width && !upper.empty()) s.front_width_m = upper.front().width;
          if (r.servo_mode == 1 && servo_measures_width && upper.size() > 1) {  // the next fore-edge to the left
            s.neighbour_offset_m = upper[0].right_y - upper[1].right_y;
            s.neighbour_width_m = upper[1].width;
          }
          if (r.servo_mode == 1 && servo_measures_width && servo_splits_front_at > 0 && !upper.empty()) {
            s.front_width_m = servo_splits_front_at;
            s.neighbour_offset_m = servo_splits_front_at;
            s.neighbour_width_m = upper.front().width - servo_splits_front_at;
          }
          if (r.servo_mode == 1 && servo_front_width)
            s.front_width_m = s.neighbour_offset_m = s.neighbour_width_m = *servo_front_width;
          answers.push_back([&cycle, s] { return cycle.on_servo(s); });
          if (r.servo_mode == 2) {  // STRIPE_END: PS where the right-most book hides the stripe
            ps = Eigen::Vector3d(0.10, upper.empty() ? -0.395 : upper.front().right_y, -0.10);
            const bookgrasp::DecisionEvent d = p1_check(r.id);
            answers.push_back([&cycle, d] { return cycle.on_decision(d); });
          } else {
            bookgrasp::DecisionEvent d;
            d.utime = t;
            d.request_id = r.id;
            if (r.rank == 0 && next_region_once > 0) {
              --next_region_once;
              d.outcome = "NEXT_REGION";
              d.next_rank = 1;
            } else if (reroute_once > 0) {
              --reroute_once;
              d.outcome = reroute_outcome;
              rerouted = true;
            } else if (no_grasp_once > 0 || upper.empty()) {
              if (no_grasp_once > 0) --no_grasp_once;
              d.outcome = "NO_GRASP";
            } else {
              d.outcome = "GRASP";
              d.valid = true;
              d.p1_present = true;
              d.gp_grasp = Eigen::Vector3d(upper.front().height, upper.front().right_y, 0.01);
              d.gp_base = hand_grasp_frame();
              d.gp_base.translation() = hand_grasp_frame() * d.gp_grasp;
            }
            d.reason = d.outcome + ": fake arbiter";
            answers.push_back([&cycle, d] { return cycle.on_decision(d); });
          }
          break;
        }
        case CycleRequest::Kind::kUserEvent:
          user_events_sent.push_back(r.text);
          break;
        default:
          break;
      }
    }
    for (auto& f : later) handle(cycle, f());
  }

  bool markers_sent_ = false;
  bool executing_plan_ = false;
  int64_t plan_end_ = 0;
  Eigen::Isometry3d plan_goal_ = Eigen::Isometry3d::Identity();
  Eigen::Matrix<double, 6, 1> twist_ = Eigen::Matrix<double, 6, 1>::Zero();
  std::map<int64_t, Plan> plans_;
  int64_t wait_user_since_ = -1;
  int64_t coast_until_ = 0;
  std::vector<std::function<std::vector<CycleRequest>()>> delayed_;
};

}  // namespace bookgrasp_test
