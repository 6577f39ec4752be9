#pragma once
/// @file
/// The component: one service's subscriptions, handlers and publications,
/// independent of whether it runs as its own process (udpm) or composed with
/// others in one process (memq). The runtime (process_main.h, composition.h)
/// attaches it to a bus; the component never creates an LCM handle itself.

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "bookgrasp/service_status_t.hpp"

namespace bookgrasp {

/// Counters of one channel (input or output) of a component.
struct ChannelCounter {
  int64_t count = 0;            ///< messages handled / published
  int64_t rejected = 0;         ///< input messages that failed to decode or were refused
  int64_t last_stamp_utime = 0; ///< runtime clock at the last message (0 = none)
  int64_t count_at_last_report = 0;
  /// (report utime, count) of the status reports of the last kStatusRateWindowS: the rate in
  /// SERVICE_STATUS is over this window, so a 1 Hz stream reads 1 Hz, not 0 and 2 by turns.
  std::deque<std::pair<int64_t, int64_t>> report_history;
};

/// SERVICE_STATUS rates are averaged over the status reports of this many seconds (or all since the
/// start when fewer).
inline constexpr double kStatusRateWindowS = 5.0;

/// Base class of every service. A subclass declares its inputs in its
/// constructor with subscribe() and publishes with publish(); the runtime
/// calls attach() to connect it to a bus.
///
/// Handlers run on the thread that dispatches the bus. A handler that throws
/// does not stop the component: the message is counted as rejected, the error
/// is kept as last_error and reported in SERVICE_STATUS.
class Component {
 public:
  /// `service` is the instance name (e.g. "bws_detector"), `implementation`
  /// the algorithm behind it (e.g. "god").
  Component(std::string service, std::string implementation);
  virtual ~Component();
  Component(const Component&) = delete;
  Component& operator=(const Component&) = delete;

  /// Instance name, as in SERVICE_STATUS.service.
  const std::string& service() const { return service_; }
  /// Implementation name, as in SERVICE_STATUS.implementation.
  const std::string& implementation() const { return implementation_; }

  /// Connects every declared subscription to `lcm`; publications go to it.
  /// `clock` gives the runtime's time in microseconds (wall time for a
  /// process, message time in a composition): it is used for statistics
  /// only, never for outputs.
  void attach(lcm::LCM* lcm, std::function<int64_t()> clock);
  /// Removes the subscriptions; the component can be attached again.
  void detach();

  /// Called by the runtime at the component's tick period, with the runtime
  /// clock. Default: nothing. Hardware drivers and timers override it.
  virtual void on_tick(int64_t now_utime);
  /// Requested tick period in seconds (0 = never). Default 0.
  virtual double tick_period_s() const { return 0.0; }
  /// Called by the runtime once no further input message is waiting (after a burst was dispatched).
  /// Components whose work per input is expensive (a camera's rendering) note the newest input in
  /// their handler and do the work here, so a backlog is skipped instead of worked through late.
  /// Returns true if it did work (it may have published). Default: nothing, false.
  virtual bool on_inputs_drained() { return false; }

  /// The component's health at `now_utime` (rates over the period since the
  /// previous call). Resets the per-report counters.
  service_status_t make_status(int64_t now_utime, double uptime_s);
  /// Messages rejected on all inputs so far.
  int64_t rejected_total() const { return rejected_total_; }
  /// Last error text ("" if none).
  const std::string& last_error() const { return last_error_; }
  /// Input counters by channel.
  const std::map<std::string, ChannelCounter>& inputs() const { return inputs_; }
  /// Output counters by channel.
  const std::map<std::string, ChannelCounter>& outputs() const { return outputs_; }

  /// Records a rejected input on `channel` with a reason that names the
  /// problem. Logged to stderr (rate limited) and reported in SERVICE_STATUS.
  void reject(const std::string& channel, const std::string& reason);
  /// Records an error that is not tied to one input.
  void report_error(const std::string& reason);

 protected:
  /// Declares a typed input. `handler` is called with each decoded message;
  /// messages that fail to decode (garbage, wrong type) are rejected.
  template <typename Msg, typename Derived>
  void subscribe(const std::string& channel, void (Derived::*handler)(const Msg&));

  /// Publishes `msg` on `channel` and counts it.
  template <typename Msg>
  void publish(const std::string& channel, const Msg& msg);

  /// The bus, or nullptr before attach().
  lcm::LCM* bus() const { return lcm_; }

 private:
  struct Input {
    std::string channel;
    std::function<void(const lcm::ReceiveBuffer*)> dispatch;
    lcm::Subscription* subscription = nullptr;
    Component* owner = nullptr;
    void on_raw(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  };
  void count_input(const std::string& channel);
  void count_output(const std::string& channel);
  int64_t now() const { return clock_ ? clock_() : 0; }

  std::string service_;
  std::string implementation_;
  lcm::LCM* lcm_ = nullptr;
  std::function<int64_t()> clock_;
  std::vector<std::unique_ptr<Input>> input_list_;
  std::map<std::string, ChannelCounter> inputs_;
  std::map<std::string, ChannelCounter> outputs_;
  int64_t rejected_total_ = 0;
  std::string last_error_;
  int64_t last_error_utime_ = 0;
  int64_t last_report_utime_ = 0;
  int64_t rejected_at_last_report_ = 0;
  int64_t errors_logged_ = 0;
};

// ---- template implementations ----

template <typename Msg, typename Derived>
void Component::subscribe(const std::string& channel, void (Derived::*handler)(const Msg&)) {
  auto input = std::make_unique<Input>();
  input->channel = channel;
  input->owner = this;
  Derived* self = static_cast<Derived*>(this);
  input->dispatch = [this, self, handler, channel](const lcm::ReceiveBuffer* rbuf) {
    Msg msg;
    const int used = msg.decode(rbuf->data, 0, rbuf->data_size);
    if (used < 0 || static_cast<uint32_t>(used) != rbuf->data_size) {
      reject(channel, "cannot decode " + std::to_string(rbuf->data_size) + " bytes as " +
                          Msg::getTypeName() + " (garbage or a message of another type)");
      return;
    }
    count_input(channel);
    (self->*handler)(msg);
  };
  inputs_[channel];
  input_list_.push_back(std::move(input));
}

template <typename Msg>
void Component::publish(const std::string& channel, const Msg& msg) {
  if (!lcm_) {
    report_error("publish on " + channel + " before the component is attached to a bus");
    return;
  }
  if (lcm_->publish(channel, &msg) != 0) {
    report_error("publish on " + channel + " failed (message too large or bus down)");
    return;
  }
  count_output(channel);
}

}  // namespace bookgrasp
