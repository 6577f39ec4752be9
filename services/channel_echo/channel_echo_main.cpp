// bookgrasp_echo: prints the messages of a channel, decoded (any bookgrasp type), or waits for one
// that satisfies a condition. For people at a terminal and for scripted tests of the running system.
#include <iostream>
#include <sstream>

#include <lcm/lcm-cpp.hpp>

#include "bookgrasp/introspect.hpp"
#include "common/lcm_url.h"
#include "common/stop_signal.h"
#include "common/time_source.h"
#include "services/channel_echo/field_condition.h"

namespace {

void help() {
  std::cout << "bookgrasp_echo - print the decoded messages of a channel, or wait for one\n\n"
               "usage: bookgrasp_echo --channel NAME [--field PATH]... [--until COND] [--count N]\n"
               "                      [--timeout S] [--quiet] [--lcm-url URL]\n\n"
               "  --channel NAME  channel (an LCM regular expression, e.g. 'BOOK_.*')\n"
               "  --field PATH    print only these fields (repeatable), e.g. --field state --field message\n"
               "  --until COND    stop at the first message with COND: PATH=VALUE or PATH!=VALUE\n"
               "                  (e.g. --until state=1); exit 0 then\n"
               "  --count N       stop after N messages (exit 0)\n"
               "  --timeout S     give up after S seconds of wall time (exit 1)\n"
               "  --quiet         print only the message that satisfied --until\n"
               "Exit code: 0 done, 1 timeout or Ctrl-C, 2 bad command line, 3 no bus.\n";
}

struct Echo {
  std::vector<std::string> fields;
  bool has_until = false;
  bookgrasp::FieldCondition until;
  bool quiet = false;
  int count = 0;
  int seen = 0;
  bool done = false;
  bool warned_missing = false;
  void on(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    std::vector<bookgrasp::FieldValue> values;
    const std::string type = bookgrasp::flatten_encoded(rb->data, static_cast<int>(rb->data_size), &values);
    if (type.empty()) {
      std::cout << channel << ": " << rb->data_size << " bytes of no bookgrasp type (or undecodable)\n";
      return;
    }
    ++seen;
    const bool hit = has_until && until.holds(values);
    if (has_until && !warned_missing && !until.has_field(values)) {
      std::cerr << "bookgrasp_echo: " << type << " on " << channel << " has no field '" << until.path
                << "': --until can never hold\n";
      warned_missing = true;
    }
    if (!quiet || hit) std::cout << channel << " " << type << " " << bookgrasp::format_fields(values, fields) << "\n";
    std::cout.flush();
    if (hit || (count > 0 && seen >= count)) done = true;
  }
};

}  // namespace

int main(int argc, char** argv) {
  std::string url_arg, channel;
  double timeout_s = 0;
  Echo echo;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "bookgrasp_echo: " << a << " needs a value (see --help)\n";
        std::exit(2);
      }
      return argv[++i];
    };
    try {
      if (a == "--help" || a == "-h") {
        help();
        return 0;
      } else if (a == "--channel") {
        channel = value();
      } else if (a == "--field") {
        echo.fields.push_back(value());
      } else if (a == "--until") {
        echo.until = bookgrasp::FieldCondition::parse(value());
        echo.has_until = true;
      } else if (a == "--count") {
        echo.count = std::stoi(value());
      } else if (a == "--timeout") {
        timeout_s = std::stod(value());
      } else if (a == "--quiet") {
        echo.quiet = true;
      } else if (a == "--lcm-url") {
        url_arg = value();
      } else {
        std::cerr << "bookgrasp_echo: unknown argument '" << a << "' (see --help)\n";
        return 2;
      }
    } catch (const std::invalid_argument& e) {
      std::cerr << "bookgrasp_echo: " << a << ": " << e.what() << "\n";
      return 2;
    }
  }
  if (channel.empty() || echo.count < 0 || timeout_s < 0) {
    std::cerr << "bookgrasp_echo: --channel is required; --count and --timeout must not be negative\n";
    return 2;
  }
  lcm::LCM lcm(bookgrasp::resolve_lcm_url(url_arg, ""));
  if (!lcm.good()) {
    std::cerr << "bookgrasp_echo: cannot open the bus: run `deploy/bookgrasp setup`\n";
    return 3;
  }
  bookgrasp::install_stop_signals();
  lcm.subscribe(channel, &Echo::on, &echo);
  const bookgrasp::WallTimeSource wall;
  const int64_t until = timeout_s > 0 ? wall.now_utime() + static_cast<int64_t>(timeout_s * 1e6) : INT64_MAX;
  while (!bookgrasp::stop_requested() && !echo.done && wall.now_utime() < until) lcm.handleTimeout(50);
  if (echo.done) return 0;
  std::cerr << "bookgrasp_echo: " << (bookgrasp::stop_requested() ? "interrupted" : "timed out") << " after "
            << echo.seen << " message(s) on " << channel << (echo.has_until ? " without the --until condition" : "")
            << "\n";
  return 1;
}
