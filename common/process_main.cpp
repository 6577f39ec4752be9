#include "common/process_main.h"

#include <fstream>
#include <iostream>
#include <sstream>

#include "common/config_overrides.h"
#include "common/lcm_url.h"
#include "common/service_host.h"
#include "common/stop_signal.h"
#include "common/time_source.h"
#include "common/version.h"

namespace bookgrasp {
namespace {

/// Messages dispatched at most in one go before the status duties and the deferred work run.
constexpr int kMaxBurst = 1000;

void print_help(const ServiceDescription& d) {
  std::cout << d.name << " - " << d.summary << "\n\n"
            << "usage: " << d.name
            << " [--config FILE] [--set KEY=VALUE]... [--lcm-url URL] [--check-config] [--help]\n\n"
            << "  --config FILE   YAML configuration (default: " << kSourceDir << "/" << d.default_config << ")\n"
            << "  --set KEY=VALUE override one value of the configuration file (dotted key, YAML value),\n"
            << "                  e.g. --set user.auto_done_after_s=5; only keys of the file can be set\n"
            << "  --lcm-url URL   bus URL; overrides service.lcm_url and $LCM_DEFAULT_URL\n"
            << "                  (default: " << kDefaultLcmUrl << ")\n"
            << "  --check-config  validate the configuration and exit (0 = valid)\n"
            << "  --help          this text\n\n"
            << "Publishes SERVICE_STATUS every service.status_period_s and CONFIG_SNAPSHOT every\n"
            << "service.config_period_s. Stops cleanly on SIGINT or SIGTERM. Version " << kVersion << ".\n";
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

int run_service_main(int argc, char** argv, const ServiceDescription& d) {
  std::string config_path = std::string(kSourceDir) + "/" + d.default_config;
  std::string url_arg;
  bool check_only = false;
  std::vector<std::string> overrides;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](const char* flag) -> std::string {
      if (i + 1 >= argc) {
        std::cerr << d.name << ": " << flag << " needs a value (see --help)\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      print_help(d);
      return 0;
    } else if (a == "--config") {
      config_path = value("--config");
    } else if (a == "--set") {
      overrides.push_back(value("--set"));
    } else if (a == "--lcm-url") {
      url_arg = value("--lcm-url");
    } else if (a == "--check-config") {
      check_only = true;
    } else {
      std::cerr << d.name << ": unknown argument '" << a << "' (see --help)\n";
      return 2;
    }
  }

  std::unique_ptr<ServiceHost> host;
  try {
    std::ifstream probe(config_path);
    if (!probe)
      throw ConfigError("config file '" + config_path + "' cannot be read: check the path given with --config");
    const std::string text = apply_config_overrides(read_file(config_path), overrides, config_path);
    const Config root = Config::from_string(text, config_path);
    ServiceSettings settings = ServiceSettings::from_config(root);
    auto component = d.factory(root);
    root.require_all_read();
    host = std::make_unique<ServiceHost>(std::move(component), settings, text, config_path);
  } catch (const std::exception& e) {
    std::cerr << d.name << ": configuration error: " << e.what() << "\n";
    return 2;
  }
  if (check_only) {
    std::cout << d.name << ": configuration " << config_path << " is valid\n";
    return 0;
  }

  const std::string url = resolve_lcm_url(url_arg, host->settings().lcm_url);
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::cerr << d.name << ": cannot open the LCM bus '" << url
              << "': for udpm, run `deploy/bookgrasp setup` (multicast route on loopback)\n";
    return 3;
  }

  bookgrasp::install_stop_signals();

  WallTimeSource clock;
  host->attach(&lcm, [&clock] { return clock.now_utime(); });
  std::cerr << d.name << ": running '" << host->settings().name << "' (" << host->component().implementation()
            << ") on " << url << "\n";
  while (!bookgrasp::stop_requested()) {
    const int64_t now = clock.now_utime();
    host->poll(now);
    const int64_t wait_us = std::min<int64_t>(host->until_next_due(clock.now_utime()), 100000);
    const int r = lcm.handleTimeout(static_cast<int>(std::max<int64_t>(1, wait_us / 1000)));
    if (r < 0 && !bookgrasp::stop_requested()) {
      host->component().report_error("LCM handle failed");
    } else if (r > 0) {
      // Everything already waiting first (bounded, so the status duties still run), then the deferred work.
      for (int i = 0; i < kMaxBurst && lcm.handleTimeout(0) > 0; ++i) {
      }
      host->component().on_inputs_drained();
    }
  }
  host->publish_stopping(clock.now_utime());
  host->component().detach();  // before `lcm` goes out of scope
  std::cerr << d.name << ": stopped cleanly\n";
  return 0;
}

}  // namespace bookgrasp
