#pragma once
/// @file
/// The planning scene: the robot's collision primitives (from the URDF), the
/// environment as oriented boxes, an optional box attached to the gripper (a
/// held book), an allowed-collision matrix, and a distance margin. Answers
/// "is this configuration collision-free?" for the planner. FCL stays in the .cpp.

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/kinematics/arm_kinematics.h"

namespace bookgrasp {

/// An oriented box of the environment (cart board, shelf, screen, floor, book volume).
struct SceneBox {
  std::string name;                                       ///< for failure messages ("cart_upper_shelf")
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity(); ///< box centre and axes in the base frame
  Eigen::Vector3d size = Eigen::Vector3d::Zero();         ///< full edge lengths, metres
};

/// A box rigidly attached to the tip link (the held book).
struct AttachedBox {
  std::string name = "held_book";
  Eigen::Isometry3d pose_in_tip = Eigen::Isometry3d::Identity();  ///< box centre in the tip (gripper) frame
  Eigen::Vector3d size = Eigen::Vector3d::Zero();                 ///< full edge lengths, metres
  std::vector<std::string> touch_links;  ///< robot links it may touch (palm, fingers)
  /// Its distance to keep from the environment: < 0 the scene's environment margin, else this (at most the
  /// scene's). A measured book may enter a gap the robot's margins were not chosen for.
  double environment_margin_m = -1.0;
};

/// Settings of the collision checks.
struct PlanningSceneParams {
  double environment_margin_m = 0.02;  ///< robot (and held box) must stay this far from the environment
  double self_margin_m = 0.005;        ///< non-adjacent robot links must stay this far apart
  double finger_position_m = 0.0301;   ///< finger joint value used for the finger geometry
  /// Box (base frame) the tool centre point must stay in: the arm driver's workspace limit, so
  /// the planner never produces a path the driver refuses. Unbounded by default.
  Eigen::Vector3d tool_min = Eigen::Vector3d::Constant(-1e9);
  Eigen::Vector3d tool_max = Eigen::Vector3d::Constant(1e9);
  /// Extra allowed link pairs, beyond adjacent links (parent/child through one joint, looking
  /// through links without geometry) and links that collide at every configuration.
  std::vector<std::pair<std::string, std::string>> allowed_collisions;
};

/// The first colliding pair found, for messages.
struct CollisionReport {
  bool collision = false;
  std::string first;   ///< robot link (or attached box) name
  std::string second;  ///< other robot link or environment box name
  /// "a with b" or "" when free.
  std::string describe() const { return collision ? first + " with " + second : std::string(); }
};

/// Collision checker for one arm in a box world.
///
/// Margins are applied by inflating the robot primitives (sphere radius +m,
/// cylinder radius +m and length +2m, box edges +2m): every inflated shape
/// contains the true shape's m-neighbourhood, so "inflated shapes do not
/// touch" guarantees a distance of at least m (conservative at box corners).
/// Const methods are thread-safe.
class PlanningScene {
 public:
  /// Builds the robot geometry and the allowed-collision matrix. Throws
  /// std::invalid_argument for an unknown link in allowed_collisions or a negative margin.
  PlanningScene(ArmKinematics kinematics, PlanningSceneParams params);
  ~PlanningScene();
  PlanningScene(const PlanningScene&);
  PlanningScene& operator=(const PlanningScene&);

  /// Replaces the environment. Throws std::invalid_argument for a non-positive or non-finite box.
  void set_environment(std::vector<SceneBox> boxes);
  /// The environment boxes.
  const std::vector<SceneBox>& environment() const { return environment_; }
  /// Attaches a box to the tip link (replaces any attached box). Throws for an unknown touch link.
  void attach(const AttachedBox& box);
  /// Removes the attached box.
  void detach();
  /// True if a box is attached.
  bool has_attached() const { return attached_.has_value; }

  /// True if q is within the joint limits and collision-free with the margins.
  bool is_valid(const Eigen::VectorXd& q) const;
  /// The first collision at q. `with_margins` false checks the exact shapes (zero margin).
  CollisionReport check(const Eigen::VectorXd& q, bool with_margins = true) const;
  /// Link pairs that are never checked against each other (for docs and tests).
  std::vector<std::pair<std::string, std::string>> allowed_pairs() const;

  /// The kinematics the scene uses.
  const ArmKinematics& kinematics() const { return kin_; }
  /// The parameters.
  const PlanningSceneParams& params() const { return params_; }

 private:
  struct Geometry;  // FCL objects of the robot and environment
  struct Attached {
    bool has_value = false;
    AttachedBox box;
  };
  void rebuild_pairs();

  ArmKinematics kin_;
  PlanningSceneParams params_;
  std::vector<SceneBox> environment_;
  Attached attached_;
  std::unique_ptr<Geometry> geo_;
};

}  // namespace bookgrasp
