#pragma once
/// @file
/// printf-style formatting into a std::string, for messages that carry numbers.

#include <cstdio>
#include <string>

namespace bookgrasp {

/// `format` filled with `args` as std::snprintf does (the arguments' types must match the conversions).
template <typename... Args>
std::string format_text(const char* format, Args... args) {
  const int n = std::snprintf(nullptr, 0, format, args...);
  if (n <= 0) return {};
  std::string s(static_cast<size_t>(n), '\0');
  std::snprintf(s.data(), s.size() + 1, format, args...);
  return s;
}

}  // namespace bookgrasp
