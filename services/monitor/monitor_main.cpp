// bookgrasp_monitor: a top-like view of every service's SERVICE_STATUS.
#include <iostream>
#include <sstream>

#include <lcm/lcm-cpp.hpp>

#include "common/lcm_url.h"
#include "common/stop_signal.h"
#include "common/time_source.h"
#include "services/monitor/service_table.h"

namespace {

struct Listener {
  bookgrasp::ServiceTable table;
  bookgrasp::WallTimeSource clock;
  void on_status(const lcm::ReceiveBuffer*, const std::string&, const bookgrasp::service_status_t* m) {
    table.update(*m, clock.now_utime());
  }
};

void help() {
  std::cout << "bookgrasp_monitor - a live table of every service's SERVICE_STATUS\n\n"
               "usage: bookgrasp_monitor [--lcm-url URL] [--channel NAME]\n"
               "                         [--expect a,b,c --timeout S] [--once --seconds S]\n\n"
               "  (no mode)           refresh the table every second until Ctrl-C\n"
               "  --expect a,b,c      wait until each named service has published a status (at most\n"
               "                      --timeout seconds, default 20), print the table; exit 0 if all\n"
               "                      were seen, 1 otherwise (the missing ones are listed)\n"
               "  --once              listen --seconds seconds (default 3), print the table, exit 0\n"
               "  --channel NAME      status channel (default SERVICE_STATUS)\n";
}

}  // namespace

int main(int argc, char** argv) {
  std::string url_arg, channel = "SERVICE_STATUS";
  std::vector<std::string> expect;
  double timeout_s = 20, seconds = 3;
  bool once = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "bookgrasp_monitor: " << a << " needs a value (see --help)\n";
        std::exit(2);
      }
      return argv[++i];
    };
    try {
      if (a == "--help" || a == "-h") {
        help();
        return 0;
      } else if (a == "--lcm-url")
        url_arg = value();
      else if (a == "--channel")
        channel = value();
      else if (a == "--timeout")
        timeout_s = std::stod(value());
      else if (a == "--seconds")
        seconds = std::stod(value());
      else if (a == "--once")
        once = true;
      else if (a == "--expect") {
        std::stringstream ss(value());
        std::string name;
        while (std::getline(ss, name, ','))
          if (!name.empty()) expect.push_back(name);
      } else {
        std::cerr << "bookgrasp_monitor: unknown argument '" << a << "' (see --help)\n";
        return 2;
      }
    } catch (const std::exception&) {
      std::cerr << "bookgrasp_monitor: " << a << " needs a number\n";
      return 2;
    }
  }
  const std::string url = bookgrasp::resolve_lcm_url(url_arg, "");
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::cerr << "bookgrasp_monitor: cannot open " << url << ": run `deploy/bookgrasp setup`\n";
    return 3;
  }
  bookgrasp::install_stop_signals();
  Listener l;
  lcm.subscribe(channel, &Listener::on_status, &l);
  const int64_t start = l.clock.now_utime();
  auto elapsed = [&] { return (l.clock.now_utime() - start) * 1e-6; };

  if (!expect.empty()) {
    while (!bookgrasp::stop_requested() && elapsed() < timeout_s && !l.table.missing(expect).empty())
      lcm.handleTimeout(50);
    // One more second so every service has reported its rates.
    const double until = elapsed() + 1.2;
    while (!bookgrasp::stop_requested() && elapsed() < until) lcm.handleTimeout(50);
    std::cout << l.table.render(l.clock.now_utime());
    const auto missing = l.table.missing(expect);
    if (missing.empty()) {
      std::cout << "all " << expect.size() << " expected services are alive\n";
      return 0;
    }
    std::cout << "NOT alive after " << timeout_s << " s:";
    for (const auto& m : missing) std::cout << " " << m;
    std::cout << "\n";
    return 1;
  }
  if (once) {
    while (!bookgrasp::stop_requested() && elapsed() < seconds) lcm.handleTimeout(50);
    std::cout << l.table.render(l.clock.now_utime());
    return 0;
  }
  int64_t next = 0;
  while (!bookgrasp::stop_requested()) {
    lcm.handleTimeout(50);
    const int64_t now = l.clock.now_utime();
    if (now >= next) {
      std::cout << "\033[2J\033[H"
                << "bookgrasp monitor on " << url << "  (Ctrl-C to quit)\n\n"
                << l.table.render(now) << std::flush;
      next = now + 1000000;
    }
  }
  return 0;
}
