#include "common/component.h"

#include <unistd.h>

#include <exception>
#include <iostream>

#include "common/version.h"

namespace bookgrasp {

Component::Component(std::string service, std::string implementation)
    : service_(std::move(service)), implementation_(std::move(implementation)) {}

Component::~Component() { detach(); }

void Component::attach(lcm::LCM* lcm, std::function<int64_t()> clock) {
  detach();
  lcm_ = lcm;
  clock_ = std::move(clock);
  for (auto& in : input_list_) in->subscription = lcm_->subscribe(in->channel, &Input::on_raw, in.get());
}

void Component::detach() {
  if (!lcm_) return;
  for (auto& in : input_list_) {
    if (in->subscription) lcm_->unsubscribe(in->subscription);
    in->subscription = nullptr;
  }
  lcm_ = nullptr;
}

void Component::Input::on_raw(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
  try {
    dispatch(rbuf);
  } catch (const std::exception& e) {
    owner->reject(channel, std::string("handler failed: ") + e.what());
  } catch (...) {
    owner->reject(channel, "handler failed with an unknown exception");
  }
}

void Component::on_tick(int64_t /*now_utime*/) {}

void Component::count_input(const std::string& channel) {
  auto& c = inputs_[channel];
  ++c.count;
  c.last_stamp_utime = now();
}

void Component::count_output(const std::string& channel) {
  auto& c = outputs_[channel];
  ++c.count;
  c.last_stamp_utime = now();
}

void Component::reject(const std::string& channel, const std::string& reason) {
  auto& c = inputs_[channel];
  ++c.rejected;
  ++rejected_total_;
  report_error(channel + ": " + reason);
}

void Component::report_error(const std::string& reason) {
  last_error_ = reason;
  last_error_utime_ = now();
  // Log the first errors and then every 100th, so a flood cannot fill a disk.
  if (errors_logged_ < 20 || errors_logged_ % 100 == 0)
    std::cerr << "[" << service_ << "] error: " << reason << std::endl;
  ++errors_logged_;
}

namespace {
std::vector<channel_stats_t> to_stats(std::map<std::string, ChannelCounter>* counters, int64_t now_utime,
                                      double period_s) {
  std::vector<channel_stats_t> out;
  for (auto& [name, c] : *counters) {
    channel_stats_t s;
    s.utime = c.last_stamp_utime;
    s.channel = name;
    s.count = c.count;
    s.rejected = c.rejected;
    // Rate over the reports of the last kStatusRateWindowS (the first report: over its own period).
    if (!c.report_history.empty() && now_utime > c.report_history.front().first)
      s.rate_hz = static_cast<double>(c.count - c.report_history.front().second) /
                  ((now_utime - c.report_history.front().first) * 1e-6);
    else
      s.rate_hz = period_s > 0 ? (c.count - c.count_at_last_report) / period_s : 0.0;
    s.age_s = c.last_stamp_utime > 0 ? (now_utime - c.last_stamp_utime) * 1e-6 : -1.0;
    c.count_at_last_report = c.count;
    c.report_history.emplace_back(now_utime, c.count);
    const int64_t window_start = now_utime - static_cast<int64_t>(kStatusRateWindowS * 1e6);
    while (c.report_history.size() >= 2 && c.report_history[1].first <= window_start) c.report_history.pop_front();
    out.push_back(s);
  }
  return out;
}
}  // namespace

service_status_t Component::make_status(int64_t now_utime, double uptime_s) {
  const double period_s = last_report_utime_ > 0 ? (now_utime - last_report_utime_) * 1e-6 : 0.0;
  service_status_t st;
  st.utime = now_utime;
  st.service = service_;
  st.implementation = implementation_;
  st.version = kVersion;
  st.pid = static_cast<int32_t>(::getpid());
  st.uptime_s = uptime_s;
  st.inputs = to_stats(&inputs_, now_utime, period_s);
  st.num_inputs = static_cast<int32_t>(st.inputs.size());
  st.outputs = to_stats(&outputs_, now_utime, period_s);
  st.num_outputs = static_cast<int32_t>(st.outputs.size());
  st.rejected_total = rejected_total_;
  st.last_error = last_error_;
  st.last_error_utime = last_error_utime_;
  st.state = rejected_total_ > rejected_at_last_report_ ? service_status_t::DEGRADED : service_status_t::RUNNING;
  rejected_at_last_report_ = rejected_total_;
  last_report_utime_ = now_utime;
  return st;
}

}  // namespace bookgrasp
