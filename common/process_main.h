#pragma once
/// @file
/// The standalone-process runner: `int main(int argc, char** argv)` of every
/// service is one call to run_service_main().

#include <functional>
#include <memory>
#include <string>

#include "common/component.h"
#include "common/config.h"

namespace bookgrasp {

/// Makes the component from the whole configuration (the `service:` section
/// is already read by the runtime). Throws ConfigError for bad values.
using ComponentFactory = std::function<std::unique_ptr<Component>(const Config& root)>;

/// What a service binary is.
struct ServiceDescription {
  std::string name;            ///< binary / default instance name
  std::string summary;         ///< one line for --help
  std::string default_config;  ///< path relative to the source tree, e.g. "config/services/x.yaml"
  ComponentFactory factory;
};

/// Parses the command line (--help, --config FILE, --lcm-url URL,
/// --check-config), loads and validates the configuration, connects to the
/// bus and dispatches until SIGINT/SIGTERM. Returns the process exit code:
/// 0 after a clean stop, 2 for a bad command line or configuration (the
/// message names the key), 3 if the bus cannot be opened.
int run_service_main(int argc, char** argv, const ServiceDescription& description);

}  // namespace bookgrasp
