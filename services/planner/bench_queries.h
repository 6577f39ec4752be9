#pragma once
/// @file
/// The library query set of the planner benchmark (issue 6, item 6): random
/// scenes around the configured cart/holder, three kinds of query per scene:
///   pregrasp  home -> 10 cm in front of the right-most upper-shelf book (no book held)
///   holder    book pulled out of the shelf -> above the book holder (book held)
///   lower     above the holder -> in front of a lower-shelf slot (book held)
/// Deterministic for a seed. See docs/PLANNER.md for the numbers.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "services/planner/motion_planner.h"
#include "services/planner/planner_config.h"

namespace bookgrasp {

/// One benchmark query: a scene, an optional held book and a request.
struct BenchQuery {
  std::string kind;                  ///< "pregrasp", "holder" or "lower"
  std::vector<SceneBox> environment;
  bool holding_book = false;
  Eigen::Vector3d book_whd = Eigen::Vector3d::Zero();  ///< width (thickness), height, depth
  PlanRequest request;               ///< start joints, pose goal, tolerances (planner left empty)
};

/// Home posture of the benchmark: the simulation's initial joints (config/scenes/default.yaml),
/// folded low to the right and back.
Eigen::VectorXd bench_home_joints();

/// `count` queries (kinds in turn) from scenes drawn with `seed`. Starts of the book-holding
/// queries come from IK and are collision-free; scenes where they are not are redrawn.
std::vector<BenchQuery> make_library_queries(const PlannerSettings& settings, const PlannerStack& stack, int count,
                                             uint64_t seed);

/// Applies a query's environment and held book to `scene`.
void apply_query_scene(const BenchQuery& query, const HeldBookParams& held_book, PlanningScene& scene);

}  // namespace bookgrasp
