// One-off migration (2026-12-04, stop 27): bwh_detector named its implementation "canny_regions" while it ran the
// page_faces method. It now names the method in use, so its outputs in logs/samples/ (BOOK_FEATURES_HAND, and its
// SERVICE_STATUS) are renamed to "page_faces"; every other byte of the log is kept. Build by hand, see logs/README.md.
#include <cstdio>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <vector>

#include "bookgrasp/book_features_hand_t.hpp"
#include "bookgrasp/service_status_t.hpp"

namespace {

/// Re-encodes `m` into `buf` and points `ev` at it.
template <class M>
void reencode(const M& m, std::vector<unsigned char>* buf, lcm::LogEvent* ev) {
  buf->resize(m.getEncodedSize());
  m.encode(buf->data(), 0, buf->size());
  ev->data = buf->data();
  ev->datalen = buf->size();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s IN.lcm OUT.lcm\n", argv[0]);
    return 2;
  }
  lcm::LogFile in(argv[1], "r"), out(argv[2], "w");
  int n = 0, features = 0, status = 0;
  std::vector<unsigned char> buf;
  while (const lcm::LogEvent* e = in.readNextEvent()) {
    lcm::LogEvent ev = *e;
    if (e->channel == "BOOK_FEATURES_HAND") {
      bookgrasp::book_features_hand_t m;
      if (m.decode(e->data, 0, e->datalen) == e->datalen && m.implementation == "canny_regions") {
        m.implementation = "page_faces";
        reencode(m, &buf, &ev);
        ++features;
      }
    } else if (e->channel == "SERVICE_STATUS") {
      bookgrasp::service_status_t m;
      if (m.decode(e->data, 0, e->datalen) == e->datalen && m.service == "bwh_detector" &&
          m.implementation == "canny_regions") {
        m.implementation = "page_faces";
        reencode(m, &buf, &ev);
        ++status;
      }
    }
    out.writeEvent(&ev);
    ++n;
  }
  std::printf("%d events, %d book_features_hand_t and %d service_status_t renamed\n", n, features, status);
  return 0;
}
