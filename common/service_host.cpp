#include "common/service_host.h"

#include <algorithm>
#include <cstdint>

#include "bookgrasp/config_snapshot_t.hpp"
#include "common/version.h"

namespace bookgrasp {

ServiceSettings ServiceSettings::from_config(const Config& root) {
  const Config s = root.child("service");
  ServiceSettings out;
  out.name = s.get<std::string>("name");
  if (out.name.empty()) throw ConfigError(root.source() + ": key 'service.name' must not be empty");
  out.implementation = s.get<std::string>("implementation");
  out.lcm_url = s.get<std::string>("lcm_url");
  out.status_period_s = s.get_double("status_period_s", 0.01, 3600.0);
  out.config_period_s = s.get_double("config_period_s", 0.1, 3600.0);
  out.status_channel = s.get<std::string>("status_channel");
  out.config_channel = s.get<std::string>("config_channel");
  return out;
}

ServiceHost::ServiceHost(std::unique_ptr<Component> component, ServiceSettings settings, std::string config_yaml,
                         std::string config_path, bool publish_duties)
    : component_(std::move(component)),
      settings_(std::move(settings)),
      config_yaml_(std::move(config_yaml)),
      config_path_(std::move(config_path)),
      publish_duties_(publish_duties) {}

void ServiceHost::attach(lcm::LCM* lcm, std::function<int64_t()> clock) {
  lcm_ = lcm;
  component_->attach(lcm, std::move(clock));
}

void ServiceHost::poll(int64_t now_utime) {
  if (!lcm_) return;
  if (start_utime_ < 0) {
    start_utime_ = now_utime;
    next_status_ = now_utime;
    next_config_ = now_utime;
    next_tick_ = now_utime;
  }
  const auto period = [](double s) { return static_cast<int64_t>(s * 1e6); };
  if (publish_duties_ && now_utime >= next_config_) {
    publish_config(now_utime);
    next_config_ = now_utime + period(settings_.config_period_s);
  }
  if (publish_duties_ && now_utime >= next_status_) {
    publish_status(now_utime, -1);
    next_status_ = now_utime + period(settings_.status_period_s);
  }
  const double tick = component_->tick_period_s();
  if (tick > 0 && now_utime >= next_tick_) {
    component_->on_tick(now_utime);
    next_tick_ = now_utime + period(tick);
  }
}

int64_t ServiceHost::until_next_due(int64_t now_utime) const {
  if (start_utime_ < 0) return 0;
  int64_t next = publish_duties_ ? std::min(next_status_, next_config_) : INT64_MAX;
  if (component_->tick_period_s() > 0) next = std::min(next, next_tick_);
  return std::max<int64_t>(0, next - now_utime);
}

void ServiceHost::publish_stopping(int64_t now_utime) {
  if (lcm_ && publish_duties_) publish_status(now_utime, service_status_t::STOPPING);
}

void ServiceHost::publish_status(int64_t now_utime, int8_t state) {
  const double uptime = start_utime_ >= 0 ? (now_utime - start_utime_) * 1e-6 : 0.0;
  service_status_t st = component_->make_status(now_utime, uptime);
  st.service = settings_.name;
  if (state >= 0) st.state = state;
  lcm_->publish(settings_.status_channel, &st);
}

void ServiceHost::publish_config(int64_t now_utime) {
  config_snapshot_t snap;
  snap.utime = now_utime;
  snap.service = settings_.name;
  snap.implementation = component_->implementation();
  snap.version = kVersion;
  snap.config_path = config_path_;
  snap.config_yaml = config_yaml_;
  lcm_->publish(settings_.config_channel, &snap);
}

}  // namespace bookgrasp
