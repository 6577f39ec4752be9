#pragma once
/// @file
/// Deterministic shortcutting of a joint-space polyline: greedy "connect to
/// the farthest directly reachable waypoint" passes and seeded random
/// shortcuts between points on the path. Only the caller's motion check
/// decides what is allowed, so every constraint it checks is kept.

#include <cstdint>
#include <functional>
#include <vector>

#include <Eigen/Core>

namespace bookgrasp {

/// True if the straight joint-space motion from a to b is valid (both ends included).
using MotionCheck = std::function<bool(const Eigen::VectorXd& a, const Eigen::VectorXd& b)>;

/// Sum of the Euclidean joint-space lengths of the segments.
double path_length(const std::vector<Eigen::VectorXd>& path);

/// Shortens `path` (first and last point kept) with greedy passes and
/// `random_shortcuts` random attempts seeded by `seed`. Never returns a path
/// with a segment `motion_valid` refused; a path of fewer than 3 points is returned as is.
std::vector<Eigen::VectorXd> simplify_path(std::vector<Eigen::VectorXd> path, const MotionCheck& motion_valid,
                                           int random_shortcuts, uint64_t seed);

}  // namespace bookgrasp
