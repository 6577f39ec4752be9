#include "services/arm_driver/joint_trajectory.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace bookgrasp {
namespace {

std::string fmt(const char* f, double a, double b) {
  char buf[128];
  std::snprintf(buf, sizeof(buf), f, a, b);
  return buf;
}

}  // namespace

std::string validate_trajectory(const JointTrajectory& tr, const Eigen::VectorXd& current, const ArmLimits& lim,
                                const TcpPosition& tcp) {
  const int n = static_cast<int>(lim.lower.size());
  const size_t m = tr.positions.size();
  if (m == 0) return "trajectory has no waypoints";
  if (tr.times.size() != m) return "trajectory has " + std::to_string(tr.times.size()) + " times for " +
                                   std::to_string(m) + " waypoints";
  if (!tr.velocities.empty() && tr.velocities.size() != m) return "velocities must be given for every waypoint or none";
  if (!tr.accelerations.empty() && tr.accelerations.size() != m)
    return "accelerations must be given for every waypoint or none";
  if (!tr.joint_names.empty() && tr.joint_names != lim.joint_names) {
    std::string expected;
    for (const auto& j : lim.joint_names) expected += (expected.empty() ? "" : ",") + j;
    return "joint names do not match the arm's (" + expected + ")";
  }
  const double rt = 1.0 + lim.relative_tolerance;
  for (size_t k = 0; k < m; ++k) {
    const std::string wp = "waypoint " + std::to_string(k) + ": ";
    if (!std::isfinite(tr.times[k])) return wp + "time is not finite";
    if (k == 0 && tr.times[0] < 0) return wp + "negative start time";
    if (k > 0 && !(tr.times[k] > tr.times[k - 1])) return wp + "times must increase strictly";
    const auto& q = tr.positions[k];
    if (q.size() != n) return wp + std::to_string(q.size()) + " joint values, the arm has " + std::to_string(n);
    if (!q.allFinite()) return wp + "position is not finite (NaN or inf)";
    for (int j = 0; j < n; ++j) {
      if (q[j] < lim.lower[j] - 1e-9 || q[j] > lim.upper[j] + 1e-9) {
        char buf[200];
        std::snprintf(buf, sizeof(buf), "joint %s position %.4f rad outside [%.4f, %.4f]",
                      lim.joint_names[j].c_str(), q[j], lim.lower[j], lim.upper[j]);
        return wp + buf;
      }
    }
    if (!tr.velocities.empty()) {
      const auto& v = tr.velocities[k];
      if (v.size() != n || !v.allFinite()) return wp + "velocity missing or not finite";
      for (int j = 0; j < n; ++j)
        if (std::abs(v[j]) > lim.max_velocity[j] * rt)
          return wp + "joint " + lim.joint_names[j] + fmt(" velocity %.3f rad/s > limit %.3f", std::abs(v[j]),
                                                          lim.max_velocity[j]);
    }
    if (!tr.accelerations.empty()) {
      const auto& a = tr.accelerations[k];
      if (a.size() != n || !a.allFinite()) return wp + "acceleration missing or not finite";
      for (int j = 0; j < n; ++j)
        if (std::abs(a[j]) > lim.max_acceleration[j] * rt)
          return wp + "joint " + lim.joint_names[j] + fmt(" acceleration %.3f rad/s^2 > limit %.3f", std::abs(a[j]),
                                                          lim.max_acceleration[j]);
    }
    if (k > 0) {
      const double dt = tr.times[k] - tr.times[k - 1];
      // Messages carry times in whole microseconds: each end of the segment may be off by 0.5 us,
      // so the mean rates below are known only to a relative 1 us / dt.
      const double rt_seg = rt + 1e-6 / dt;
      for (int j = 0; j < n; ++j) {
        const double mean_v = std::abs(q[j] - tr.positions[k - 1][j]) / dt;
        if (mean_v > lim.max_velocity[j] * rt_seg)
          return wp + "joint " + lim.joint_names[j] + fmt(" moves at %.3f rad/s on average > limit %.3f", mean_v,
                                                          lim.max_velocity[j]);
        if (!tr.velocities.empty()) {
          const double mean_a = std::abs(tr.velocities[k][j] - tr.velocities[k - 1][j]) / dt;
          if (mean_a > lim.max_acceleration[j] * rt_seg)
            return wp + "joint " + lim.joint_names[j] +
                   fmt(" accelerates at %.3f rad/s^2 on average > limit %.3f", mean_a, lim.max_acceleration[j]);
        }
      }
    }
    if (tcp) {
      const Eigen::Vector3d p = tcp(q);
      if ((p.array() < lim.workspace_min.array()).any() || (p.array() > lim.workspace_max.array()).any()) {
        char buf[160];
        std::snprintf(buf, sizeof(buf), "gripper at (%.3f, %.3f, %.3f) m leaves the workspace", p.x(), p.y(), p.z());
        return wp + buf;
      }
    }
  }
  if (current.size() != n) return "current joint state unknown: no SIM_STATE/ARM state yet";
  const double start_err = (tr.positions[0] - current).cwiseAbs().maxCoeff();
  if (start_err > lim.start_tolerance)
    return fmt("trajectory does not start at the current state (max joint difference %.4f rad > %.4f)", start_err,
               lim.start_tolerance);
  return "";
}

void sample_trajectory(const JointTrajectory& tr, double t, Eigen::VectorXd* q, Eigen::VectorXd* qd) {
  const size_t m = tr.positions.size();
  const int n = static_cast<int>(tr.positions[0].size());
  if (t <= tr.times.front() || m == 1) {
    *q = tr.positions.front();
    *qd = Eigen::VectorXd::Zero(n);
    if (m > 1 && !tr.velocities.empty()) *qd = tr.velocities.front();
    return;
  }
  if (t >= tr.times.back()) {
    *q = tr.positions.back();
    *qd = Eigen::VectorXd::Zero(n);
    return;
  }
  const size_t k = static_cast<size_t>(std::upper_bound(tr.times.begin(), tr.times.end(), t) - tr.times.begin());
  const double t0 = tr.times[k - 1], h = tr.times[k] - t0, s = (t - t0) / h;
  const Eigen::VectorXd& p0 = tr.positions[k - 1];
  const Eigen::VectorXd& p1 = tr.positions[k];
  if (tr.velocities.empty()) {
    *q = p0 + s * (p1 - p0);
    *qd = (p1 - p0) / h;
    return;
  }
  const Eigen::VectorXd& v0 = tr.velocities[k - 1];
  const Eigen::VectorXd& v1 = tr.velocities[k];
  const double s2 = s * s, s3 = s2 * s;
  const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
  *q = h00 * p0 + h10 * h * v0 + h01 * p1 + h11 * h * v1;
  const double d00 = 6 * s2 - 6 * s, d10 = 3 * s2 - 4 * s + 1, d01 = -6 * s2 + 6 * s, d11 = 3 * s2 - 2 * s;
  *qd = (d00 * p0 + d01 * p1) / h + d10 * v0 + d11 * v1;
}

}  // namespace bookgrasp
