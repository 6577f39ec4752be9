#pragma once
/// @file
/// Selection and conditions over a message's flattened fields (bookgrasp/introspect.hpp), for
/// tools that print or wait for messages on the bus: "state=1", "state!=1", "gripper_contact=1",
/// "message=done". Pure: no LCM.

#include <string>
#include <vector>

#include "bookgrasp/introspect.hpp"

namespace bookgrasp {

/// "PATH=VALUE" or "PATH!=VALUE". Numbers compare as numbers (1 == 1.0), text as text.
struct FieldCondition {
  std::string path;
  bool equal = true;  ///< false for !=
  std::string value;

  /// Parses "PATH=VALUE" / "PATH!=VALUE". Throws std::invalid_argument naming the text.
  static FieldCondition parse(const std::string& text);
  /// True when the message has the field and it satisfies the condition. A missing field
  /// never satisfies it (not even !=): a typo in PATH must not look like success.
  bool holds(const std::vector<FieldValue>& fields) const;
  /// True when the message has the field.
  bool has_field(const std::vector<FieldValue>& fields) const;
};

/// One line "name=value ..." of the fields whose path is in `select` (all fields when empty).
std::string format_fields(const std::vector<FieldValue>& fields, const std::vector<std::string>& select);

}  // namespace bookgrasp
