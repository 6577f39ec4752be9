#include "services/arbiter/p1_frames.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace bookgrasp {

P1Frames::P1Frames(int frames) : frames_(frames) {
  if (frames < 1) throw std::invalid_argument("P1Frames: frames must be >= 1, got " + std::to_string(frames));
}

void P1Frames::add(const std::optional<Eigen::Vector3d>& p1) {
  window_.push_back(p1);
  if (static_cast<int>(window_.size()) > frames_) window_.erase(window_.begin());
}

std::optional<Eigen::Vector3d> P1Frames::p1() const {
  if (!full()) return std::nullopt;
  std::vector<Eigen::Vector3d> found;
  for (const auto& p : window_)
    if (p) found.push_back(*p);
  if (2 * found.size() <= window_.size()) return std::nullopt;
  Eigen::Vector3d m;
  for (int k = 0; k < 3; ++k) {
    std::vector<double> v;
    for (const auto& p : found) v.push_back(p[k]);
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    m[k] = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  }
  return m;
}

}  // namespace bookgrasp
