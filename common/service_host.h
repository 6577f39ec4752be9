#pragma once
/// @file
/// Hosts one Component on a bus: the runtime duties shared by the process
/// runner and the in-process composition (SERVICE_STATUS at a fixed period,
/// the configuration snapshot at start and periodically, ticks).

#include <cstdint>
#include <memory>
#include <string>

#include "common/component.h"
#include "common/config.h"

namespace bookgrasp {

/// The `service:` section every service configuration starts with.
struct ServiceSettings {
  std::string name;                  ///< instance name, e.g. "bws_detector"
  std::string implementation;        ///< algorithm, e.g. "god"
  std::string lcm_url;               ///< "" = LCM_DEFAULT_URL or the image-safe default
  double status_period_s = 1.0;      ///< SERVICE_STATUS period
  double config_period_s = 5.0;      ///< CONFIG_SNAPSHOT period
  std::string status_channel = "SERVICE_STATUS";
  std::string config_channel = "CONFIG_SNAPSHOT";

  /// Reads the `service:` section; throws ConfigError naming a bad key.
  static ServiceSettings from_config(const Config& root);
};

/// Runs the periodic duties of one component against a clock given by the caller.
class ServiceHost {
 public:
  /// Takes ownership of `component`. `config_yaml`/`config_path` go into
  /// CONFIG_SNAPSHOT. With `publish_duties` false only ticks are run (a bare
  /// component in a test composition publishes no status or snapshot).
  ServiceHost(std::unique_ptr<Component> component, ServiceSettings settings, std::string config_yaml,
              std::string config_path, bool publish_duties = true);

  /// Attaches the component to `lcm`; `clock` is the runtime time source.
  void attach(lcm::LCM* lcm, std::function<int64_t()> clock);
  /// Publishes what is due at `now_utime` (status, config snapshot, tick).
  void poll(int64_t now_utime);
  /// Publishes a final SERVICE_STATUS with state STOPPING.
  void publish_stopping(int64_t now_utime);
  /// Microseconds until the next duty is due at `now_utime` (>= 0).
  int64_t until_next_due(int64_t now_utime) const;

  /// The hosted component.
  Component& component() { return *component_; }
  /// The settings it was started with.
  const ServiceSettings& settings() const { return settings_; }

 private:
  void publish_status(int64_t now_utime, int8_t state);
  void publish_config(int64_t now_utime);

  std::unique_ptr<Component> component_;
  ServiceSettings settings_;
  std::string config_yaml_;
  std::string config_path_;
  lcm::LCM* lcm_ = nullptr;
  int64_t start_utime_ = -1;
  int64_t next_status_ = 0;
  int64_t next_config_ = 0;
  int64_t next_tick_ = 0;
  bool publish_duties_ = true;
};

}  // namespace bookgrasp
