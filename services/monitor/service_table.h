#pragma once
/// @file
/// The monitor's model: the latest SERVICE_STATUS of every service, restarts
/// detected from pid changes, rendered as a text table. No LCM in here.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "bookgrasp/service_status_t.hpp"

namespace bookgrasp {

/// What the monitor knows about one service.
struct ServiceRow {
  service_status_t last;           ///< latest status message
  int64_t received_utime = 0;      ///< monitor clock when it arrived
  int restarts = 0;                ///< pid changes seen
};

/// The latest status of every service seen on the bus.
class ServiceTable {
 public:
  /// Records a status received at `now_utime` (monitor clock).
  void update(const service_status_t& status, int64_t now_utime);
  /// Services seen so far, by name.
  const std::map<std::string, ServiceRow>& rows() const { return rows_; }
  /// Names from `expected` that have not published a status yet.
  std::vector<std::string> missing(const std::vector<std::string>& expected) const;
  /// A table: service, implementation, state, pid, uptime, status age,
  /// inputs and outputs with rates, data age, rejected, restarts, last error.
  /// A service whose last status is older than `stale_s` is shown as STALE.
  std::string render(int64_t now_utime, double stale_s = 3.0) const;

 private:
  std::map<std::string, ServiceRow> rows_;
};

/// Name of a service_status_t state ("RUNNING", ...).
std::string service_state_name(int8_t state);

}  // namespace bookgrasp
