#pragma once
/// @file
/// Components by service name, so offline tools (replay, evaluation) can build
/// any service from its configuration exactly as its process does.

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "common/component.h"
#include "common/config.h"
#include "common/process_main.h"

namespace bookgrasp {

/// Maps service names to their ServiceDescription (factory and default config).
class ComponentRegistry {
 public:
  /// Registers `description` under description.name (replaces an earlier one).
  void add(ServiceDescription description);
  /// Names registered, sorted.
  std::vector<std::string> names() const;
  /// The description of `name`; throws std::runtime_error listing the known names if absent.
  const ServiceDescription& get(const std::string& name) const;
  /// Builds `name` from the YAML file `config_path` ("" = its default config
  /// under `source_dir`), validating it like the process does (unknown keys fail).
  std::unique_ptr<Component> make(const std::string& name, const std::string& config_path,
                                  const std::string& source_dir) const;

 private:
  std::map<std::string, ServiceDescription> entries_;
};

/// Every production service of the project (services/replay/registered_services.cpp).
ComponentRegistry project_services();

}  // namespace bookgrasp
