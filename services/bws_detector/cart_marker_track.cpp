#include "services/bws_detector/cart_marker_track.h"

#include <iterator>

namespace bookgrasp::bws {

void CartMarkerTrack::add(int64_t utime, const std::optional<Eigen::Isometry3d>& cart_in_base) {
  if (any_message_ && utime < latest_utime_ - kRestartUtime) clear();
  if (!any_message_ || utime > latest_utime_) latest_utime_ = utime;
  any_message_ = true;
  if (!cart_in_base) return;
  poses_[utime] = *cart_in_base;
  while (poses_.size() > capacity_) poses_.erase(poses_.begin());
}

std::optional<CartObservation> CartMarkerTrack::nearest(int64_t utime) const {
  if (poses_.empty()) return std::nullopt;
  auto after = poses_.lower_bound(utime);  // first at or after
  auto best = after;
  if (after == poses_.end()) {
    best = std::prev(after);
  } else if (after->first != utime && after != poses_.begin()) {
    const auto before = std::prev(after);
    if (utime - before->first <= after->first - utime) best = before;
  }
  return CartObservation{best->first, best->second};
}

void CartMarkerTrack::clear() {
  poses_.clear();
  any_message_ = false;
  latest_utime_ = 0;
}

}  // namespace bookgrasp::bws
