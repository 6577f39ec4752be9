// The stripe servo's left limit (coordinator geometry.stripe_left_limit_y_m) against the planner's collision model:
// along the stripe, at the servo's standoff and orientation, the gripper keeps the planner's margins from the
// book holder beside the cart everywhere right of the limit (an empty shelf's stripe servo drove the palm into the
// holder's back plate: "start is in collision: gripper_palm with holder_back (touching)"), and the limit is not
// needlessly far right: 6 cm left of it the margin is broken.
#include <cmath>

#include <gtest/gtest.h>

#include "common/config.h"
#include "services/eval_full/cycle_reach.h"
#include "services/planner/planner_config.h"
#include "services/planner/scene_geometry.h"

namespace bookgrasp {
namespace {

const std::string kSrc = BOOKGRASP_SOURCE_DIR;

struct Probe {
  double y = 0;            ///< grasp Y of the TCP
  bool reachable = false;  ///< IK found a posture
  CollisionReport margin;  ///< the planner's check with margins
};

// The stripe servo's pose at grasp Y `y` (position A's X and Z, its orientation), its IK from `q` (updated), checked
// in `scene` with margins.
Probe probe_at(double y, const scene::Scene& truth, const CycleGeometry& g, const PlannerStack& stack,
               const PlanningScene& scene, Eigen::VectorXd* q) {
  Probe p;
  p.y = y;
  const Eigen::Isometry3d grasp = true_grasp_frame(truth);
  const Eigen::Isometry3d tcp = pose_in_grasp_frame(grasp, Eigen::Vector3d(g.stripe_start.x(), y, g.stripe_start.z()));
  const IkResult r = stack.ik.solve(tcp, *q);
  p.reachable = r.success;
  if (!r.success) return p;
  *q = r.q;
  p.margin = scene.check(r.q);
  return p;
}

TEST(StripeClearance, RightOfTheLeftLimitTheGripperKeepsThePlannersMargins) {
  const CycleGeometry g =
      CycleGeometry::from_config(Config::load_file(kSrc + "/config/services/coordinator.yaml").child("geometry"));
  const PlannerSettings settings = PlannerSettings::load(kSrc + "/config/services/planner.yaml");
  const PlannerStack stack(settings);
  ASSERT_LT(g.stripe_left_limit_y, g.stripe_start.y());
  for (const char* file : {"far_cart.yaml"}) {
    SCOPED_TRACE(file);
    const scene::Scene truth = scene::load_scene(kSrc + "/config/scenes/" + file, 1);
    // The planner's environment placed by the true markers (MARKERS axes: y down, z into the tag).
    const Eigen::Isometry3d flip(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
    PlanningScene scene = stack.scene;
    scene.set_environment(build_environment(
        settings.geometry, {{"cart", truth.cart_marker.pose * flip}, {"holder", truth.holder_marker.pose * flip}}));
    Eigen::VectorXd q = settings.ik.preferred_posture;
    // From position A leftwards, as the servo moves.
    double first_broken = NAN;
    std::string why;
    for (double y = g.stripe_start.y(); y >= g.shelf_left_y - 1e-9; y -= 0.005) {
      const Probe p = probe_at(y, truth, g, stack, scene, &q);
      if (y >= g.stripe_left_limit_y - 1e-9) {
        EXPECT_TRUE(p.reachable) << "Y " << y;
        EXPECT_FALSE(p.margin.collision) << "Y " << y << ": " << p.margin.describe();
      } else if (std::isnan(first_broken) && (!p.reachable || p.margin.collision)) {
        first_broken = y;
        why = p.reachable ? p.margin.describe() : "no IK";
      }
    }
    std::printf(
        "%s: the limit %.3f; left of it the stripe pose is first unreachable or within the margins at %.3f (%s)\n",
        file, g.stripe_left_limit_y, first_broken, why.c_str());
    // Not needlessly conservative: within 6 cm left of the limit the margin breaks.
    ASSERT_FALSE(std::isnan(first_broken));
    EXPECT_GT(first_broken, g.stripe_left_limit_y - 0.06);
  }
}

}  // namespace
}  // namespace bookgrasp
