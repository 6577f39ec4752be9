#pragma once
/// @file
/// The cart marker's observations by message time, so that each stereo frame is
/// answered with the cart pose the marker detector measured in that same frame
/// (same utime), whatever order the two messages arrive in. Pure: no LCM.

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>

#include <Eigen/Geometry>

namespace bookgrasp::bws {

/// The cart pose seen at one message time.
struct CartObservation {
  int64_t utime = 0;               ///< utime of the MARKERS message (= the stereo frame it came from)
  Eigen::Isometry3d cart_in_base;  ///< the cart marker's pose in `base`
};

/// Cart marker observations by utime.
class CartMarkerTrack {
 public:
  /// A MARKERS message this long before the latest one means its source restarted (a
  /// restarted simulation's clock starts over): what came before is forgotten.
  static constexpr int64_t kRestartUtime = 1000000;

  /// Keeps at most `capacity` observations (the oldest go first).
  explicit CartMarkerTrack(size_t capacity = 64) : capacity_(capacity) {}

  /// Records one MARKERS message at `utime`: the cart pose when it had the cart marker,
  /// nothing otherwise (the message still says the detector has answered up to `utime`).
  void add(int64_t utime, const std::optional<Eigen::Isometry3d>& cart_in_base);

  /// True once a MARKERS message at or after `utime` was recorded: the marker detector's
  /// answer for the frame at `utime` is in (or will never come).
  bool covers(int64_t utime) const { return any_message_ && latest_utime_ >= utime; }

  /// The observation at `utime` if there is one, else the one nearest in time (the earlier
  /// on a tie); nothing when no cart marker was seen.
  std::optional<CartObservation> nearest(int64_t utime) const;

  /// Forgets everything (a frame from a restarted source).
  void clear();

  /// True when no cart marker is kept.
  bool empty() const { return poses_.empty(); }

 private:
  size_t capacity_;
  std::map<int64_t, Eigen::Isometry3d> poses_;
  bool any_message_ = false;
  int64_t latest_utime_ = 0;
};

}  // namespace bookgrasp::bws
