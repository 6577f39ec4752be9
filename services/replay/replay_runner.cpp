#include "services/replay/replay_runner.h"

#include <chrono>

#include "common/composition.h"

namespace bookgrasp {
namespace {

/// Captures every message published on the bus except the ones the replay feeds in.
struct Capture {
  const std::set<std::string>* fed;
  std::vector<LoggedMessage>* out;
  bool feeding = false;  // true while the replay itself publishes a log message
  void on_any(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    if (feeding) return;
    LoggedMessage m;
    m.channel = channel;
    const auto* b = static_cast<const uint8_t*>(rbuf->data);
    m.data.assign(b, b + rbuf->data_size);
    m.log_utime = m.message_utime();
    out->push_back(std::move(m));
  }
};

}  // namespace

ReplayRun replay_log(const std::vector<LoggedMessage>& log, std::vector<std::unique_ptr<Component>> components,
                     const std::set<std::string>& feed, const std::set<std::string>& produced_by_chain) {
  const auto start = std::chrono::steady_clock::now();
  ReplayRun run;
  Composition comp;
  std::set<std::string> subscribed;
  std::vector<Component*> members;
  for (auto& c : components) {
    for (const auto& [ch, counter] : c->inputs()) subscribed.insert(ch);
    members.push_back(c.get());
    comp.add(std::move(c));
  }
  std::set<std::string> produced = produced_by_chain;
  auto should_feed = [&](const std::string& ch) {
    if (!feed.empty()) return feed.count(ch) > 0;
    return subscribed.count(ch) > 0 && produced.count(ch) == 0;
  };
  Capture capture{&run.fed_channels, &run.outputs};
  comp.bus().subscribe(".*", &Capture::on_any, &capture);

  int64_t first = -1, last = 0;
  for (const auto& m : log) {
    // A chain member has published this channel: from now on it is computed, not replayed.
    for (const auto* member : members)
      for (const auto& [ch, counter] : member->outputs())
        if (counter.count > 0) produced.insert(ch);
    if (!should_feed(m.channel)) continue;
    run.fed_channels.insert(m.channel);
    capture.feeding = true;
    comp.bus().publish(m.channel, m.data.data(), static_cast<unsigned>(m.data.size()));
    comp.spin(1);  // the fed message itself, seen by Capture while `feeding`
    capture.feeding = false;
    comp.spin();   // everything it caused
    ++run.messages_fed;
    const int64_t t = m.message_utime();
    run.fed_utimes.insert(t);
    if (first < 0) first = t;
    last = std::max(last, t);
  }
  run.log_duration_s = first >= 0 ? (last - first) * 1e-6 : 0.0;
  run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

}  // namespace bookgrasp
