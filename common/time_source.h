#pragma once
/// @file
/// Time sources of the runtime. Wall time is for the runtime's own duties in
/// a process (status period, ticks); message time drives everything that must
/// be deterministic (composition, replay, simulation).

#include <chrono>
#include <cstdint>
#include <cstring>

namespace bookgrasp {

/// Wall-clock microseconds since the Unix epoch.
class WallTimeSource {
 public:
  /// Now, in microseconds since the epoch.
  int64_t now_utime() const {
    return std::chrono::duration_cast<std::chrono::microseconds>(
               std::chrono::system_clock::now().time_since_epoch())
        .count();
  }
};

/// Message time: the latest utime seen on the bus. Every bookgrasp message
/// starts with `int64_t utime`, which LCM encodes big-endian right after the
/// 8-byte type fingerprint, so it can be read without decoding the type.
class MessageTimeSource {
 public:
  /// Advances to the utime carried by `data` (an encoded bookgrasp message),
  /// if it is later than the current time. Returns false if `data` is too short.
  bool observe(const void* data, size_t size) {
    int64_t t = 0;
    if (!peek_utime(data, size, &t)) return false;
    if (t > now_) now_ = t;
    return true;
  }
  /// Sets the time explicitly (e.g. the start of a replay).
  void set(int64_t utime) { now_ = utime; }
  /// The latest message time, microseconds.
  int64_t now_utime() const { return now_; }

  /// Reads the utime of an encoded bookgrasp message. False if too short.
  static bool peek_utime(const void* data, size_t size, int64_t* utime) {
    if (size < 16) return false;
    const auto* b = static_cast<const uint8_t*>(data) + 8;
    uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v = (v << 8) | b[i];
    *utime = static_cast<int64_t>(v);
    return true;
  }

 private:
  int64_t now_ = 0;
};

}  // namespace bookgrasp
