#include "services/coordinator/coordinator_node.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "bookgrasp/arm_command_t.hpp"
#include "bookgrasp/gripper_command_t.hpp"
#include "bookgrasp/plan_request_t.hpp"
#include "bookgrasp/servo_request_t.hpp"
#include "bookgrasp/task_status_t.hpp"
#include "common/pose_conversion.h"

namespace bookgrasp {
namespace {

std::optional<TaskProgress> load_or_explain(const std::string& path) {
  try {
    return load_progress(path);
  } catch (const std::exception& e) {
    throw ConfigError(std::string("progress file is unreadable: ") + e.what() +
                      " (fix it, or move it away to start the task afresh)");
  }
}

bool finite3(const double (&v)[3]) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

}  // namespace

DecisionEvent decision_from_message(const grasp_point_t& msg) {
  DecisionEvent d;
  d.utime = msg.utime;
  d.request_id = msg.request_id;
  const std::string head = msg.reason.substr(0, msg.reason.find(':'));
  std::istringstream words(head);
  words >> d.outcome;
  if (d.outcome == "NEXT_REGION") {
    std::string rank_word;
    words >> rank_word >> d.next_rank;
    if (rank_word != "rank" || words.fail())
      throw std::invalid_argument("NEXT_REGION without 'rank N' in the reason: " + msg.reason);
  }
  d.valid = msg.valid;
  d.p1_present = finite3(msg.p1_grasp);
  if (d.p1_present) d.p1_grasp = Eigen::Vector3d(msg.p1_grasp[0], msg.p1_grasp[1], msg.p1_grasp[2]);
  d.ps_present = finite3(msg.ps_grasp);
  if (d.ps_present) d.ps_grasp = Eigen::Vector3d(msg.ps_grasp[0], msg.ps_grasp[1], msg.ps_grasp[2]);
  if (finite3(msg.gp_grasp)) d.gp_grasp = Eigen::Vector3d(msg.gp_grasp[0], msg.gp_grasp[1], msg.gp_grasp[2]);
  d.gp_base = pose_to_isometry(msg.gp_base);
  d.reason = msg.reason;
  return d;
}

CoordinatorNode::CoordinatorNode(const Config& root)
    : Component(root.get<std::string>("service.name"), root.get<std::string>("service.implementation")),
      settings_(CycleSettings::from_config(root)),
      cycle_(settings_, load_or_explain(root.get<std::string>("progress_file"))) {
  const Config c = root.child("channels");
  ch_.arm_state = c.get<std::string>("arm_state");
  ch_.markers = c.get<std::string>("markers");
  ch_.grasp_point = c.get<std::string>("grasp_point");
  ch_.servo_status = c.get<std::string>("servo_status");
  ch_.plan_result = c.get<std::string>("plan_result");
  ch_.user_event = c.get<std::string>("user_event");
  ch_.servo_request = c.get<std::string>("servo_request");
  ch_.plan_request = c.get<std::string>("plan_request");
  ch_.arm_command = c.get<std::string>("arm_command");
  ch_.gripper_command = c.get<std::string>("gripper_command");
  ch_.task_status = c.get<std::string>("task_status");
  cart_role_ = root.get<std::string>("markers.cart_role");
  holder_role_ = root.get<std::string>("markers.holder_role");
  progress_path_ = root.get<std::string>("progress_file");
  if (progress_path_.empty())
    throw ConfigError(root.source() + ": progress_file is empty: give a path for the persisted progress");
  status_period_s_ = root.get_double("task_status_period_s", 0.01, 60);
  subscribe(ch_.arm_state, &CoordinatorNode::on_arm_state);
  subscribe(ch_.markers, &CoordinatorNode::on_markers);
  subscribe(ch_.grasp_point, &CoordinatorNode::on_grasp_point);
  subscribe(ch_.servo_status, &CoordinatorNode::on_servo_status);
  subscribe(ch_.plan_result, &CoordinatorNode::on_plan_result);
  subscribe(ch_.user_event, &CoordinatorNode::on_user_event);
}

void CoordinatorNode::on_arm_state(const arm_state_t& msg) {
  if (msg.num_joints != static_cast<int32_t>(msg.positions.size()) || msg.num_joints <= 0) {
    reject(ch_.arm_state, "num_joints does not match the positions (or is 0)");
    return;
  }
  if (!is_valid_pose(msg.end_effector) || !std::isfinite(msg.gripper_width_m)) {
    reject(ch_.arm_state, "end_effector pose or gripper_width_m is not finite");
    return;
  }
  for (double q : msg.positions)
    if (!std::isfinite(q)) {
      reject(ch_.arm_state, "a joint position is not finite");
      return;
    }
  joint_names_ = msg.joint_names;
  ArmEvent e;
  e.utime = msg.utime;
  e.joints = msg.positions;
  e.end_effector = pose_to_isometry(msg.end_effector);
  e.gripper_width = msg.gripper_width_m;
  e.gripper_contact = msg.gripper_contact;
  e.state = msg.state;
  e.active_command_id = msg.active_command_id;
  e.message = msg.message;
  send(cycle_.on_arm(e), msg.utime);
  after_event(msg.utime);
}

void CoordinatorNode::on_markers(const marker_detections_t& msg) {
  MarkersEvent e;
  e.utime = msg.utime;
  for (const marker_t& m : msg.markers) {
    if (m.role != cart_role_ && m.role != holder_role_) continue;
    if (!is_valid_pose(m.pose_in_base)) {
      reject(ch_.markers, m.role + " marker " + std::to_string(m.id) + " has an invalid pose_in_base");
      continue;
    }
    (m.role == cart_role_ ? e.cart : e.holder) = pose_to_isometry(m.pose_in_base);
  }
  send(cycle_.on_markers(e), msg.utime);
  after_event(msg.utime);
}

void CoordinatorNode::on_grasp_point(const grasp_point_t& msg) {
  if (!is_valid_pose(msg.gp_base)) {
    reject(ch_.grasp_point, "gp_base is not a valid pose");
    return;
  }
  if (msg.valid && !finite3(msg.gp_grasp)) {
    reject(ch_.grasp_point, "valid grasp point with a non-finite gp_grasp");
    return;
  }
  send(cycle_.on_decision(decision_from_message(msg)), msg.utime);  // a bad NEXT_REGION reason throws: rejected
  after_event(msg.utime);
}

void CoordinatorNode::on_servo_status(const servo_status_t& msg) {
  ServoEvent e;
  e.utime = msg.utime;
  e.request_id = msg.request_id;
  e.mode = msg.mode;
  e.state = msg.state;
  e.front_width_m = msg.front_width_m;
  e.neighbour_offset_m = msg.neighbour_offset_m;
  e.neighbour_width_m = msg.neighbour_width_m;
  e.message = msg.message;
  send(cycle_.on_servo(e), msg.utime);
  after_event(msg.utime);
}

void CoordinatorNode::on_plan_result(const plan_result_t& msg) {
  PlanEvent e;
  e.utime = msg.utime;
  e.request_id = msg.request_id;
  e.success = msg.success;
  e.message = msg.message;
  if (msg.success) {
    const joint_trajectory_t& t = msg.trajectory;
    if (t.num_points != static_cast<int32_t>(t.points.size()) || t.num_points < 1) {
      reject(ch_.plan_result, "successful plan " + std::to_string(msg.request_id) + " without trajectory points");
      return;
    }
    e.duration_s = static_cast<double>(t.points.back().utime) * 1e-6;
    plans_[msg.request_id] = t;
    while (plans_.size() > 16) plans_.erase(plans_.begin());
  }
  send(cycle_.on_plan(e), msg.utime);
  after_event(msg.utime);
}

void CoordinatorNode::on_user_event(const user_event_t& msg) {
  UserEvent e;
  e.utime = msg.utime;
  e.event = msg.event;
  e.detail = msg.detail;
  send(cycle_.on_user(e), msg.utime);
  after_event(msg.utime);
}

plan_request_t plan_request_message(const CycleRequest& r, const CycleSettings& settings, int64_t utime) {
  plan_request_t m;
  m.utime = utime;
  m.request_id = r.id;
  m.planner = settings.planner;
  m.goal_type = r.joints_goal ? plan_request_t::JOINTS : plan_request_t::POSE;
  m.num_joints = static_cast<int32_t>(r.start_joints.size());
  m.start_joints = r.start_joints;
  m.goal_joints = r.joints_goal ? r.goal_joints : std::vector<double>(r.start_joints.size(), 0.0);
  m.goal_joints.resize(r.start_joints.size(), 0.0);
  m.goal_pose = isometry_to_pose(r.pose, "base", "gripper", utime);
  m.position_tolerance_m = settings.plan_position_tolerance_m;
  m.orientation_tolerance_rad = settings.plan_orientation_tolerance_rad;
  m.keep_orientation = false;
  m.time_budget_s = settings.plan_time_budget_s;
  m.holding_book = r.holding_book;
  for (int i = 0; i < 3; ++i) m.held_book_size_m[i] = r.book_size[i];
  m.num_then_poses = static_cast<int32_t>(r.then_poses.size());
  for (const Eigen::Isometry3d& p : r.then_poses) m.then_poses.push_back(isometry_to_pose(p, "base", "gripper", utime));
  m.num_obstacles = static_cast<int32_t>(r.obstacles.size());
  for (const auto& [name, box] : r.obstacles) {
    obstacle_box_t o;
    o.utime = utime;
    o.name = name;
    o.pose = isometry_to_pose(box.pose, "base", name, utime);
    for (int i = 0; i < 3; ++i) o.size_m[i] = box.size[i];
    m.obstacles.push_back(o);
  }
  return m;
}

void CoordinatorNode::send(const std::vector<CycleRequest>& requests, int64_t utime) {
  for (const CycleRequest& r : requests) {
    switch (r.kind) {
      case CycleRequest::Kind::kServo:
      case CycleRequest::Kind::kServoCancel: {
        servo_request_t m;
        m.utime = utime;
        m.request_id = r.id;
        m.mode = r.kind == CycleRequest::Kind::kServoCancel ? servo_request_t::CANCEL
                                                             : static_cast<int8_t>(r.servo_mode);
        m.start_pose = isometry_to_pose(r.pose, "base", "gripper", utime);
        if (r.kind == CycleRequest::Kind::kServoCancel) m.start_pose.frame = "";  // no start pose
        m.fixed_depth_m = r.fixed_depth;
        m.rank_from_right = r.rank;
        m.timeout_s = r.timeout_s;
        publish(ch_.servo_request, m);
        break;
      }
      case CycleRequest::Kind::kPlan: {
        publish(ch_.plan_request, plan_request_message(r, settings_, utime));
        break;
      }
      case CycleRequest::Kind::kExecutePlan:
      case CycleRequest::Kind::kTwist:
      case CycleRequest::Kind::kArmStop:
      case CycleRequest::Kind::kHeartbeat: {
        arm_command_t m;
        m.utime = utime;
        m.command_id = r.id;
        m.trajectory.utime = utime;
        m.trajectory.num_joints = 0;
        m.trajectory.num_points = 0;
        for (double& t : m.twist) t = 0;
        m.twist_frame = "base";
        if (r.kind == CycleRequest::Kind::kExecutePlan) {
          const auto it = plans_.find(r.plan_id);
          if (it == plans_.end()) {
            report_error("no stored trajectory for plan " + std::to_string(r.plan_id));
            break;
          }
          m.mode = arm_command_t::TRAJECTORY;
          m.trajectory = it->second;
        } else if (r.kind == CycleRequest::Kind::kTwist) {
          m.mode = arm_command_t::CARTESIAN_VELOCITY;
          for (int i = 0; i < 6; ++i) m.twist[i] = r.twist[i];
        } else {
          m.mode = r.kind == CycleRequest::Kind::kArmStop ? arm_command_t::STOP : arm_command_t::HEARTBEAT;
        }
        publish(ch_.arm_command, m);
        break;
      }
      case CycleRequest::Kind::kGripperMove:
      case CycleRequest::Kind::kGripperGrasp: {
        gripper_command_t m;
        m.utime = utime;
        m.command_id = r.id;
        m.mode = r.kind == CycleRequest::Kind::kGripperGrasp ? gripper_command_t::GRASP : gripper_command_t::MOVE;
        m.width_m = r.width;
        m.speed_mps = r.speed;
        m.force_n = r.force;
        publish(ch_.gripper_command, m);
        break;
      }
      case CycleRequest::Kind::kUserEvent: {
        user_event_t m;
        m.utime = utime;
        m.event = r.text;
        m.detail = r.detail;
        publish(ch_.user_event, m);
        break;
      }
    }
  }
}

void CoordinatorNode::after_event(int64_t utime) {
  if (cycle_.take_progress_changed()) {
    try {
      save_progress(progress_path_, cycle_.progress());
    } catch (const std::exception& e) {
      report_error(std::string("cannot persist the progress: ") + e.what());
    }
  }
  const bool changed = cycle_.take_status_changed();
  if (!changed && last_status_utime_ >= 0 &&
      static_cast<double>(utime - last_status_utime_) < status_period_s_ * 1e6)
    return;
  const CycleStatus s = cycle_.status();
  task_status_t m;
  m.utime = utime;
  m.state = s.state;
  m.books_total = s.books_total;
  m.books_moved = s.books_moved;
  m.current_book = s.current_book;
  m.attempt = s.attempt;
  m.failures = s.failures;
  m.message = s.message;
  publish(ch_.task_status, m);
  last_status_utime_ = utime;
}

}  // namespace bookgrasp
