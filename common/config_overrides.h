#pragma once
/// @file
/// Command-line overrides of configuration values ("dotted.key=value"), applied to a YAML
/// document before it is validated, so an override is checked exactly like the file's own value.

#include <string>
#include <vector>

namespace bookgrasp {

/// Returns `yaml` (the text of a configuration file named `source`) with every override of
/// `overrides` applied. An override is "dotted.key=value"; the value is parsed as YAML
/// ("30", "true", "[1, 2]", "text"). Only keys that exist in the document can be overridden,
/// so a typo is an error, not a silently added key. Throws ConfigError naming `source` and
/// the override when it is malformed, a section is missing or the key is unknown.
std::string apply_config_overrides(const std::string& yaml, const std::vector<std::string>& overrides,
                                   const std::string& source);

}  // namespace bookgrasp
