#pragma once
/// @file
/// Reading and writing LCM log files as plain values.

#include <cstdint>
#include <string>
#include <vector>

namespace bookgrasp {

/// One message of a log: where it was published, when it was recorded, its bytes.
struct LoggedMessage {
  int64_t log_utime = 0;        ///< lcm-logger's receive time (wall clock)
  std::string channel;
  std::vector<uint8_t> data;    ///< the encoded message
  /// The message's own utime (message time), read from the encoded bytes; 0 if too short.
  int64_t message_utime() const;
};

/// Reads a whole LCM log. Throws std::runtime_error naming the file if it
/// cannot be opened or is not an LCM log.
std::vector<LoggedMessage> read_lcm_log(const std::string& path);

/// Writes `messages` as an LCM log (overwrites). Throws std::runtime_error on failure.
void write_lcm_log(const std::string& path, const std::vector<LoggedMessage>& messages);

}  // namespace bookgrasp
