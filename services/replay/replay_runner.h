#pragma once
/// @file
/// Re-runs components offline on recorded messages: feeds them the channels
/// they subscribe to, in log order, on an in-process bus driven by message
/// time (as fast as possible), and captures what they publish.

#include <memory>
#include <set>
#include <string>
#include <vector>

#include "common/component.h"
#include "common/lcm_log.h"

namespace bookgrasp {

/// What a replay did.
struct ReplayRun {
  std::vector<LoggedMessage> outputs;  ///< everything the components published, in order
  std::set<std::string> fed_channels;  ///< channels taken from the log
  std::set<int64_t> fed_utimes;        ///< message utimes of the fed messages
  int64_t messages_fed = 0;
  double log_duration_s = 0;           ///< message time spanned by the fed messages
  double wall_s = 0;                   ///< how long the replay took
};

/// Replays `log` through `components` (composed on memq://). Fed channels:
/// `feed` if not empty, else every channel some component subscribes to, minus
/// channels a component of the chain publishes (so a chain recomputes its
/// intermediate results instead of reading the recorded ones). `produced_by_chain`
/// lists channels known to be published by the chain (e.g. from a previous run);
/// channels seen published during the run are added as they appear.
ReplayRun replay_log(const std::vector<LoggedMessage>& log, std::vector<std::unique_ptr<Component>> components,
                     const std::set<std::string>& feed = {}, const std::set<std::string>& produced_by_chain = {});

}  // namespace bookgrasp
