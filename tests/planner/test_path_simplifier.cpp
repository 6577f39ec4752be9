// Path simplification in a 2-D joint space with a square obstacle: the result
// never crosses it (checked independently at fine resolution), keeps the ends, is shorter.
#include "services/planner/path_simplifier.h"

#include <gtest/gtest.h>

namespace bookgrasp {
namespace {

// Obstacle: the square |x| < 0.5, |y| < 0.5.
bool free_point(const Eigen::VectorXd& q) { return std::abs(q[0]) >= 0.5 || std::abs(q[1]) >= 0.5; }

bool free_segment(const Eigen::VectorXd& a, const Eigen::VectorXd& b, double step) {
  const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
  for (int i = 0; i <= n; ++i)
    if (!free_point(a + (static_cast<double>(i) / n) * (b - a))) return false;
  return true;
}

// Exact test: does the segment a-b meet the open square? (Liang-Barsky clipping.)
bool free_segment_exact(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  double t0 = 0, t1 = 1;
  for (int k = 0; k < 2; ++k) {
    const double d = b[k] - a[k];
    if (std::abs(d) < 1e-15) {
      if (std::abs(a[k]) >= 0.5) return true;
      continue;
    }
    double ta = (-0.5 - a[k]) / d, tb = (0.5 - a[k]) / d;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 >= t1;  // empty (or single-point) overlap with the open square
}

Eigen::VectorXd p(double x, double y) { return (Eigen::VectorXd(2) << x, y).finished(); }

TEST(PathSimplifier, ShortensAZigZagAroundAnObstacleWithoutCrossingIt) {
  // A wasteful path from (-1, 0) to (1, 0) over the top of the square.
  std::vector<Eigen::VectorXd> path{p(-1, 0), p(-1.5, 0.5), p(-1, 1), p(-0.5, 1.5), p(0, 0.8),
                                    p(0.5, 1.5), p(1, 1), p(1.5, 0.5), p(1, 0)};
  for (size_t i = 1; i < path.size(); ++i) ASSERT_TRUE(free_segment(path[i - 1], path[i], 1e-4));
  const MotionCheck check = [](const Eigen::VectorXd& a, const Eigen::VectorXd& b) { return free_segment_exact(a, b); };
  const auto out = simplify_path(path, check, 200, 42);
  ASSERT_GE(out.size(), 3u);  // it cannot go straight through
  EXPECT_TRUE(out.front().isApprox(path.front()));
  EXPECT_TRUE(out.back().isApprox(path.back()));
  for (size_t i = 1; i < out.size(); ++i) EXPECT_TRUE(free_segment(out[i - 1], out[i], 1e-4));
  EXPECT_LT(path_length(out), 0.8 * path_length(path));
  // The shortest path over the square's corners is 2 * sqrt(0.5^2 + 0.5^2) + 1 = 2.414.
  EXPECT_GE(path_length(out), 2.414 - 1e-3);
  EXPECT_LT(path_length(out), 3.0);
}

TEST(PathSimplifier, DeterministicAndTrivialCases) {
  std::vector<Eigen::VectorXd> path{p(-1, 0), p(-1, 1), p(1, 1), p(1, 0)};
  const MotionCheck check = [](const Eigen::VectorXd& a, const Eigen::VectorXd& b) { return free_segment(a, b, 0.01); };
  const auto a = simplify_path(path, check, 50, 7), b = simplify_path(path, check, 50, 7);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(a[i] == b[i]);
  const std::vector<Eigen::VectorXd> two{p(0, 1), p(1, 1)};
  EXPECT_EQ(simplify_path(two, check, 10, 1).size(), 2u);
  EXPECT_NEAR(path_length({p(0, 0), p(3, 4)}), 5.0, 1e-12);
}

}  // namespace
}  // namespace bookgrasp
