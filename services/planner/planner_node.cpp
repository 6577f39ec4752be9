#include "services/planner/planner_node.h"

#include <cmath>

#include "common/pose_conversion.h"

namespace bookgrasp {
namespace {

uint64_t mix_seed(uint64_t x) {  // splitmix64: request identity -> planner seed
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

constexpr double kMaxObstacleSizeM = 2.0;  // a request's box larger than this is a mistake (the cart is 0.84 m wide)

bool all_finite(const std::vector<double>& v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

}  // namespace

PlannerNode::PlannerNode(const PlannerSettings& settings)
    : Component("planner", "cellbirrt_ompl_fcl"),
      settings_(settings),
      stack_(std::make_unique<PlannerStack>(settings)),
      scene_(stack_->scene) {
  subscribe(settings_.channel_plan_request, &PlannerNode::on_request);
  subscribe(settings_.channel_markers, &PlannerNode::on_markers);
}

bool PlannerNode::apply_markers(const marker_detections_t& msg, std::string* reason) {
  std::map<std::string, Eigen::Isometry3d> updates;
  for (const marker_t& m : msg.markers) {
    if (m.role != "cart" && m.role != "holder") continue;
    if (!is_valid_pose(m.pose_in_base)) {
      *reason = "marker '" + m.role + "' (id " + std::to_string(m.id) + ") has an invalid pose_in_base (NaN or non-unit quaternion)";
      return false;
    }
    if (!m.pose_in_base.frame.empty() && m.pose_in_base.frame != "base") {
      *reason = "marker '" + m.role + "' pose_in_base is in frame '" + m.pose_in_base.frame + "', expected 'base'";
      return false;
    }
    updates[m.role] = pose_to_isometry(m.pose_in_base);
  }
  if (static_cast<int>(msg.markers.size()) != msg.num_markers) {
    *reason = "num_markers " + std::to_string(msg.num_markers) + " differs from the array length";
    return false;
  }
  if (updates.empty()) return true;
  for (const auto& [role, pose] : updates) marker_poses_[role] = pose;
  std::vector<std::pair<std::string, Eigen::Isometry3d>> poses(marker_poses_.begin(), marker_poses_.end());
  scene_.set_environment(build_environment(settings_.geometry, poses));
  return true;
}

plan_result_t PlannerNode::process(const plan_request_t& req) const {
  plan_result_t out;
  out.utime = req.utime;
  out.request_id = req.request_id;
  out.success = false;
  out.failure = plan_result_t::NONE;
  out.planner = req.planner.empty() ? settings_.planner.default_planner : req.planner;
  out.planning_time_s = 0.0;
  out.path_length_rad = 0.0;
  const ArmKinematics& kin = stack_->kinematics;
  const int n = kin.num_joints();
  out.trajectory.utime = req.utime;
  out.trajectory.num_joints = n;
  out.trajectory.joint_names = kin.joint_names();
  out.trajectory.num_points = 0;
  const auto invalid = [&](const std::string& why) {
    out.failure = plan_result_t::INVALID_REQUEST;
    out.message = "invalid request: " + why;
    return out;
  };

  // ---- validation of the message itself ----
  if (req.num_joints != n) return invalid("num_joints is " + std::to_string(req.num_joints) + ", the arm has " + std::to_string(n));
  if (static_cast<int>(req.start_joints.size()) != n || static_cast<int>(req.goal_joints.size()) != n)
    return invalid("start_joints/goal_joints lengths differ from num_joints");
  if (!all_finite(req.start_joints)) return invalid("start_joints contain NaN or infinity");
  if (req.goal_type != plan_request_t::JOINTS && req.goal_type != plan_request_t::POSE)
    return invalid("goal_type " + std::to_string(req.goal_type) + " is neither JOINTS (1) nor POSE (2)");
  if (req.goal_type == plan_request_t::JOINTS && !all_finite(req.goal_joints))
    return invalid("goal_joints contain NaN or infinity");
  if (req.goal_type == plan_request_t::POSE) {
    if (!is_valid_pose(req.goal_pose)) return invalid("goal_pose is not a rigid transform (NaN or non-unit quaternion)");
    if (!req.goal_pose.frame.empty() && req.goal_pose.frame != "base")
      return invalid("goal_pose is in frame '" + req.goal_pose.frame + "'; give it in 'base'");
  }
  if (req.num_then_poses < 0 || static_cast<size_t>(req.num_then_poses) != req.then_poses.size())
    return invalid("num_then_poses " + std::to_string(req.num_then_poses) + " differs from then_poses' length");
  if (req.num_then_poses > 0 && req.goal_type != plan_request_t::POSE)
    return invalid("then_poses need a POSE goal (they are tracked from its IK solutions)");
  for (size_t i = 0; i < req.then_poses.size(); ++i) {
    if (!is_valid_pose(req.then_poses[i]))
      return invalid("then_poses[" + std::to_string(i) + "] is not a rigid transform (NaN or non-unit quaternion)");
    if (!req.then_poses[i].frame.empty() && req.then_poses[i].frame != "base")
      return invalid("then_poses[" + std::to_string(i) + "] is in frame '" + req.then_poses[i].frame +
                     "'; give it in 'base'");
  }
  if (req.num_obstacles < 0 || static_cast<size_t>(req.num_obstacles) != req.obstacles.size())
    return invalid("num_obstacles " + std::to_string(req.num_obstacles) + " differs from obstacles' length");
  std::vector<SceneBox> obstacles;
  for (size_t i = 0; i < req.obstacles.size(); ++i) {
    const obstacle_box_t& b = req.obstacles[i];
    const std::string which = "obstacles[" + std::to_string(i) + "] ('" + b.name + "')";
    if (!is_valid_pose(b.pose)) return invalid(which + " pose is not a rigid transform (NaN or non-unit quaternion)");
    if (!b.pose.frame.empty() && b.pose.frame != "base")
      return invalid(which + " is in frame '" + b.pose.frame + "'; give it in 'base'");
    for (double s : b.size_m)
      if (!std::isfinite(s) || s <= 0 || s > kMaxObstacleSizeM)
        return invalid(which + " size_m must be three sizes in (0, " + std::to_string(kMaxObstacleSizeM) + "] m");
    obstacles.push_back(SceneBox{"request_" + b.name, pose_to_isometry(b.pose),
                                 Eigen::Vector3d(b.size_m[0], b.size_m[1], b.size_m[2])});
  }
  if (!std::isfinite(req.time_budget_s) || req.time_budget_s < 0) return invalid("time_budget_s must be >= 0 (0 = default)");
  if (req.time_budget_s > settings_.max_time_budget_s)
    return invalid("time_budget_s " + std::to_string(req.time_budget_s) + " exceeds planner.max_time_budget_s " +
                   std::to_string(settings_.max_time_budget_s));
  if (req.holding_book) {
    for (double s : req.held_book_size_m)
      if (!std::isfinite(s) || s <= 0 || s > 1.0) return invalid("held_book_size_m must be three sizes in (0, 1] m");
  }

  // ---- the core ----
  PlanRequest r;
  r.start = Eigen::Map<const Eigen::VectorXd>(req.start_joints.data(), n);
  r.goal_is_pose = req.goal_type == plan_request_t::POSE;
  if (!r.goal_is_pose) r.goal_joints = Eigen::Map<const Eigen::VectorXd>(req.goal_joints.data(), n);
  else r.goal_pose = pose_to_isometry(req.goal_pose);
  r.position_tolerance_m = req.position_tolerance_m;
  r.orientation_tolerance_rad = req.orientation_tolerance_rad;
  r.keep_orientation = req.keep_orientation;
  for (const pose_t& p : req.then_poses) r.then_poses.push_back(pose_to_isometry(p));
  if (req.holding_book) {
    r.max_tool_tilt_rad = settings_.held_book.max_tilt_rad;
    r.max_tool_pitch_rad = settings_.held_book.max_pitch_rad;
  }
  r.time_budget_s = req.time_budget_s > 0 ? req.time_budget_s : settings_.default_time_budget_s;
  r.planner = req.planner;
  r.seed = mix_seed(static_cast<uint64_t>(req.utime) ^ mix_seed(static_cast<uint64_t>(req.request_id)) ^ settings_.ik.seed);
  PlanningScene scene = scene_;
  if (!obstacles.empty()) {
    std::vector<SceneBox> environment = scene.environment();
    environment.insert(environment.end(), obstacles.begin(), obstacles.end());
    scene.set_environment(std::move(environment));
  }
  if (req.holding_book)
    scene.attach(held_book_box(Eigen::Vector3d(req.held_book_size_m[0], req.held_book_size_m[1], req.held_book_size_m[2]),
                               settings_.held_book));
  const PlanOutcome o = stack_->planner.plan(scene, r);
  out.success = o.success;
  out.failure = static_cast<int8_t>(o.failure);
  out.message = o.message;
  out.planner = o.planner;
  out.planning_time_s = o.planning_time_s;
  out.path_length_rad = o.path_length_rad;
  if (o.success) {
    for (const TimedPoint& p : o.trajectory.points) {
      trajectory_point_t tp;
      tp.utime = static_cast<int64_t>(std::llround(p.time_s * 1e6));
      tp.num_joints = n;
      tp.positions.assign(p.position.data(), p.position.data() + n);
      tp.velocities.assign(p.velocity.data(), p.velocity.data() + n);
      tp.accelerations.assign(p.acceleration.data(), p.acceleration.data() + n);
      out.trajectory.points.push_back(tp);
    }
    out.trajectory.num_points = static_cast<int32_t>(out.trajectory.points.size());
  }
  return out;
}

void PlannerNode::on_request(const plan_request_t& request) {
  // Restarted while the task runs, the planner knows the cart and the holder only at their nominal poses until
  // the first MARKERS: a plan there can drive the held book into the cart. The request waits for them (a newer
  // one replaces it; the requester's own timeout still applies).
  if (settings_.defer_until_markers && marker_poses_.empty()) {
    deferred_ = request;
    return;
  }
  answer(request);
}

void PlannerNode::answer(const plan_request_t& request) {
  const plan_result_t result = process(request);
  if (result.failure == plan_result_t::INVALID_REQUEST) reject(settings_.channel_plan_request, result.message);
  publish(settings_.channel_plan_result, result);
}

void PlannerNode::on_markers(const marker_detections_t& markers) {
  std::string reason;
  if (!apply_markers(markers, &reason)) {
    reject(settings_.channel_markers, reason);
    return;
  }
  if (deferred_ && !marker_poses_.empty()) {
    const plan_request_t r = std::move(*deferred_);
    deferred_.reset();
    answer(r);
  }
}

}  // namespace bookgrasp
