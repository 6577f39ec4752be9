#pragma once
/// @file
/// Which simulation states become camera frames, for a frame rate in
/// simulation time.

#include <cmath>
#include <cstdint>
#include <stdexcept>

namespace bookgrasp::sim_render {

/// Frames are due on a fixed grid of simulation time (multiples of the
/// period): a state is captured if it is the first one at or after the next
/// grid point. The grid does not depend on when the camera started, so the
/// same state stream always gives the same frames.
class CaptureSchedule {
 public:
  /// `rate_hz` frames per second of simulation time (> 0).
  explicit CaptureSchedule(double rate_hz) {
    if (!(rate_hz > 0.0) || !std::isfinite(rate_hz)) throw std::invalid_argument("frame rate must be > 0");
    period_us_ = static_cast<int64_t>(std::llround(1e6 / rate_hz));
    if (period_us_ < 1) period_us_ = 1;
  }
  /// True if a frame is due at `utime`; then the next frame is due at the
  /// next grid point after `utime`.
  bool due(int64_t utime) {
    if (started_ && utime < next_due_) return false;
    started_ = true;
    const int64_t slot = utime >= 0 ? utime / period_us_ : -((-utime + period_us_ - 1) / period_us_);
    next_due_ = (slot + 1) * period_us_;
    return true;
  }
  /// Frame period in microseconds.
  int64_t period_us() const { return period_us_; }

 private:
  int64_t period_us_ = 0;
  int64_t next_due_ = 0;
  bool started_ = false;
};

}  // namespace bookgrasp::sim_render
