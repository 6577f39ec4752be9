// bookgrasp_replay: re-run components offline on a recorded log and diff their outputs.
#include <sys/stat.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>

#include "common/version.h"
#include "services/replay/component_registry.h"
#include "services/replay/output_diff.h"
#include "services/replay/replay_runner.h"

namespace {

std::set<std::string> split(const std::string& s) {
  std::set<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.insert(item);
  return out;
}

void help(const bookgrasp::ComponentRegistry& reg) {
  std::cout << "bookgrasp_replay - re-run components offline on a recorded LCM log and diff their outputs\n\n"
               "usage: bookgrasp_replay --log FILE --service NAME[,NAME...] [--config NAME=FILE]...\n"
               "                        [--feed CH,...] [--ignore FIELD,...] [--out DIR] [--expect-identical]\n\n"
               "  --service     one service, or a chain (cameras' output through several components);\n"
               "                known: ";
  for (const auto& n : reg.names()) std::cout << n << " ";
  std::cout << "\n  --config      a configuration for NAME (default: its config/services/ file)\n"
               "  --feed        channels taken from the log (default: what the services subscribe to,\n"
               "                minus what the chain itself publishes)\n"
               "  --ignore      fields not compared, e.g. timing fields (processing_ms,total_ms)\n"
               "  --out DIR     writes DIR/replayed.lcm, DIR/report.md, DIR/metrics.json (default out/replay)\n"
               "  --expect-identical  exit 1 if any output differs\n"
               "Driven by the messages' own utime, as fast as possible; the same log and config give the\n"
               "same outputs bit for bit.\n";
}

}  // namespace

int main(int argc, char** argv) {
  const bookgrasp::ComponentRegistry reg = bookgrasp::project_services();
  std::string log_path, out_dir = "out/replay";
  std::vector<std::string> services;
  std::map<std::string, std::string> configs;
  std::set<std::string> feed, ignore;
  bool expect_identical = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "bookgrasp_replay: " << a << " needs a value (see --help)\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      help(reg);
      return 0;
    } else if (a == "--log") log_path = value();
    else if (a == "--service") {
      std::stringstream ss(value());
      std::string s;
      while (std::getline(ss, s, ',')) services.push_back(s);
    } else if (a == "--config") {
      const std::string v = value();
      const auto eq = v.find('=');
      if (eq == std::string::npos) {
        std::cerr << "bookgrasp_replay: --config wants NAME=FILE, got '" << v << "'\n";
        return 2;
      }
      configs[v.substr(0, eq)] = v.substr(eq + 1);
    } else if (a == "--feed") feed = split(value());
    else if (a == "--ignore") ignore = split(value());
    else if (a == "--out") out_dir = value();
    else if (a == "--expect-identical") expect_identical = true;
    else {
      std::cerr << "bookgrasp_replay: unknown argument '" << a << "' (see --help)\n";
      return 2;
    }
  }
  if (log_path.empty() || services.empty()) {
    std::cerr << "bookgrasp_replay: --log and --service are required (see --help)\n";
    return 2;
  }
  try {
    const auto log = bookgrasp::read_lcm_log(log_path);
    std::vector<std::unique_ptr<bookgrasp::Component>> components;
    for (const auto& s : services) {
      const auto it = configs.find(s);
      components.push_back(reg.make(s, it == configs.end() ? "" : it->second, bookgrasp::kSourceDir));
    }
    std::cerr << "replaying " << log.size() << " messages of " << log_path << " through";
    for (const auto& s : services) std::cerr << " " << s;
    std::cerr << "\n";
    const auto run = bookgrasp::replay_log(log, std::move(components), feed);
    const auto report = bookgrasp::diff_outputs(log, run.outputs, {}, ignore, run.fed_utimes);
    ::mkdir(out_dir.c_str(), 0755);
    bookgrasp::write_lcm_log(out_dir + "/replayed.lcm", run.outputs);
    const double speed = run.wall_s > 0 ? run.log_duration_s / run.wall_s : 0.0;
    char timing[256];
    std::snprintf(timing, sizeof(timing),
                  "fed %lld messages (%.2f s of message time) in %.3f s wall: %.1fx real time\n",
                  static_cast<long long>(run.messages_fed), run.log_duration_s, run.wall_s, speed);
    std::ofstream(out_dir + "/report.md") << "# Replay of " << log_path << "\n\n" << timing << "\n"
                                          << report.markdown();
    std::string json = report.json();
    json.insert(1, "\"messages_fed\": " + std::to_string(run.messages_fed) + ", \"log_duration_s\": " +
                       std::to_string(run.log_duration_s) + ", \"wall_s\": " + std::to_string(run.wall_s) +
                       ", \"speed_vs_real_time\": " + std::to_string(speed) + ", ");
    std::ofstream(out_dir + "/metrics.json") << json;
    std::cout << timing << report.markdown() << "wrote " << out_dir << "/{replayed.lcm,report.md,metrics.json}\n";
    return expect_identical && !report.identical() ? 1 : 0;
  } catch (const std::exception& e) {
    std::cerr << "bookgrasp_replay: " << e.what() << "\n";
    return 2;
  }
}
