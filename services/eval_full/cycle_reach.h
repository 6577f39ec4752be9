#pragma once
/// @file
/// Reachability of every pose of the library cycle for one scene, from the
/// scene's ground truth and the coordinator's geometry (no simulation, no
/// vision): whether the arm's IK reaches each stage's TCP pose within the joint
/// limits, and the elbow (arm_4) bend each pose forces. For the LWA3 the elbow
/// bend is fixed by the distance from the shoulder to the wrist centre, which a
/// TCP pose fixes: no choice of the redundant (swivel) joint can change it, so a
/// pose whose required bend exceeds the limit is out of reach for any posture.

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "common/kinematics/inverse_kinematics.h"
#include "common/scene/scene.h"
#include "services/coordinator/cycle_geometry.h"

namespace bookgrasp {

/// One pose of the cycle and whether the arm reaches it.
struct StageReach {
  std::string stage;            ///< e.g. "stripe_start", "grasp", "extract_end", "holder_place"
  Eigen::Isometry3d tcp;        ///< TCP pose in base
  bool reachable = false;       ///< IK converged within the joint limits
  double elbow_needed_rad = 0;  ///< |arm_4| this pose forces (NaN: the wrist is out of the arm's reach)
  std::string reason;           ///< IK's reason when not reachable
};

/// The elbow bend (rad, 0 = straight) that a TCP pose forces on the arm described by `kin`, from
/// the distance between the shoulder (arm_2 joint) and the wrist centre (arm_6 joint); NaN when
/// that distance is beyond the stretched arm or below the folded one.
double elbow_bend_for_tcp(const ArmKinematics& kin, const Eigen::Isometry3d& tcp);

/// The cart's grasp frame in base from the scene's true cart pose (X up, Y right, Z into the shelf).
Eigen::Isometry3d true_grasp_frame(const scene::Scene& scene);

/// Every stage pose of the cycle of the scene's book `book_index` (0 = the right-most at generation) from the
/// scene's truth and `g`, each checked with `ik` from `seed_q`, as if the books right of it had gone to the lower
/// shelf before it (its place there is left of theirs, `g.lower_gap` apart; their pushes are not modelled):
/// stripe_start, stripe_end, bwh_start, pre_grasp, grasp, extract_lift, extract_end,
/// holder_pre_place, holder_place, holder_retreat, holder_regrasp, lower_pre_place, lower_place, lower_retreat.
/// Throws std::runtime_error if the scene has no such book.
std::vector<StageReach> cycle_reach(const scene::Scene& scene, const CycleGeometry& g, const InverseKinematics& ik,
                                    const Eigen::VectorXd& seed_q, size_t book_index = 0);

}  // namespace bookgrasp
