#include "common/config_overrides.h"

#include <sstream>

#include <yaml-cpp/yaml.h>

#include "common/config.h"

namespace bookgrasp {

std::string apply_config_overrides(const std::string& yaml, const std::vector<std::string>& overrides,
                                   const std::string& source) {
  if (overrides.empty()) return yaml;
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    throw ConfigError(source + ": not valid YAML: " + e.what());
  }
  if (!root.IsMap()) throw ConfigError(source + ": the top level is not a mapping");
  for (const std::string& ov : overrides) {
    const auto eq = ov.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == ov.size())
      throw ConfigError(source + ": override '" + ov + "' is not dotted.key=value");
    const std::string dotted = ov.substr(0, eq);
    std::vector<std::string> parts;
    std::stringstream ss(dotted);
    for (std::string s; std::getline(ss, s, '.');) {
      if (s.empty()) throw ConfigError(source + ": override '" + ov + "' has an empty key part");
      parts.push_back(s);
    }
    YAML::Node value;
    try {
      value = YAML::Load(ov.substr(eq + 1));
    } catch (const YAML::Exception& e) {
      throw ConfigError(source + ": override '" + ov + "': the value is not valid YAML: " + e.what());
    }
    // Walk with fresh handles: assigning to a yaml-cpp node handle rebinds it, it does not copy.
    std::vector<YAML::Node> chain{root};
    for (size_t i = 0; i + 1 < parts.size(); ++i) {
      YAML::Node next = chain.back()[parts[i]];
      if (!next.IsMap())
        throw ConfigError(source + ": override '" + ov + "': no section '" + parts[i] + "' in the file");
      chain.push_back(next);
    }
    if (!chain.back()[parts.back()].IsDefined())
      throw ConfigError(source + ": override of unknown key '" + dotted + "' (typo? only keys of the file can be set)");
    chain.back()[parts.back()] = value;
  }
  YAML::Emitter out;
  out << root;
  return out.c_str();
}

}  // namespace bookgrasp
