#pragma once
/// @file
/// Compares recorded outputs with replayed ones, channel by channel, down to
/// the fields that moved (e.g. "p1_base[1]: max |diff| 2.3 mm").

#include <map>
#include <set>
#include <string>
#include <vector>

#include "common/lcm_log.h"

namespace bookgrasp {

/// How one numeric or text field differs across the matched messages of a channel.
struct FieldDiff {
  std::string path;          ///< e.g. "p1_base[1]", "regions[*].offset_m" (array indices folded)
  int messages = 0;          ///< matched messages where it differs
  double max_abs = 0;        ///< largest |replayed - recorded| (numbers)
  double mean_abs = 0;       ///< mean over the messages where it differs
  std::string example;       ///< one "recorded -> replayed" example
};

/// Comparison of one channel.
struct ChannelDiff {
  std::string channel;
  std::string type;          ///< message type name ("" if unknown)
  int recorded = 0;          ///< messages in the recording
  int replayed = 0;          ///< messages the replay produced
  int matched = 0;           ///< pairs with the same utime (k-th with k-th)
  int identical = 0;         ///< matched pairs equal byte for byte
  int differing = 0;         ///< matched pairs that differ
  int missing = 0;           ///< recorded, not replayed
  int extra = 0;             ///< replayed, not recorded
  int unreplayable = 0;      ///< recorded, but its input (same utime) is not in the log: not counted as missing
  int after_log_end = 0;     ///< replayed after the channel's last recorded message: not counted as extra
  std::vector<FieldDiff> fields;  ///< fields that moved, largest first
};

/// The whole comparison.
struct DiffReport {
  std::vector<ChannelDiff> channels;
  /// True if every channel matched completely and every pair is identical.
  bool identical() const;
  /// A Markdown report.
  std::string markdown() const;
  /// The same as JSON.
  std::string json() const;
};

/// Compares the messages of `recorded` and `replayed` on `channels` (empty =
/// every channel the replay produced). Messages pair up by utime (the k-th
/// message with a given utime on a channel pairs with the k-th replayed one).
/// Fields ignored: any path in `ignore_fields` (e.g. timing fields like "total_ms").
/// Log boundaries: if `fed_utimes` (utimes of the messages fed to the replay) is
/// given, a recorded output with no fed input of the same utime is `unreplayable`,
/// and replayed outputs later than the channel's last recorded one are
/// `after_log_end` (the recording stopped before they were published); neither
/// makes the comparison differ.
DiffReport diff_outputs(const std::vector<LoggedMessage>& recorded, const std::vector<LoggedMessage>& replayed,
                        const std::set<std::string>& channels = {},
                        const std::set<std::string>& ignore_fields = {},
                        const std::set<int64_t>& fed_utimes = {});

}  // namespace bookgrasp
