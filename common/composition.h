#pragma once
/// @file
/// Several components in one process on one in-process bus (memq://), driven
/// by message time. Used by tests, evaluation and replay; the components are
/// the same classes the service processes run.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "common/component.h"
#include "common/service_host.h"
#include "common/time_source.h"

namespace bookgrasp {

/// An in-process bus with the components attached to it.
///
/// Dispatch is single-threaded and in publication order, so the same inputs
/// give the same outputs. The clock is message time (the latest utime seen on
/// the bus); SERVICE_STATUS and CONFIG_SNAPSHOT follow it when enabled.
class Composition {
 public:
  /// Opens `url` (default memq://). Throws std::runtime_error if it cannot.
  explicit Composition(const std::string& url = "memq://");
  ~Composition();

  /// Adds a component without runtime duties (no status, no config snapshot).
  /// Returns a reference valid for the composition's lifetime.
  template <typename T>
  T& add(std::unique_ptr<T> component) {
    T& ref = *component;
    add_host(std::make_unique<ServiceHost>(std::move(component), settings_for(ref), "", "", false));
    return ref;
  }
  /// Adds a component with its settings; it publishes SERVICE_STATUS and
  /// CONFIG_SNAPSHOT in message time like a process would.
  Component& add_service(std::unique_ptr<Component> component, const ServiceSettings& settings,
                         const std::string& config_yaml);

  /// Dispatches queued messages until the queue is empty or `max_messages`
  /// were handled (-1 = no limit); each time the queue is empty the
  /// components' Component::on_inputs_drained() runs, and what they publish
  /// is dispatched too. Returns the number of messages handled.
  int spin(int max_messages = -1);

  /// The bus: publish inputs here.
  lcm::LCM& bus() { return lcm_; }
  /// Message time: the latest utime seen on the bus.
  int64_t now_utime() const { return time_.now_utime(); }

 private:
  static ServiceSettings settings_for(const Component& c);
  void add_host(std::unique_ptr<ServiceHost> host);
  void on_any(const lcm::ReceiveBuffer* rbuf, const std::string& channel);

  lcm::LCM lcm_;
  MessageTimeSource time_;
  std::vector<std::unique_ptr<ServiceHost>> hosts_;
};

}  // namespace bookgrasp
