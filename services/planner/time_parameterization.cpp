#include "services/planner/time_parameterization.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bookgrasp {
namespace {

/// Samples closer than this in time are not both kept: trajectory messages carry microseconds, and two samples
/// less than half a microsecond apart got the same utime, which the arm driver refuses ("times must increase
/// strictly", seen once in a composed run, default.yaml seed 5).
constexpr double kMinSampleGapS = 1e-5;

/// Trapezoidal profile of s from 0 to 1 with peak speed v and acceleration a.
struct Profile {
  double v = 0, a = 0, t_acc = 0, t_total = 0;
  Profile(double vmax, double amax) : v(vmax), a(amax) {
    if (v * v / a >= 1.0) {  // triangle: the peak speed is never reached
      v = std::sqrt(a);
      t_acc = v / a;
      t_total = 2 * t_acc;
    } else {
      t_acc = v / a;
      t_total = 2 * t_acc + (1.0 - v * v / a) / v;
    }
  }
  // s, s', s'' at time t in [0, t_total].
  void eval(double t, double& s, double& sd, double& sdd) const {
    t = std::clamp(t, 0.0, t_total);
    if (t < t_acc) {
      s = 0.5 * a * t * t;
      sd = a * t;
      sdd = a;
    } else if (t <= t_total - t_acc) {
      s = 0.5 * a * t_acc * t_acc + v * (t - t_acc);
      sd = v;
      sdd = 0;
    } else {
      const double r = t_total - t;
      s = 1.0 - 0.5 * a * r * r;
      sd = a * r;
      sdd = -a;
    }
  }
};

}  // namespace

TimedTrajectory parameterize_trapezoidal(const std::vector<Eigen::VectorXd>& waypoints,
                                         const Eigen::VectorXd& max_velocity,
                                         const Eigen::VectorXd& max_acceleration, double sample_period_s) {
  if (waypoints.empty()) throw std::invalid_argument("time parameterisation needs at least one waypoint");
  const Eigen::Index n = max_velocity.size();
  if (max_acceleration.size() != n) throw std::invalid_argument("velocity and acceleration limits differ in size");
  if (!(max_velocity.array() > 0).all() || !(max_acceleration.array() > 0).all() || !(sample_period_s > 0))
    throw std::invalid_argument("velocity/acceleration limits and the sample period must be positive");
  for (const auto& w : waypoints)
    if (w.size() != n) throw std::invalid_argument("waypoint size differs from the number of joint limits");

  TimedTrajectory out;
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  out.points.push_back({0.0, waypoints.front(), zero, zero});
  double t0 = 0.0;
  for (size_t k = 1; k < waypoints.size(); ++k) {
    const Eigen::VectorXd dq = waypoints[k] - waypoints[k - 1];
    const Eigen::VectorXd adq = dq.cwiseAbs();
    if (adq.maxCoeff() < 1e-12) continue;
    double vs = INFINITY, as = INFINITY;
    for (Eigen::Index j = 0; j < n; ++j) {
      if (adq[j] < 1e-12) continue;
      vs = std::min(vs, max_velocity[j] / adq[j]);
      as = std::min(as, max_acceleration[j] / adq[j]);
    }
    const Profile p(vs, as);
    if (p.t_total < kMinSampleGapS) {  // a step of ~1e-10 rad: the previous point takes this waypoint
      out.points.back().position = waypoints[k];
      continue;
    }
    // Samples on the global grid strictly inside the segment (at least kMinSampleGapS from both ends), then the
    // segment end exactly.
    double t_next = std::ceil(t0 / sample_period_s + 1e-9) * sample_period_s;
    if (t_next <= t0 + kMinSampleGapS) t_next += sample_period_s;
    for (; t_next < t0 + p.t_total - kMinSampleGapS; t_next += sample_period_s) {
      double s, sd, sdd;
      p.eval(t_next - t0, s, sd, sdd);
      out.points.push_back({t_next, waypoints[k - 1] + s * dq, sd * dq, sdd * dq});
    }
    t0 += p.t_total;
    out.points.push_back({t0, waypoints[k], zero, zero});
  }
  out.duration_s = t0;
  return out;
}

}  // namespace bookgrasp
