#include "services/planner/cell_birrt.h"

#include <algorithm>
#include <cmath>

#include <ompl/base/PlannerData.h>
#include <ompl/base/goals/GoalSampleableRegion.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathGeometric.h>

namespace bookgrasp {
namespace ob = ompl::base;
namespace og = ompl::geometric;

namespace {

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

double segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b, double* t_out) {
  const Eigen::Vector3d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 1e-12 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  if (t_out) *t_out = t;
  return (a + t * ab - p).norm();
}

}  // namespace

CellBiRRT::CellBiRRT(const ob::SpaceInformationPtr& si, const InverseKinematics& ik, CellBiRrtParams params,
                     CellBiRrtProblem problem)
    : ob::Planner(si, "CellBiRRT"), ik_(ik), params_(std::move(params)), problem_(std::move(problem)),
      rng_(problem_.seed) {
  specs_.recognizedGoal = ob::GOAL_SAMPLEABLE_REGION;
  specs_.approximateSolutions = false;
  specs_.directed = false;
  build_cells();
}

CellBiRRT::~CellBiRRT() = default;

void CellBiRRT::clear() {
  Planner::clear();
  trees_[0].clear();
  trees_[1].clear();
  rng_.seed(problem_.seed);
  build_cells();
  cell_ok_ = cell_tried_ = 0;
}

void CellBiRRT::build_cells() {
  cell_centres_.clear();
  cell_weights_.clear();
  const Eigen::Vector3d extent = params_.workspace_max - params_.workspace_min;
  const int nx = std::max(1, static_cast<int>(std::ceil(extent.x() / params_.cell_size_m)));
  const int ny = std::max(1, static_cast<int>(std::ceil(extent.y() / params_.cell_size_m)));
  const int nz = std::max(1, static_cast<int>(std::ceil(extent.z() / params_.cell_size_m)));
  const Eigen::Vector3d a = problem_.start_tip.translation(), b = problem_.goal_tip.translation();
  const double s2 = 2 * params_.tube_sigma_m * params_.tube_sigma_m;
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      for (int k = 0; k < nz; ++k) {
        const Eigen::Vector3d c = params_.workspace_min + params_.cell_size_m * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
        if (problem_.point_free && !problem_.point_free(c)) continue;
        const double d = segment_distance(c, a, b, nullptr);
        const double w = std::max(params_.min_cell_weight, std::exp(-d * d / s2));
        cell_centres_.push_back(c);
        cell_weights_.push_back(w);
      }
    }
  }
}

bool CellBiRRT::state_ok(const Eigen::VectorXd& q) const {
  ob::State* s = si_->allocState();
  to_state(q, s);
  const bool ok = si_->isValid(s);
  si_->freeState(s);
  return ok;
}

bool CellBiRRT::motion_ok(const Eigen::VectorXd& a, const Eigen::VectorXd& b) const {
  ob::State* sa = si_->allocState();
  ob::State* sb = si_->allocState();
  to_state(a, sa);
  to_state(b, sb);
  const bool ok = si_->checkMotion(sa, sb);
  si_->freeState(sa);
  si_->freeState(sb);
  return ok;
}

int CellBiRRT::add_node(Tree& tree, const Eigen::VectorXd& q, int parent) {
  tree.push_back(Node{q, ik_.kinematics().tip_pose(q).translation(), parent});
  return static_cast<int>(tree.size()) - 1;
}

int CellBiRRT::nearest(const Tree& tree, const Eigen::VectorXd& q) const {
  int best = 0;
  double best_d = INFINITY;
  for (size_t i = 0; i < tree.size(); ++i) {
    const double d = (tree[i].q - q).squaredNorm();
    if (d < best_d) {
      best_d = d;
      best = static_cast<int>(i);
    }
  }
  return best;
}

void CellBiRRT::sample_uniform(Eigen::VectorXd& q) {
  const auto& k = ik_.kinematics();
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  q.resize(k.num_joints());
  for (int i = 0; i < k.num_joints(); ++i)
    q[i] = k.lower_limits()[i] + unit(rng_) * (k.upper_limits()[i] - k.lower_limits()[i]);
}

bool CellBiRRT::sample_cell(const Tree& tree, Eigen::VectorXd& q) {
  if (cell_centres_.empty()) return false;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  // Cell selection: roulette on the current weights.
  double total = 0;
  for (double w : cell_weights_) total += w;
  double pick = unit(rng_) * total;
  size_t cell = 0;
  for (; cell + 1 < cell_weights_.size(); ++cell) {
    pick -= cell_weights_[cell];
    if (pick <= 0) break;
  }
  ++cell_tried_;
  // Tool pose inside the cell that satisfies the orientation constraint.
  const Eigen::Vector3d p = cell_centres_[cell] + params_.cell_size_m * Eigen::Vector3d(unit(rng_) - 0.5, unit(rng_) - 0.5,
                                                                                      unit(rng_) - 0.5);
  Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
  target.translation() = p;
  if (problem_.keep_orientation) {
    target.linear() = problem_.constrained_orientation;
  } else {
    double t = 0;
    segment_distance(p, problem_.start_tip.translation(), problem_.goal_tip.translation(), &t);
    const Eigen::Quaterniond qa(problem_.start_tip.linear()), qb(problem_.goal_tip.linear());
    Eigen::Vector3d axis(unit(rng_) - 0.5, unit(rng_) - 0.5, unit(rng_) - 0.5);
    if (axis.norm() < 1e-9) axis = Eigen::Vector3d::UnitZ();
    const Eigen::AngleAxisd noise(params_.orientation_noise_rad * unit(rng_), axis.normalized());
    target.linear() = (noise * qa.slerp(t, qb)).toRotationMatrix();
  }
  // IK seeded from the tree node whose tool is nearest to the sampled position.
  int seed = 0;
  double best = INFINITY;
  for (size_t i = 0; i < tree.size(); ++i) {
    const double d = (tree[i].tip - p).squaredNorm();
    if (d < best) {
      best = d;
      seed = static_cast<int>(i);
    }
  }
  const IkResult r = ik_.solve_once(target, tree[seed].q, params_.ik_iterations, 0);
  if (!r.success || !state_ok(r.q)) {
    cell_weights_[cell] = std::max(params_.min_cell_weight * 1e-3, cell_weights_[cell] * params_.failure_decay);
    return false;
  }
  ++cell_ok_;
  q = r.q;
  return true;
}

CellBiRRT::Grow CellBiRRT::extend(Tree& tree, const Eigen::VectorXd& target, int& added) {
  const int near = nearest(tree, target);
  const Eigen::VectorXd& from = tree[near].q;
  const double d = (target - from).norm();
  Grow result = Grow::kReached;
  Eigen::VectorXd to = target;
  // With the orientation kept, each new node is projected back onto the constraint (IK to its own
  // tool position with the kept orientation).
  const double range = params_.range_rad;
  if (d > range) {
    to = from + (range / d) * (target - from);
    result = Grow::kAdvanced;
    if (problem_.keep_orientation) {
      Eigen::Isometry3d on_manifold = Eigen::Isometry3d::Identity();
      on_manifold.translation() = ik_.kinematics().tip_pose(to).translation();
      on_manifold.linear() = problem_.constrained_orientation;
      const IkResult r = ik_.solve_once(on_manifold, to, params_.ik_iterations, 0);
      if (!r.success) return Grow::kTrapped;
      to = r.q;
      // The projection may undo the step: require real progress, or the connect loop would not end.
      if ((target - to).norm() > d - 0.25 * range) return Grow::kTrapped;
    }
  }
  if (!motion_ok(from, to)) return Grow::kTrapped;
  added = add_node(tree, to, near);
  return result;
}

ob::PlannerStatus CellBiRRT::solve(const ob::PlannerTerminationCondition& ptc) {
  checkValidity();
  const int n = ik_.kinematics().num_joints();
  auto* goal = dynamic_cast<ob::GoalSampleableRegion*>(pdef_->getGoal().get());
  if (!goal) return ob::PlannerStatus::UNRECOGNIZED_GOAL_TYPE;
  while (const ob::State* st = pis_.nextStart()) add_node(trees_[0], from_state(st, n), -1);
  if (trees_[0].empty()) return ob::PlannerStatus::INVALID_START;
  {
    ob::State* g = si_->allocState();
    for (unsigned i = 0; i < goal->maxSampleCount(); ++i) {
      goal->sampleGoal(g);
      if (si_->isValid(g)) add_node(trees_[1], from_state(g, n), -1);
    }
    si_->freeState(g);
  }
  if (trees_[1].empty()) return ob::PlannerStatus::INVALID_GOAL;

  const double p_cell = params_.cell_sample_probability;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int a = 0;  // tree that grows towards the sample this round
  Eigen::VectorXd sample;
  while (!ptc) {
    Tree& ta = trees_[a];
    Tree& tb = trees_[1 - a];
    bool have = false;
    if (unit(rng_) < p_cell) have = sample_cell(ta, sample);
    if (!have) sample_uniform(sample);
    int added = -1;
    if (extend(ta, sample, added) != Grow::kTrapped) {
      // Connect: grow the other tree towards the new node until it gets there or is blocked.
      const Eigen::VectorXd target = ta[added].q;
      Grow g = Grow::kAdvanced;
      int last = -1;
      while (g == Grow::kAdvanced && !ptc) g = extend(tb, target, last);
      if (g == Grow::kReached) {
        // Path: start tree root -> meeting point -> goal tree root.
        const Tree& ts = trees_[0];
        const Tree& tg = trees_[1];
        const int s_end = (a == 0) ? added : last;
        const int g_end = (a == 0) ? last : added;
        std::vector<Eigen::VectorXd> first, second;
        for (int i = s_end; i >= 0; i = ts[i].parent) first.push_back(ts[i].q);
        std::reverse(first.begin(), first.end());
        for (int i = tg[g_end].parent; i >= 0; i = tg[i].parent) second.push_back(tg[i].q);
        auto path = std::make_shared<og::PathGeometric>(si_);
        ob::State* s = si_->allocState();
        for (const auto& q : first) {
          to_state(q, s);
          path->append(s);
        }
        for (const auto& q : second) {
          to_state(q, s);
          path->append(s);
        }
        si_->freeState(s);
        pdef_->addSolutionPath(path, false, 0.0, getName());
        return ob::PlannerStatus::EXACT_SOLUTION;
      }
    }
    a = 1 - a;
  }
  return ob::PlannerStatus::TIMEOUT;
}

void CellBiRRT::getPlannerData(ob::PlannerData& data) const {
  // Trees are kept as plain Eigen vectors; only the planner's properties are exported
  // (tree_size() and the cell counters describe the search).
  Planner::getPlannerData(data);
}

}  // namespace bookgrasp
