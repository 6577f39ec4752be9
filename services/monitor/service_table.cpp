#include "services/monitor/service_table.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

namespace bookgrasp {

std::string service_state_name(int8_t s) {
  switch (s) {
    case service_status_t::STARTING: return "STARTING";
    case service_status_t::RUNNING: return "RUNNING";
    case service_status_t::DEGRADED: return "DEGRADED";
    case service_status_t::ERROR: return "ERROR";
    case service_status_t::STOPPING: return "STOPPING";
    default: return "?" + std::to_string(static_cast<int>(s));
  }
}

void ServiceTable::update(const service_status_t& status, int64_t now_utime) {
  auto it = rows_.find(status.service);
  if (it == rows_.end()) {
    rows_[status.service] = ServiceRow{status, now_utime, 0};
    return;
  }
  if (it->second.last.pid != status.pid) ++it->second.restarts;
  it->second.last = status;
  it->second.received_utime = now_utime;
}

std::vector<std::string> ServiceTable::missing(const std::vector<std::string>& expected) const {
  std::vector<std::string> out;
  for (const auto& e : expected)
    if (!rows_.count(e)) out.push_back(e);
  return out;
}

namespace {
std::string channels(const std::vector<channel_stats_t>& list, double* max_age) {
  std::string out;
  for (const auto& c : list) {
    char buf[128];
    std::snprintf(buf, sizeof(buf), "%s%s %.1fHz", out.empty() ? "" : ", ", c.channel.c_str(), c.rate_hz);
    out += buf;
    if (c.age_s > *max_age) *max_age = c.age_s;
  }
  return out.empty() ? "-" : out;
}
}  // namespace

std::string ServiceTable::render(int64_t now_utime, double stale_s) const {
  std::ostringstream o;
  char line[512];
  std::snprintf(line, sizeof(line), "%-18s %-18s %-9s %7s %8s %6s %8s %5s %4s  %s\n", "SERVICE", "IMPL", "STATE", "PID",
                "UPTIME", "AGE", "DATA_AGE", "REJ", "RST", "INPUTS | OUTPUTS | LAST ERROR");
  o << line;
  for (const auto& [name, row] : rows_) {
    const double age = (now_utime - row.received_utime) * 1e-6;
    const std::string state = age > stale_s ? "STALE" : service_state_name(row.last.state);
    double data_age = -1;
    const std::string in = channels(row.last.inputs, &data_age);
    double out_age = -1;
    const std::string out = channels(row.last.outputs, &out_age);
    char data_age_s[32];
    if (data_age < 0) std::snprintf(data_age_s, sizeof(data_age_s), "-");
    else std::snprintf(data_age_s, sizeof(data_age_s), "%.1fs", data_age);
    std::snprintf(line, sizeof(line), "%-18s %-18.18s %-9s %7d %7.0fs %5.1fs %8s %5lld %4d  ", name.c_str(),
                  row.last.implementation.c_str(), state.c_str(), row.last.pid, row.last.uptime_s, age, data_age_s,
                  static_cast<long long>(row.last.rejected_total), row.restarts);
    o << line << in << " | " << out << " | " << (row.last.last_error.empty() ? "-" : row.last.last_error) << "\n";
  }
  if (rows_.empty()) o << "(no SERVICE_STATUS seen yet)\n";
  return o.str();
}

}  // namespace bookgrasp
