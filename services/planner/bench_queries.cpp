#include "services/planner/bench_queries.h"

#include <cmath>
#include <random>

namespace bookgrasp {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

// Gripper orientation for a book on a shelf facing the robot: x up, y to the right along the
// shelf (cart -y), z into the shelf (cart +x).
Eigen::Matrix3d shelf_grasp_orientation(const Eigen::Isometry3d& cart) {
  Eigen::Matrix3d r;
  r.col(0) = Eigen::Vector3d::UnitZ();
  r.col(1) = -cart.linear().col(1);
  r.col(2) = cart.linear().col(0);
  return r;
}

Eigen::Isometry3d pose(const Eigen::Vector3d& p, const Eigen::Matrix3d& r) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = p;
  t.linear() = r;
  return t;
}

}  // namespace

Eigen::VectorXd bench_home_joints() {
  Eigen::VectorXd q(7);
  q << 120 * kDeg, 75 * kDeg, 0, -112 * kDeg, 0, -80 * kDeg, 0;
  return q;
}

void apply_query_scene(const BenchQuery& query, const HeldBookParams& held_book, PlanningScene& scene) {
  scene.set_environment(query.environment);
  if (query.holding_book) scene.attach(held_book_box(query.book_whd, held_book));
  else scene.detach();
}

std::vector<BenchQuery> make_library_queries(const PlannerSettings& settings, const PlannerStack& stack, int count,
                                             uint64_t seed) {
  std::mt19937_64 rng(seed);
  auto uni = [&rng](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  const MarkerBoxes* cart_group = nullptr;
  const MarkerBoxes* holder_group = nullptr;
  for (const auto& g : settings.geometry.marker_groups) {
    if (g.role == "cart") cart_group = &g;
    if (g.role == "holder") holder_group = &g;
  }
  if (!cart_group || !holder_group)
    throw std::runtime_error("benchmark needs scene.objects.cart and scene.objects.holder in the planner config");
  PlanningScene scene = stack.scene;
  const InverseKinematics& ik = stack.ik;
  const double top = settings.held_book.top_above_tcp_m, behind = settings.held_book.behind_tcp_m;
  // First candidate pose whose IK from the preferred posture converges to a collision-free
  // configuration in `scene` (returns false if none). Poses reachable only from a few lucky random
  // seeds (at the edge of the workspace) are not used as library queries.
  auto reachable = [&](const std::vector<Eigen::Isometry3d>& candidates, uint64_t, Eigen::Isometry3d* pose_out,
                       Eigen::VectorXd* q_out) {
    for (const auto& c : candidates) {
      const IkResult r = ik.solve_once(c, ik.params().preferred_posture, ik.params().max_iterations);
      if (r.success && scene.is_valid(r.q)) {
        *pose_out = c;
        *q_out = r.q;
        return true;
      }
    }
    return false;
  };
  // Approach yaws tried in turn (0 first): the arm cannot reach close to its own base with the
  // gripper pointing straight forward (shoulder-wrist distance >= 0.407 m), so near books need a
  // slanted approach.
  const std::vector<double> yaws_deg{0, 15, -15, 30, -30, 45, -45, 60, -60};
  // Poses in front of a shelf face point `g` (base), `standoff` back along the approach.
  auto shelf_candidates = [&](const Eigen::Isometry3d& cart, const Eigen::Vector3d& g, double standoff) {
    std::vector<Eigen::Isometry3d> out;
    for (double yaw : yaws_deg) {
      const Eigen::Matrix3d r = Eigen::AngleAxisd(yaw * kDeg, Eigen::Vector3d::UnitZ()) * shelf_grasp_orientation(cart);
      out.push_back(pose(g - standoff * r.col(2), r));
    }
    return out;
  };

  std::vector<BenchQuery> out;
  int guard = 0;
  while (static_cast<int>(out.size()) < count && guard++ < 50 * count + 100) {
    // ---- scene: cart 0.55-0.65 m in front of the base, slightly shifted and turned ----
    Eigen::Isometry3d cart = cart_group->nominal_object_in_base;
    cart.translation() += Eigen::Vector3d(uni(-0.05, 0.05), uni(-0.05, 0.05), 0.0);
    cart.rotate(Eigen::AngleAxisd(uni(-5, 5) * kDeg, Eigen::Vector3d::UnitZ()));
    Eigen::Isometry3d holder = holder_group->nominal_object_in_base;
    holder.translation() += Eigen::Vector3d(uni(-0.03, 0.03), uni(-0.03, 0.03), 0.0);
    const std::vector<SceneBox> env = build_environment(
        settings.geometry, {{"cart", cart * cart_group->marker_in_object}, {"holder", holder * holder_group->marker_in_object}});
    // ---- the right-most book (distributions of config/scenes/default.yaml) ----
    const bool portrait = uni(0, 1) < 0.5;
    const double width = uni(0.010, 0.035);
    const double height = portrait ? uni(0.20, 0.30) : uni(0.14, 0.19);
    const double depth = std::min(0.33, height * (portrait ? uni(0.62, 0.78) : uni(1.20, 1.45)));
    const double book_y = -0.40 + uni(0.03, 0.35) + width / 2;  // cart y: right panel inner face at -0.40
    const double slot_y = uni(-0.30, 0.30);
    const double tcp_z = height - top;
    const uint64_t qseed = seed * 1000003ULL + out.size();

    BenchQuery base;
    base.environment = env;
    base.request.position_tolerance_m = 0.001;
    base.request.orientation_tolerance_rad = 0.01;
    base.request.time_budget_s = 1.0;
    base.request.goal_is_pose = true;
    base.book_whd = Eigen::Vector3d(width, height, depth);

    // Pre-grasp: 8 cm in front of the book's front face at grasp height (no book held).
    BenchQuery q1 = base;
    q1.kind = "pregrasp";
    apply_query_scene(q1, settings.held_book, scene);
    Eigen::VectorXd q_unused;
    if (!reachable(shelf_candidates(cart, cart * Eigen::Vector3d(0.0, book_y, tcp_z), 0.08), qseed,
                   &q1.request.goal_pose, &q_unused))
      continue;
    q1.request.start = bench_home_joints();

    // Book pulled out: its fore-edge... its far end 5 cm in front of the shelf (book held).
    BenchQuery q2 = base;
    q2.kind = "holder";
    q2.holding_book = true;
    apply_query_scene(q2, settings.held_book, scene);
    Eigen::Isometry3d retreat;
    if (!reachable(shelf_candidates(cart, cart * Eigen::Vector3d(0.0, book_y, tcp_z + 0.01), depth - behind + 0.05),
                   qseed + 1, &retreat, &q2.request.start))
      continue;
    // Above the holder: upright, cover towards the back plate, centred over the base plate.
    std::vector<Eigen::Isometry3d> above;
    for (double clearance : {0.04, 0.10, 0.16, 0.22}) {
      for (double sign : {1.0, -1.0}) {
        for (double yaw : {0.0, 15.0, -15.0, 30.0, -30.0}) {
          Eigen::Matrix3d r;
          r.col(0) = Eigen::Vector3d::UnitZ();
          r.col(2) = sign * holder.linear().col(1);
          r.col(1) = r.col(2).cross(r.col(0));
          r = Eigen::AngleAxisd(yaw * kDeg, Eigen::Vector3d::UnitZ()) * r;
          const Eigen::Vector3d centre = holder * Eigen::Vector3d(0.0, 0.0, 0.31 + clearance + tcp_z);
          above.push_back(pose(centre - (0.5 * depth - behind) * r.col(2), r));
        }
      }
    }
    Eigen::VectorXd q_above;
    if (!reachable(above, qseed + 2, &q2.request.goal_pose, &q_above)) continue;

    // Lower shelf: the held book's far end 5 cm in front of a lower-shelf slot, 1.5 cm above the board.
    BenchQuery q3 = base;
    q3.kind = "lower";
    q3.holding_book = true;
    q3.request.start = q_above;
    const double lower_tcp_z = -0.35 + 0.015 + tcp_z;
    if (!reachable(shelf_candidates(cart, cart * Eigen::Vector3d(0.0, slot_y, lower_tcp_z), depth - behind + 0.05),
                   qseed + 3, &q3.request.goal_pose, &q_unused))
      continue;

    for (BenchQuery* q : {&q1, &q2, &q3}) {
      if (static_cast<int>(out.size()) >= count) break;
      q->request.seed = seed * 1000003ULL + out.size();
      out.push_back(*q);
    }
  }
  return out;
}

}  // namespace bookgrasp
