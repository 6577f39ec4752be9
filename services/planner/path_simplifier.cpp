#include "services/planner/path_simplifier.h"

#include <random>

namespace bookgrasp {
namespace {

// Greedy pass: from each kept point, jump to the farthest point reachable in one valid motion.
std::vector<Eigen::VectorXd> greedy(const std::vector<Eigen::VectorXd>& path, const MotionCheck& valid) {
  std::vector<Eigen::VectorXd> out{path.front()};
  size_t i = 0;
  while (i + 1 < path.size()) {
    size_t next = i + 1;
    for (size_t j = path.size() - 1; j > i + 1; --j) {
      if (valid(path[i], path[j])) {
        next = j;
        break;
      }
    }
    out.push_back(path[next]);
    i = next;
  }
  return out;
}

}  // namespace

double path_length(const std::vector<Eigen::VectorXd>& path) {
  double length = 0.0;
  for (size_t i = 1; i < path.size(); ++i) length += (path[i] - path[i - 1]).norm();
  return length;
}

std::vector<Eigen::VectorXd> simplify_path(std::vector<Eigen::VectorXd> path, const MotionCheck& motion_valid,
                                           int random_shortcuts, uint64_t seed) {
  if (path.size() < 3) return path;
  path = greedy(path, motion_valid);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int attempt = 0; attempt < random_shortcuts && path.size() >= 3; ++attempt) {
    // Two points on different segments, at random fractions along them.
    std::uniform_int_distribution<size_t> pick(0, path.size() - 2);
    size_t a = pick(rng), b = pick(rng);
    if (a == b) continue;
    if (a > b) std::swap(a, b);
    const double fa = unit(rng), fb = unit(rng);
    const Eigen::VectorXd pa = path[a] + fa * (path[a + 1] - path[a]);
    const Eigen::VectorXd pb = path[b] + fb * (path[b + 1] - path[b]);
    // Only worth it if the shortcut is shorter than the path between the two points.
    double along = (path[a + 1] - pa).norm() + (pb - path[b]).norm();
    for (size_t k = a + 1; k < b; ++k) along += (path[k + 1] - path[k]).norm();
    if ((pb - pa).norm() > along - 1e-6) continue;
    if (!motion_valid(pa, pb)) continue;
    std::vector<Eigen::VectorXd> next(path.begin(), path.begin() + static_cast<long>(a) + 1);
    if ((pa - path[a]).norm() > 1e-9) next.push_back(pa);
    if ((pb - path[b + 1]).norm() > 1e-9) next.push_back(pb);
    next.insert(next.end(), path.begin() + static_cast<long>(b) + 1, path.end());
    path = std::move(next);
  }
  return greedy(path, motion_valid);
}

}  // namespace bookgrasp
