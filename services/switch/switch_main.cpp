// bookgrasp_switch: publish a DETECTOR_SWITCH (detector_switch_t) so consumers follow another
// implementation of a logical detector channel; the switch is then in every recording.
#include <iostream>

#include <lcm/lcm-cpp.hpp>

#include "bookgrasp/detector_switch_t.hpp"
#include "common/lcm_url.h"
#include "common/time_source.h"

int main(int argc, char** argv) {
  std::string url_arg, channel = "DETECTOR_SWITCH", logical, impl, reason = "operator";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "bookgrasp_switch: " << a << " needs a value (see --help)\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      std::cout << "bookgrasp_switch - make consumers follow another implementation of a detector\n\n"
                   "usage: bookgrasp_switch --logical CHANNEL --impl NAME [--reason TEXT] [--channel DETECTOR_SWITCH]\n"
                   "                        [--lcm-url URL]\n"
                   "e.g. bookgrasp_switch --logical BOOK_CORNER_STEREO --impl pcl\n";
      return 0;
    } else if (a == "--logical") logical = value();
    else if (a == "--impl") impl = value();
    else if (a == "--reason") reason = value();
    else if (a == "--channel") channel = value();
    else if (a == "--lcm-url") url_arg = value();
    else {
      std::cerr << "bookgrasp_switch: unknown argument '" << a << "' (see --help)\n";
      return 2;
    }
  }
  if (logical.empty() || impl.empty()) {
    std::cerr << "bookgrasp_switch: --logical and --impl are required (see --help)\n";
    return 2;
  }
  lcm::LCM lcm(bookgrasp::resolve_lcm_url(url_arg, ""));
  if (!lcm.good()) {
    std::cerr << "bookgrasp_switch: cannot open the bus: run `deploy/bookgrasp setup`\n";
    return 3;
  }
  // Message time: the switch is stamped with the latest utime of the stream it switches (the
  // simulation's time in simulation), so it sorts correctly in a log and never moves a
  // message-time clock forward. If that stream is silent for 2 s, wall time is used.
  struct Probe {
    int64_t utime = 0;
    void on(const lcm::ReceiveBuffer* rb, const std::string&) {
      bookgrasp::MessageTimeSource::peek_utime(rb->data, rb->data_size, &utime);
    }
  } probe;
  lcm.subscribe(logical, &Probe::on, &probe);
  const bookgrasp::WallTimeSource wall;
  const int64_t until = wall.now_utime() + 2000000;
  while (probe.utime == 0 && wall.now_utime() < until) lcm.handleTimeout(50);
  bookgrasp::detector_switch_t msg;
  msg.utime = probe.utime != 0 ? probe.utime : wall.now_utime();
  if (probe.utime == 0) std::cerr << "bookgrasp_switch: nothing on " << logical << " for 2 s: stamped with wall time\n";
  msg.logical_channel = logical;
  msg.implementation = impl;
  msg.reason = reason;
  if (lcm.publish(channel, &msg) != 0) {
    std::cerr << "bookgrasp_switch: publish failed\n";
    return 1;
  }
  std::cout << "published " << channel << ": " << logical << " -> " << impl << " (" << reason << ")\n";
  return 0;
}
