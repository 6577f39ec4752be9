#pragma once
/// @file
/// CellBiRRT, the paper's planner (Section 4, refs [8, 9]) as an OMPL planner.
///
/// The Cartesian workspace is divided into cells. A cell is selected (roulette
/// on weights: high along the tube between the start and goal tool positions,
/// lowered each time a cell gives no usable sample) as the basis for a random
/// configuration: a tool position drawn inside the cell and an orientation
/// satisfying the end-effector constraint (the constrained orientation, or the
/// start/goal orientation interpolated along the tube with bounded noise) are
/// turned into a configuration by IK seeded from the nearest tree node. Two
/// trees (start, goals) grow towards these samples and towards each other
/// (RRT-Connect style extend/connect). A fraction of samples is uniform in
/// joint space to keep the search probabilistically complete.
///
/// Includes OMPL: include only from .cpp files.

#include <cstdint>
#include <functional>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <ompl/base/Planner.h>

#include "common/kinematics/inverse_kinematics.h"

namespace bookgrasp {

/// Tuning of CellBiRRT (configuration `planner.cell_birrt`).
struct CellBiRrtParams {
  double range_rad = 0.3;                 ///< longest tree extension step (joint-space norm)
  double cell_size_m = 0.1;               ///< cell edge length
  Eigen::Vector3d workspace_min{-1.2, -1.2, -0.9};  ///< workspace box (base frame) divided into cells
  Eigen::Vector3d workspace_max{1.2, 1.2, 1.4};
  double tube_sigma_m = 0.25;             ///< cell weight exp(-d^2 / 2 sigma^2), d = distance to the start-goal segment
  double min_cell_weight = 0.02;          ///< floor of a cell's weight (every free cell stays selectable)
  double failure_decay = 0.7;             ///< weight factor applied to a cell each time it gives no sample
  double cell_sample_probability = 0.8;   ///< cell samples vs uniform joint samples
  double orientation_noise_rad = 0.5;     ///< orientation spread of free (unconstrained) cell samples
  int ik_iterations = 40;                 ///< IK iterations per cell sample
};

/// What CellBiRRT needs to know about one problem besides the OMPL problem definition.
struct CellBiRrtProblem {
  Eigen::Isometry3d start_tip = Eigen::Isometry3d::Identity();  ///< tool pose at the start
  Eigen::Isometry3d goal_tip = Eigen::Isometry3d::Identity();   ///< tool pose at the goal
  bool keep_orientation = false;                 ///< samples use `constrained_orientation`
  Eigen::Matrix3d constrained_orientation = Eigen::Matrix3d::Identity();
  std::function<bool(const Eigen::Vector3d&)> point_free;  ///< false for cell centres inside obstacles
  uint64_t seed = 1;                             ///< random seed (same seed -> same tree)
};

/// The planner. Works on a RealVectorStateSpace of the arm's joints.
class CellBiRRT : public ompl::base::Planner {
 public:
  /// `ik` must outlive the planner.
  CellBiRRT(const ompl::base::SpaceInformationPtr& si, const InverseKinematics& ik, CellBiRrtParams params,
            CellBiRrtProblem problem);
  ~CellBiRRT() override;

  ompl::base::PlannerStatus solve(const ompl::base::PlannerTerminationCondition& ptc) override;
  void clear() override;
  /// Exports the planner properties only (the trees are not OMPL states).
  void getPlannerData(ompl::base::PlannerData& data) const override;

  /// Cell samples that produced a configuration / all cell sample attempts (after solve()).
  int cell_samples_ok() const { return cell_ok_; }
  /// Cell sample attempts (after solve()).
  int cell_samples_tried() const { return cell_tried_; }
  /// Nodes in both trees (after solve()).
  int tree_size() const { return static_cast<int>(trees_[0].size() + trees_[1].size()); }

 private:
  struct Node {
    Eigen::VectorXd q;
    Eigen::Vector3d tip;
    int parent = -1;
  };
  using Tree = std::vector<Node>;
  enum class Grow { kTrapped, kAdvanced, kReached };

  void build_cells();
  bool sample_cell(const Tree& tree, Eigen::VectorXd& q);
  void sample_uniform(Eigen::VectorXd& q);
  int nearest(const Tree& tree, const Eigen::VectorXd& q) const;
  Grow extend(Tree& tree, const Eigen::VectorXd& target, int& added);
  bool motion_ok(const Eigen::VectorXd& a, const Eigen::VectorXd& b) const;
  bool state_ok(const Eigen::VectorXd& q) const;
  int add_node(Tree& tree, const Eigen::VectorXd& q, int parent);

  const InverseKinematics& ik_;
  CellBiRrtParams params_;
  CellBiRrtProblem problem_;
  std::mt19937_64 rng_;
  std::vector<Eigen::Vector3d> cell_centres_;
  std::vector<double> cell_weights_;
  Tree trees_[2];
  int cell_ok_ = 0, cell_tried_ = 0;
};

}  // namespace bookgrasp
