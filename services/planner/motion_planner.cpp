#include "services/planner/motion_planner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <sstream>
#include <stdexcept>

#include <ompl/base/MotionValidator.h>
#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/StateSampler.h>
#include <ompl/base/goals/GoalStates.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/planners/rrt/BiTRRT.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>

#include "services/planner/cell_birrt.h"
#include "services/planner/path_simplifier.h"

namespace bookgrasp {
namespace ob = ompl::base;
namespace og = ompl::geometric;

namespace {

using StateCheck = std::function<bool(const Eigen::VectorXd&)>;

void to_state(const Eigen::VectorXd& q, ob::State* s) {
  auto* v = s->as<ob::RealVectorStateSpace::StateType>()->values;
  for (Eigen::Index i = 0; i < q.size(); ++i) v[i] = q[i];
}

Eigen::VectorXd from_state(const ob::State* s, int n) {
  const auto* v = s->as<ob::RealVectorStateSpace::StateType>()->values;
  Eigen::VectorXd q(n);
  for (int i = 0; i < n; ++i) q[i] = v[i];
  return q;
}

// Interpolated check of a straight joint-space segment; `a` is not re-checked. Without
// `last_valid_fraction` the points are visited coarse to fine (bisection order), which finds a
// collision on a long segment after a few checks; the set of points checked is the same.
bool segment_ok(const StateCheck& valid, const Eigen::VectorXd& a, const Eigen::VectorXd& b, double resolution,
                double* last_valid_fraction = nullptr) {
  const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / resolution)));
  if (!last_valid_fraction) {
    int top = 1;
    while (top < steps) top *= 2;
    for (int stride = top; stride >= 1; stride /= 2)
      for (int i = stride; i <= steps; i += 2 * stride)
        if (!valid(a + (static_cast<double>(i) / steps) * (b - a))) return false;
    return true;
  }
  for (int i = 1; i <= steps; ++i) {
    const double t = static_cast<double>(i) / steps;
    if (!valid(a + t * (b - a))) {
      *last_valid_fraction = static_cast<double>(i - 1) / steps;
      return false;
    }
  }
  *last_valid_fraction = 1.0;
  return true;
}

/// OMPL motion validator on top of the same interpolated check the simplifier uses.
class InterpolatingMotionValidator : public ob::MotionValidator {
 public:
  InterpolatingMotionValidator(const ob::SpaceInformationPtr& si, StateCheck check, double resolution, int n)
      : ob::MotionValidator(si), check_(std::move(check)), resolution_(resolution), n_(n) {}
  bool checkMotion(const ob::State* s1, const ob::State* s2) const override {
    const bool ok = segment_ok(check_, from_state(s1, n_), from_state(s2, n_), resolution_);
    if (ok) ++valid_;
    else ++invalid_;
    return ok;
  }
  bool checkMotion(const ob::State* s1, const ob::State* s2, std::pair<ob::State*, double>& last_valid) const override {
    double f = 0;
    const Eigen::VectorXd a = from_state(s1, n_), b = from_state(s2, n_);
    const bool ok = segment_ok(check_, a, b, resolution_, &f);
    if (!ok) {
      if (last_valid.first) to_state(a + f * (b - a), last_valid.first);
      last_valid.second = f;
      ++invalid_;
    } else {
      ++valid_;
    }
    return ok;
  }

 private:
  StateCheck check_;
  double resolution_;
  int n_;
};

/// Uniform sampler with its own seeded generator, so stock planners are repeatable per request.
class SeededSampler : public ob::StateSampler {
 public:
  SeededSampler(const ob::StateSpace* space, uint64_t seed) : ob::StateSampler(space), gen_(seed) {
    const auto& b = space->as<ob::RealVectorStateSpace>()->getBounds();
    low_ = b.low;
    high_ = b.high;
  }
  void sampleUniform(ob::State* s) override {
    auto* v = s->as<ob::RealVectorStateSpace::StateType>()->values;
    for (size_t i = 0; i < low_.size(); ++i) v[i] = std::uniform_real_distribution<double>(low_[i], high_[i])(gen_);
  }
  void sampleUniformNear(ob::State* s, const ob::State* near, double distance) override {
    auto* v = s->as<ob::RealVectorStateSpace::StateType>()->values;
    const auto* c = near->as<ob::RealVectorStateSpace::StateType>()->values;
    for (size_t i = 0; i < low_.size(); ++i)
      v[i] = std::uniform_real_distribution<double>(std::max(low_[i], c[i] - distance),
                                                    std::min(high_[i], c[i] + distance))(gen_);
  }
  void sampleGaussian(ob::State* s, const ob::State* mean, double stddev) override {
    auto* v = s->as<ob::RealVectorStateSpace::StateType>()->values;
    const auto* c = mean->as<ob::RealVectorStateSpace::StateType>()->values;
    for (size_t i = 0; i < low_.size(); ++i)
      v[i] = std::clamp(std::normal_distribution<double>(c[i], stddev)(gen_), low_[i], high_[i]);
  }

 private:
  std::mt19937_64 gen_;
  std::vector<double> low_, high_;
};

double rotation_angle(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

std::string fmt(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// A valid state near `start` (which violates only the margins) joined to it by a straight segment that `exact_ok`
// accepts at a fine spacing: random joint-space directions at radii growing to params.start_escape_max_rad, the
// nearest found first. Deterministic for a seed. Empty when escaping is off (max 0) or nothing was found.
std::optional<Eigen::VectorXd> find_start_escape(const Eigen::VectorXd& start, const StateCheck& valid,
                                                 const StateCheck& exact_ok, const ArmKinematics& kin,
                                                 const MotionPlannerParams& params, uint64_t seed) {
  if (!(params.start_escape_max_rad > 0) || params.start_escape_attempts <= 0) return std::nullopt;
  std::mt19937_64 rng(seed ^ 0x5bd1e9955bd1e995ULL);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double spacing = std::min(0.002, 0.25 * params.collision_resolution_rad);
  const int n = static_cast<int>(start.size());
  for (int i = 0; i < params.start_escape_attempts; ++i) {
    Eigen::VectorXd dir(n);
    for (int k = 0; k < n; ++k) dir[k] = normal(rng);
    if (!(dir.norm() > 1e-9)) continue;
    const double radius = params.start_escape_max_rad * (i + 1) / params.start_escape_attempts;
    const Eigen::VectorXd q =
        (start + radius * dir.normalized()).cwiseMax(kin.lower_limits()).cwiseMin(kin.upper_limits());
    if (valid(q) && segment_ok(exact_ok, start, q, spacing)) return q;
  }
  return std::nullopt;
}

// Whether the straight moves `then` (tool poses in base, in order, the first from `from`) can be followed from the
// posture `q` by IK in steps of at most params.then_step_m / then_step_rad, each step seeded by the last (a local,
// continuous path like the arm driver's), every posture params.then_limit_margin_rad inside the joint limits. `why`
// says which move and joint fail.
bool straight_moves_trackable(const InverseKinematics& ik, const Eigen::VectorXd& q, const Eigen::Isometry3d& from,
                              const std::vector<Eigen::Isometry3d>& then, const MotionPlannerParams& params,
                              std::string* why) {
  const ArmKinematics& kin = ik.kinematics();
  constexpr double kMaxJointStepRad = 0.3;  // a larger jump between steps is another IK branch, not a path
  Eigen::VectorXd at = q;
  Eigen::Isometry3d a = from;
  for (size_t m = 0; m < then.size(); ++m) {
    const Eigen::Isometry3d& b = then[m];
    const Eigen::Quaterniond ra(a.linear()), rb(b.linear());
    const double length = (b.translation() - a.translation()).norm();
    const int steps = std::max(1, static_cast<int>(std::ceil(std::max(length / params.then_step_m,
                                                                      ra.angularDistance(rb) / params.then_step_rad))));
    for (int k = 1; k <= steps; ++k) {
      const double t = static_cast<double>(k) / steps;
      Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
      target.linear() = ra.slerp(t, rb).toRotationMatrix();
      target.translation() = a.translation() + t * (b.translation() - a.translation());
      const IkResult r = ik.solve_once(target, at, ik.params().max_iterations, 0);
      // Says where tracking stopped (built only then: this loop runs ~100 IK steps per goal solution).
      const auto stop = [&](const std::string& what) {
        *why = "straight move " + std::to_string(m + 1) + " of " + std::to_string(then.size()) + " (" +
               fmt(length) + " m) at " + fmt(100.0 * t) + " %: " + what;
        return false;
      };
      if (!r.success) return stop("no IK (" + r.reason + ")");
      for (int j = 0; j < r.q.size(); ++j)
        if (r.q[j] < kin.lower_limits()[j] + params.then_limit_margin_rad ||
            r.q[j] > kin.upper_limits()[j] - params.then_limit_margin_rad)
          return stop(kin.joint_names()[j] + " at its limit");
      if ((r.q - at).cwiseAbs().maxCoeff() > kMaxJointStepRad) return stop("the posture jumps (another IK branch)");
      at = r.q;
    }
    a = b;
  }
  return true;
}

}  // namespace

const char* to_string(PlanFailure f) {
  switch (f) {
    case PlanFailure::kNone: return "none";
    case PlanFailure::kInvalidRequest: return "invalid_request";
    case PlanFailure::kStartInCollision: return "start_in_collision";
    case PlanFailure::kGoalInCollision: return "goal_in_collision";
    case PlanFailure::kNoIk: return "no_ik";
    case PlanFailure::kTimeout: return "timeout";
    case PlanFailure::kUnknownPlanner: return "unknown_planner";
  }
  return "?";
}

const std::vector<std::string>& MotionPlanner::planner_names() {
  static const std::vector<std::string> names{"CellBiRRT", "RRTConnect", "BiTRRT"};
  return names;
}

MotionPlanner::MotionPlanner(InverseKinematics ik, MotionPlannerParams params)
    : ik_(std::move(ik)), params_(std::move(params)) {
  const int n = ik_.kinematics().num_joints();
  if (params_.max_velocity.size() != n || params_.max_acceleration.size() != n)
    throw std::invalid_argument("planner velocity/acceleration limits need " + std::to_string(n) + " values");
  bool known = false;
  for (const auto& name : planner_names()) known = known || name == params_.default_planner;
  if (!known) throw std::invalid_argument("unknown default planner '" + params_.default_planner + "'");
  if (!(params_.collision_resolution_rad > 0) || !(params_.range_rad > 0) || !(params_.cell_size_m > 0))
    throw std::invalid_argument("planner resolution, range and cell size must be positive");
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
}

bool segment_collision_free(const PlanningScene& scene, const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                            double resolution_rad, bool with_margins) {
  if (scene.check(a, with_margins).collision) return false;
  return segment_ok([&](const Eigen::VectorXd& q) { return !scene.check(q, with_margins).collision; }, a, b,
                    resolution_rad);
}

PlanOutcome MotionPlanner::plan(const PlanningScene& scene, const PlanRequest& req) const {
  const auto t_begin = std::chrono::steady_clock::now();
  const auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t_begin).count();
  };
  const ArmKinematics& kin = ik_.kinematics();
  const int n = kin.num_joints();
  PlanOutcome out;
  out.planner = req.planner.empty() ? params_.default_planner : req.planner;
  const auto fail = [&](PlanFailure f, const std::string& message) {
    out.success = false;
    out.failure = f;
    out.message = message;
    out.planning_time_s = elapsed();
    return out;
  };

  // ---- request checks ----
  bool known = false;
  for (const auto& name : planner_names()) known = known || name == out.planner;
  if (!known) {
    std::string all;
    for (const auto& name : planner_names()) all += (all.empty() ? "" : ", ") + name;
    return fail(PlanFailure::kUnknownPlanner, "unknown planner '" + out.planner + "' (known: " + all + ")");
  }
  if (req.start.size() != n || !req.start.allFinite())
    return fail(PlanFailure::kInvalidRequest, "start needs " + std::to_string(n) + " finite joint values");
  if (!kin.within_limits(req.start, 1e-6))
    return fail(PlanFailure::kInvalidRequest, "start is outside the joint limits");
  if (!(req.time_budget_s > 0) || !std::isfinite(req.time_budget_s))
    return fail(PlanFailure::kInvalidRequest, "time budget must be a positive number of seconds");
  if (!(req.position_tolerance_m >= 0) || !(req.orientation_tolerance_rad >= 0) ||
      !std::isfinite(req.position_tolerance_m) || !std::isfinite(req.orientation_tolerance_rad))
    return fail(PlanFailure::kInvalidRequest, "tolerances must be finite and >= 0");
  if (req.keep_orientation && !(req.orientation_tolerance_rad > 0))
    return fail(PlanFailure::kInvalidRequest, "keep_orientation needs orientation_tolerance_rad > 0");
  if (!req.goal_is_pose) {
    if (req.goal_joints.size() != n || !req.goal_joints.allFinite())
      return fail(PlanFailure::kInvalidRequest, "joint goal needs " + std::to_string(n) + " finite values");
    if (!kin.within_limits(req.goal_joints, 1e-6))
      return fail(PlanFailure::kInvalidRequest, "joint goal is outside the joint limits");
  } else if (!req.goal_pose.matrix().allFinite()) {
    return fail(PlanFailure::kInvalidRequest, "goal pose is not finite");
  }
  const Eigen::VectorXd start = req.start.cwiseMax(kin.lower_limits()).cwiseMin(kin.upper_limits());

  // ---- validity: collisions with margins, plus the kept orientation ----
  const Eigen::Isometry3d start_tip = kin.tip_pose(start);
  const Eigen::Matrix3d kept = start_tip.linear();
  const double band = req.orientation_tolerance_rad;
  const bool keep = req.keep_orientation;
  if (!(req.max_tool_tilt_rad >= 0) || !std::isfinite(req.max_tool_tilt_rad))
    return fail(PlanFailure::kInvalidRequest, "max_tool_tilt_rad must be finite and >= 0");
  if (!(req.max_tool_pitch_rad >= 0) || !std::isfinite(req.max_tool_pitch_rad) || req.max_tool_pitch_rad > M_PI / 2)
    return fail(PlanFailure::kInvalidRequest, "max_tool_pitch_rad must be finite and within [0, pi/2]");
  const double min_up = req.max_tool_tilt_rad > 0 ? std::cos(req.max_tool_tilt_rad) : -2.0;
  const double max_pitch_sin = req.max_tool_pitch_rad > 0 ? std::sin(req.max_tool_pitch_rad) : 2.0;
  // Tilt of the tool's x axis from base +z (cosine = its z component).
  const auto tilt_of = [](const Eigen::Matrix3d& r) { return std::acos(std::clamp(r(2, 0), -1.0, 1.0)); };
  // Pitch of the tool's z axis from the horizontal plane (sine = the magnitude of its z component).
  const auto pitch_of = [](const Eigen::Matrix3d& r) { return std::asin(std::clamp(std::abs(r(2, 2)), 0.0, 1.0)); };
  // The path's tool bounds: the x axis within max_tool_tilt_rad of upright, the z axis within max_tool_pitch_rad of
  // horizontal.
  const auto within_tool_bounds = [min_up, max_pitch_sin](const Eigen::Matrix3d& r) {
    return !(r(2, 0) < min_up) && !(std::abs(r(2, 2)) > max_pitch_sin);
  };
  const StateCheck valid = [&scene, &kin, keep, kept, band, min_up, max_pitch_sin,
                            within_tool_bounds](const Eigen::VectorXd& q) {
    if (keep || min_up > -1.5 || max_pitch_sin < 1.5) {
      const Eigen::Matrix3d r = kin.tip_pose(q).linear();
      if (keep && rotation_angle(r, kept) > band) return false;
      if (!within_tool_bounds(r)) return false;
    }
    return scene.is_valid(q);
  };
  // Start and goal must meet the orientation bounds the path keeps. A goal outside them is a bad request; a start
  // outside them is where the arm is (e.g. a restarted simulation put it back in its initial posture), like a start
  // in collision: a planning failure, not a malformed message.
  const Eigen::Matrix3d goal_r = req.goal_is_pose ? Eigen::Matrix3d(req.goal_pose.linear())
                                                  : Eigen::Matrix3d(kin.tip_pose(req.goal_joints).linear());
  struct Bound {
    double limit;
    std::function<double(const Eigen::Matrix3d&)> angle;
    const char* what;  // "<verb> the tool's <axis> axis"
    const char* from;  // "upright" / "horizontal"
    const char* key;
  };
  for (const Bound& b : {Bound{req.max_tool_tilt_rad, tilt_of, "tilts the tool's x axis", "upright", "max_tool_tilt_rad"},
                         Bound{req.max_tool_pitch_rad, pitch_of, "pitches the tool's z axis", "horizontal",
                               "max_tool_pitch_rad"}}) {
    if (!(b.limit > 0)) continue;
    struct End {
      const char* name;
      Eigen::Matrix3d r;
      PlanFailure failure;
    };
    for (const End& e : {End{"start", start_tip.linear(), PlanFailure::kStartInCollision},
                         End{"goal", goal_r, PlanFailure::kInvalidRequest}})
      if (b.angle(e.r) > b.limit)
        return fail(e.failure, std::string("the ") + e.name + " " + b.what + " " + fmt(b.angle(e.r)) + " rad from " +
                                   b.from + ", more than " + b.key + " " + fmt(b.limit));
  }
  // A start within the margins but touching nothing (a servo or a guarded move ended near the holder or a board):
  // leave the margin on a short straight segment checked on the exact shapes, then plan from there.
  Eigen::VectorXd search_start = start;
  std::string escape_note;
  const CollisionReport start_report = scene.check(start);
  if (start_report.collision) {
    const CollisionReport touching = scene.check(start, false);
    if (touching.collision)
      return fail(PlanFailure::kStartInCollision, "start is in collision: " + touching.describe() + " (touching)");
    const StateCheck exact_ok = [&scene, &kin, within_tool_bounds](const Eigen::VectorXd& q) {
      return within_tool_bounds(kin.tip_pose(q).linear()) && !scene.check(q, false).collision;
    };
    const std::optional<Eigen::VectorXd> escape = find_start_escape(start, valid, exact_ok, kin, params_, req.seed);
    if (!escape)
      return fail(PlanFailure::kStartInCollision, "start is in collision: " + start_report.describe() +
                                                      " (closer than the margin; no valid state within " +
                                                      fmt(params_.start_escape_max_rad) +
                                                      " rad (planner.start_escape_max_rad) reachable in a " +
                                                      "straight move: move out before planning)");
    search_start = *escape;
    escape_note =
        ", left the margin of " + start_report.describe() + " by " + fmt((*escape - start).norm()) + " rad first";
  }

  // ---- goals ----
  std::vector<Eigen::VectorXd> goals;
  std::string then_note;  // the goals could not all be checked for the straight moves after them
  if (!req.goal_is_pose) {
    const CollisionReport r = scene.check(req.goal_joints);
    if (r.collision) return fail(PlanFailure::kGoalInCollision, "goal is in collision: " + r.describe());
    if (keep && rotation_angle(kin.tip_pose(req.goal_joints).linear(), kept) > band)
      return fail(PlanFailure::kInvalidRequest, "keep_orientation: the goal's tool orientation differs from the start's by more than the tolerance");
    goals.push_back(req.goal_joints);
  } else {
    if (keep && rotation_angle(req.goal_pose.linear(), kept) > band)
      return fail(PlanFailure::kInvalidRequest, "keep_orientation: the goal pose orientation differs from the start's by " +
                                                     fmt(rotation_angle(req.goal_pose.linear(), kept)) + " rad, more than the tolerance");
    std::mt19937_64 rng(req.seed ^ 0x9e3779b97f4a7c15ULL);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::normal_distribution<double> jitter(0.0, 0.5);
    int ik_ok = 0;
    std::string ik_reason;
    std::map<std::string, int> collisions;  // first colliding pair -> IK solutions it stopped
    Eigen::VectorXd closest;  // failed attempt that came closest: later seeds also perturb it
    std::vector<Eigen::VectorXd> near_limit_goals;  // valid, but within goal_limit_margin_rad of a joint limit
    std::vector<Eigen::VectorXd> untrackable_goals;  // valid, but the then_poses leave the joint limits from them
    std::string untrackable_reason;
    double closest_error = INFINITY;
    for (int attempt = 0; attempt < params_.goal_ik_attempts &&
                          static_cast<int>(goals.size()) < params_.goal_ik_solutions; ++attempt) {
      Eigen::VectorXd seed(n);
      if (attempt == 0) {
        seed = start;
      } else if (attempt == 1) {
        seed = ik_.params().preferred_posture;
      } else if (attempt % 2 == 1 && closest.size() == n) {
        for (int k = 0; k < n; ++k) seed[k] = closest[k] + jitter(rng);
      } else {
        for (int k = 0; k < n; ++k)
          seed[k] = kin.lower_limits()[k] + unit(rng) * (kin.upper_limits()[k] - kin.lower_limits()[k]);
      }
      const IkResult r = ik_.solve_once(req.goal_pose, seed, ik_.params().max_iterations);
      if (!r.success) {
        ik_reason = r.reason;
        const double e = r.position_error_m + ik_.params().orientation_weight_m * r.orientation_error_rad;
        if (e < closest_error) {
          closest_error = e;
          closest = r.q;
        }
        continue;
      }
      ++ik_ok;
      const CollisionReport c = scene.check(r.q);
      if (c.collision) {
        ++collisions[c.describe()];
        continue;
      }
      // A goal at a joint's limit leaves the straight moves that follow it no room (the arm driver stops a
      // Cartesian motion at a limit): such goals are used only when there is no other.
      const bool near_limit = !kin.within_limits(r.q, -params_.goal_limit_margin_rad);
      // The straight moves after the goal (then_poses) are tracked from it: a solution from which they run into a
      // joint limit is a last resort too, after the near-limit ones.
      std::string why_not;
      const bool trackable = req.then_poses.empty() ||
                             straight_moves_trackable(ik_, r.q, req.goal_pose, req.then_poses, params_, &why_not);
      if (!trackable && untrackable_reason.empty()) untrackable_reason = why_not;
      std::vector<Eigen::VectorXd>& list = !trackable ? untrackable_goals : near_limit ? near_limit_goals : goals;
      bool distinct = true;
      for (const auto& g : list) distinct = distinct && (g - r.q).norm() > 0.1;
      if (distinct) list.push_back(r.q);
    }
    if (goals.empty()) goals = near_limit_goals;
    if (goals.empty() && !untrackable_goals.empty()) {
      goals = untrackable_goals;
      then_note = "; no goal solution found from which the " + std::to_string(req.then_poses.size()) +
                  " straight moves after it stay within the joint limits (" + untrackable_reason + ")";
    }
    if (ik_ok == 0)
      return fail(PlanFailure::kNoIk, "no IK solution for the goal pose after " +
                                          std::to_string(params_.goal_ik_attempts) + " attempts (" + ik_reason + ")");
    if (goals.empty()) {
      // The pairs by how many solutions they stopped, most first: where the goal pose itself is blocked.
      std::vector<std::pair<int, std::string>> by_count;
      for (const auto& [pair, count] : collisions) by_count.emplace_back(count, pair);
      std::stable_sort(by_count.begin(), by_count.end(),
                       [](const auto& a, const auto& b) { return a.first > b.first; });
      std::string pairs;
      for (const auto& [count, pair] : by_count)
        pairs += (pairs.empty() ? "" : ", ") + pair + " (" + std::to_string(count) + ")";
      return fail(PlanFailure::kGoalInCollision,
                  "all " + std::to_string(ik_ok) + " IK solutions of the goal pose are in collision: " + pairs);
    }
  }

  out.goal_ik_time_s = elapsed();
  // ---- OMPL problem ----
  auto space = std::make_shared<ob::RealVectorStateSpace>(n);
  ob::RealVectorBounds bounds(n);
  for (int k = 0; k < n; ++k) {
    bounds.setLow(k, kin.lower_limits()[k]);
    bounds.setHigh(k, kin.upper_limits()[k]);
  }
  space->setBounds(bounds);
  const uint64_t seed = req.seed;
  space->setStateSamplerAllocator(
      [seed](const ob::StateSpace* s) -> ob::StateSamplerPtr { return std::make_shared<SeededSampler>(s, seed); });
  auto si = std::make_shared<ob::SpaceInformation>(space);
  si->setStateValidityChecker([&valid, n](const ob::State* s) { return valid(from_state(s, n)); });
  si->setMotionValidator(std::make_shared<InterpolatingMotionValidator>(si, valid, params_.collision_resolution_rad, n));
  si->setup();
  auto pdef = std::make_shared<ob::ProblemDefinition>(si);
  {
    ob::ScopedState<> s(space);
    to_state(search_start, s.get());
    pdef->addStartState(s);
    auto goal_states = std::make_shared<ob::GoalStates>(si);
    for (const auto& g : goals) {
      to_state(g, s.get());
      goal_states->addState(s);
    }
    pdef->setGoal(goal_states);
  }
  ob::PlannerPtr planner;
  std::shared_ptr<CellBiRRT> cell;
  if (out.planner == "CellBiRRT") {
    CellBiRrtParams cp;
    cp.range_rad = params_.range_rad;
    cp.cell_size_m = params_.cell_size_m;
    cp.workspace_min = params_.workspace_min;
    cp.workspace_max = params_.workspace_max;
    cp.tube_sigma_m = params_.tube_sigma_m;
    cp.min_cell_weight = params_.min_cell_weight;
    cp.failure_decay = params_.failure_decay;
    cp.cell_sample_probability = params_.cell_sample_probability;
    cp.orientation_noise_rad = params_.orientation_noise_rad;
    cp.ik_iterations = params_.cell_ik_iterations;
    CellBiRrtProblem problem;
    problem.start_tip = start_tip;
    problem.goal_tip = req.goal_is_pose ? req.goal_pose : kin.tip_pose(goals.front());
    problem.keep_orientation = keep;
    problem.constrained_orientation = kept;
    problem.seed = seed;
    // Cell centres inside an obstacle or out of the arm's reach are not used.
    struct Obstacle {
      Eigen::Isometry3d inverse;
      Eigen::Vector3d half;
    };
    std::vector<Obstacle> obstacles;
    for (const SceneBox& b : scene.environment()) obstacles.push_back({b.pose.inverse(), 0.5 * b.size});
    const std::vector<Eigen::Isometry3d> zero_links = kin.link_poses(Eigen::VectorXd::Zero(n));
    const int shoulder_link = kin.model().joints.empty() ? 0 : [&] {
      // Child link of the second movable joint on the chain: the shoulder centre of an LWA3-type arm.
      int count = 0;
      for (size_t l = 0; l < kin.model().links.size(); ++l) {
        const int j = kin.model().links[l].parent_joint;
        if (j >= 0 && kin.model().joints[j].kind != RobotJoint::Kind::kFixed && ++count == 2) return static_cast<int>(l);
      }
      return 0;
    }();
    const Eigen::Vector3d shoulder = zero_links[shoulder_link].translation();
    const double reach = (zero_links[kin.tip_link()].translation() - shoulder).norm() + params_.cell_size_m;
    problem.point_free = [obstacles, shoulder, reach](const Eigen::Vector3d& p) {
      if ((p - shoulder).norm() > reach) return false;
      for (const Obstacle& o : obstacles)
        if (((o.inverse * p).cwiseAbs() - o.half).maxCoeff() < 0) return false;
      return true;
    };
    cell = std::make_shared<CellBiRRT>(si, ik_, cp, problem);
    planner = cell;
  } else if (out.planner == "RRTConnect") {
    auto p = std::make_shared<og::RRTConnect>(si);
    p->setRange(params_.range_rad);
    planner = p;
  } else {
    auto p = std::make_shared<og::BiTRRT>(si);
    p->setRange(params_.range_rad);
    planner = p;
  }
  planner->setProblemDefinition(pdef);
  planner->setup();
  const double search_begin = elapsed();
  // The step count decides (load-independent, so a composed run gives the same answer on a busy machine); the
  // clock is the safety stop.
  auto steps = std::make_shared<long>(0);
  const long max_steps = params_.max_search_steps;
  const ob::PlannerTerminationCondition step_limit(
      [steps, max_steps] { return ++*steps > max_steps && max_steps > 0; });
  const ob::PlannerStatus status =
      planner->solve(params_.wall_clock_stop ? ob::plannerOrTerminationCondition(
                                                   step_limit, ob::timedPlannerTerminationCondition(req.time_budget_s))
                                             : step_limit);
  out.search_time_s = elapsed() - search_begin;
  out.search_steps = std::min(*steps, max_steps > 0 ? max_steps : *steps);
  if (status != ob::PlannerStatus::EXACT_SOLUTION || !pdef->hasExactSolution()) {
    std::string detail = "status: " + status.asString();
    if (cell)
      detail += ", " + std::to_string(cell->tree_size()) + " nodes, cell samples " +
                std::to_string(cell->cell_samples_ok()) + "/" + std::to_string(cell->cell_samples_tried());
    const std::string limit = max_steps > 0 && *steps > max_steps
                                  ? std::to_string(max_steps) + " search steps (planner.max_search_steps)"
                                  : "the time budget of " + fmt(req.time_budget_s) + " s";
    return fail(PlanFailure::kTimeout, out.planner + " found no path within " + limit + " (" + detail + ")");
  }
  const auto* path = pdef->getSolutionPath()->as<og::PathGeometric>();
  for (size_t i = 0; i < path->getStateCount(); ++i) out.raw_path.push_back(from_state(path->getState(i), n));

  // ---- simplify and time-parameterise ----
  const MotionCheck motion = [&](const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    return segment_ok(valid, a, b, params_.collision_resolution_rad);
  };
  const double simplify_begin = elapsed();
  out.path = simplify_path(out.raw_path, motion, params_.simplify_shortcuts, seed);
  if (!escape_note.empty()) {
    // The way out of the margin comes first (not simplified away: the start itself is not a valid state).
    out.raw_path.insert(out.raw_path.begin(), start);
    out.path.insert(out.path.begin(), start);
  }
  out.trajectory = parameterize_trapezoidal(out.path, params_.max_velocity, params_.max_acceleration,
                                            params_.sample_period_s);
  out.path_length_rad = path_length(out.path);
  out.simplify_time_s = elapsed() - simplify_begin;
  out.success = true;
  out.failure = PlanFailure::kNone;
  std::ostringstream msg;
  msg << out.planner << ": " << out.path.size() << " waypoints (" << out.raw_path.size() << " before simplification), "
      << fmt(out.path_length_rad) << " rad, " << fmt(out.trajectory.duration_s) << " s";
  if (cell) msg << ", " << cell->tree_size() << " nodes, cell samples " << cell->cell_samples_ok() << "/"
                << cell->cell_samples_tried();
  msg << escape_note << then_note;
  out.message = msg.str();
  out.planning_time_s = elapsed();
  return out;
}

}  // namespace bookgrasp
