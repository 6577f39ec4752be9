#pragma once
/// @file
/// Deterministic value source for the generated message fillers (tests only).

#include <cstdint>
#include <string>

namespace bookgrasp_test {

/// Produces varied, finite, deterministic values for every LCM primitive type.
class FillRng {
 public:
  /// Starts the sequence at `seed`.
  explicit FillRng(uint64_t seed) : s_(seed * 0x9E3779B97F4A7C15ull + 1) {}
  /// Next raw 64-bit value (splitmix64).
  uint64_t next() {
    uint64_t z = (s_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  /// An array length, 0..3.
  int32_t length() { return static_cast<int32_t>(next() % 4); }
  void value(int8_t& v) { v = static_cast<int8_t>(next()); }
  void value(int16_t& v) { v = static_cast<int16_t>(next()); }
  void value(int32_t& v) { v = static_cast<int32_t>(next()); }
  void value(int64_t& v) { v = static_cast<int64_t>(next()); }
  void value(uint8_t& v) { v = static_cast<uint8_t>(next()); }
  void value(bool& v) { v = (next() & 1) != 0; }
  void value(float& v) { v = static_cast<float>(static_cast<int64_t>(next() % 2000001) - 1000000) * 1e-3f; }
  void value(double& v) { v = static_cast<double>(static_cast<int64_t>(next() % 2000000001) - 1000000000) * 1e-6; }
  void value(std::string& v) {
    const int n = static_cast<int>(next() % 12);
    v.clear();
    for (int i = 0; i < n; ++i) v += static_cast<char>('a' + next() % 26);
  }

 private:
  uint64_t s_;
};

}  // namespace bookgrasp_test
