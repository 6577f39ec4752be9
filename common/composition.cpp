#include "common/composition.h"

#include <stdexcept>

namespace bookgrasp {

Composition::Composition(const std::string& url) : lcm_(url) {
  if (!lcm_.good()) throw std::runtime_error("cannot open LCM bus '" + url + "'");
  // Subscribed first, so the clock advances before any component sees the message.
  lcm_.subscribe(".*", &Composition::on_any, this);
}

Composition::~Composition() {
  for (auto& h : hosts_) h->component().detach();
}

ServiceSettings Composition::settings_for(const Component& c) {
  ServiceSettings s;
  s.name = c.service();
  s.implementation = c.implementation();
  return s;
}

void Composition::add_host(std::unique_ptr<ServiceHost> host) {
  host->attach(&lcm_, [this] { return time_.now_utime(); });
  hosts_.push_back(std::move(host));
}

Component& Composition::add_service(std::unique_ptr<Component> component, const ServiceSettings& settings,
                                    const std::string& config_yaml) {
  Component& ref = *component;
  add_host(std::make_unique<ServiceHost>(std::move(component), settings, config_yaml, "", true));
  return ref;
}

void Composition::on_any(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
  time_.observe(rbuf->data, rbuf->data_size);
}

int Composition::spin(int max_messages) {
  int handled = 0;
  while (max_messages < 0 || handled < max_messages) {
    if (lcm_.handleTimeout(0) <= 0) {
      // Nothing waiting: the components' deferred work (as a process would do it), which may publish.
      bool worked = false;
      for (auto& h : hosts_) worked = h->component().on_inputs_drained() || worked;
      if (!worked) break;
      continue;
    }
    ++handled;
    for (auto& h : hosts_) h->poll(time_.now_utime());
  }
  return handled;
}

}  // namespace bookgrasp
