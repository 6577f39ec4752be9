// bookgrasp_images: write the pictures of an image channel (camera images, detector debug overlays)
// to PNG, from a recorded log or live from the bus.
#include <sys/stat.h>

#include <csignal>
#include <cstdio>
#include <iostream>

#include <lcm/lcm-cpp.hpp>

#include "common/image_conversion.h"
#include "common/lcm_url.h"
#include "common/time_source.h"
#include "services/image_view/image_message.h"
#include "common/lcm_log.h"

namespace {

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }

struct Live {
  std::string out_dir;
  int written = 0;
  int64_t last_write = 0;
  bookgrasp::WallTimeSource clock;
  void on(const lcm::ReceiveBuffer* rb, const std::string& channel) {
    const int64_t now = clock.now_utime();
    if (now - last_write < 1000000) return;  // the latest picture, once a second
    auto p = bookgrasp::decode_picture(rb->data, static_cast<int>(rb->data_size));
    if (!p) return;
    bookgrasp::write_png(out_dir + "/" + channel + "_latest.png", p->rgb);
    last_write = now;
    ++written;
    std::cerr << "\r" << channel << ": " << written << " updates of " << out_dir << "/" << channel << "_latest.png"
              << std::flush;
  }
};

}  // namespace

int main(int argc, char** argv) {
  std::string log_path, channel, out_dir = "out/images", url_arg;
  int every = 1;
  double seconds = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "bookgrasp_images: " << a << " needs a value (see --help)\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      std::cout << "bookgrasp_images - write the pictures of an image channel to PNG\n\n"
                   "usage: bookgrasp_images --channel CH [--log FILE [--every N]] [--out DIR] [--seconds S]\n\n"
                   "  --log FILE   from a recording: one PNG per message (every N-th), named CH_<utime>.png\n"
                   "  (no --log)   live from the bus: DIR/CH_latest.png refreshed every second, until Ctrl-C\n"
                   "               or --seconds S\n"
                   "Reads image_t (camera images, detector debug overlays; depth and labels colour-mapped),\n"
                   "stereo_frame_t (left | right) and hand_image_t.\n";
      return 0;
    } else if (a == "--log") log_path = value();
    else if (a == "--channel") channel = value();
    else if (a == "--out") out_dir = value();
    else if (a == "--lcm-url") url_arg = value();
    else if (a == "--every") every = std::max(1, std::atoi(value().c_str()));
    else if (a == "--seconds") seconds = std::atof(value().c_str());
    else {
      std::cerr << "bookgrasp_images: unknown argument '" << a << "' (see --help)\n";
      return 2;
    }
  }
  if (channel.empty()) {
    std::cerr << "bookgrasp_images: --channel is required (see --help)\n";
    return 2;
  }
  ::mkdir(out_dir.c_str(), 0755);
  try {
    if (!log_path.empty()) {
      int seen = 0, written = 0, skipped = 0;
      for (const auto& m : bookgrasp::read_lcm_log(log_path)) {
        if (m.channel != channel || seen++ % every != 0) continue;
        auto p = bookgrasp::decode_picture(m.data.data(), static_cast<int>(m.data.size()));
        if (!p) {
          ++skipped;
          continue;
        }
        bookgrasp::write_png(out_dir + "/" + channel + "_" + std::to_string(p->utime) + ".png", p->rgb);
        ++written;
      }
      std::cout << "wrote " << written << " PNGs of " << channel << " into " << out_dir;
      if (skipped) std::cout << " (" << skipped << " messages are not images)";
      std::cout << "\n";
      return written > 0 ? 0 : 1;
    }
    lcm::LCM lcm(bookgrasp::resolve_lcm_url(url_arg, ""));
    if (!lcm.good()) {
      std::cerr << "bookgrasp_images: cannot open the bus: run `deploy/bookgrasp setup`\n";
      return 3;
    }
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    Live live;
    live.out_dir = out_dir;
    lcm.subscribe(channel, &Live::on, &live);
    const bookgrasp::WallTimeSource wall;
    const int64_t end = seconds > 0 ? wall.now_utime() + static_cast<int64_t>(seconds * 1e6) : INT64_MAX;
    while (!g_stop && wall.now_utime() < end) lcm.handleTimeout(100);
    std::cerr << "\n";
    return live.written > 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "bookgrasp_images: " << e.what() << "\n";
    return 2;
  }
}
