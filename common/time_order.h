#pragma once
/// @file
/// Time order of one source's messages (message time): later is normal; slightly earlier or equal
/// is out of order (rejected); much earlier means the source restarted (a restarted simulation
/// starts its clock again), which consumers must accept and recover from instead of rejecting
/// everything until the new clock passes the old one.

#include <cstdint>
#include <string>

namespace bookgrasp {

/// A message time arriving after the ones seen before it: how to treat it.
enum class TimeOrder {
  kNext,       ///< later than the last one: normal
  kStale,      ///< equal, or earlier by at most the restart jump: out of order, reject it
  kRestarted,  ///< earlier by more than the restart jump: the source restarted, accept it and reset
};

/// Classifies the message times of one source.
class TimeOrderGuard {
 public:
  /// Jumps back of more than `restart_jump_us` mean a restart of the source.
  explicit TimeOrderGuard(int64_t restart_jump_us = kDefaultRestartJumpUs) : restart_jump_us_(restart_jump_us) {}
  /// Classifies `utime` and, unless kStale, makes it the last time seen.
  TimeOrder check(int64_t utime);
  /// The last accepted time (INT64_MIN before any).
  int64_t last() const { return last_; }
  /// A message for a rejected or restarting time: names both times and what happens.
  std::string describe(int64_t utime, TimeOrder verdict) const;

  /// One second: far beyond any reordering on a bus, far below any restart of a simulation.
  static constexpr int64_t kDefaultRestartJumpUs = 1000000;

 private:
  int64_t restart_jump_us_;
  int64_t last_ = INT64_MIN;
  int64_t previous_ = INT64_MIN;
};

}  // namespace bookgrasp
