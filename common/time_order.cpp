#include "common/time_order.h"

namespace bookgrasp {

TimeOrder TimeOrderGuard::check(int64_t utime) {
  if (last_ == INT64_MIN || utime > last_) {
    previous_ = last_;
    last_ = utime;
    return TimeOrder::kNext;
  }
  if (last_ - utime > restart_jump_us_) {
    previous_ = last_;
    last_ = utime;
    return TimeOrder::kRestarted;
  }
  return TimeOrder::kStale;
}

std::string TimeOrderGuard::describe(int64_t utime, TimeOrder verdict) const {
  switch (verdict) {
    case TimeOrder::kStale:
      return "utime " + std::to_string(utime) + " is not after the previous " + std::to_string(last_) +
             " (out of order or repeated): ignored";
    case TimeOrder::kRestarted:
      return "utime " + std::to_string(utime) + " is " + std::to_string((previous_ - utime) / 1000) +
             " ms before the previous " + std::to_string(previous_) + ": the source restarted; state reset";
    case TimeOrder::kNext:
      break;
  }
  return "";
}

}  // namespace bookgrasp
