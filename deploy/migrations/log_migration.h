// Shared by the one-off migrations of logs/samples/ (see logs/README.md): every event is copied byte for byte except
// the ones that decode as the old type, which are converted and re-encoded in the new type.
#pragma once
#include <cstdio>
#include <lcm/lcm-cpp.hpp>
#include <vector>

/// Rewrites log argv[1] into argv[2]: events that decode as `Old` become `convert(old)` (a `New`). Prints the counts
/// ("N events, K <type_name> converted").
template <class Old, class Convert>
int migrate_log(int argc, char** argv, const char* type_name, Convert convert) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s IN.lcm OUT.lcm\n", argv[0]);
    return 2;
  }
  lcm::LogFile in(argv[1], "r"), out(argv[2], "w");
  int n = 0, conv = 0;
  std::vector<unsigned char> buf;
  while (const lcm::LogEvent* e = in.readNextEvent()) {
    lcm::LogEvent ev = *e;
    Old o;
    if (o.decode(e->data, 0, e->datalen) == e->datalen) {
      const auto m = convert(o);
      buf.resize(m.getEncodedSize());
      m.encode(buf.data(), 0, buf.size());
      ev.data = buf.data();
      ev.datalen = buf.size();
      ++conv;
    }
    out.writeEvent(&ev);
    ++n;
  }
  std::printf("%d events, %d %s converted\n", n, conv, type_name);
  return 0;
}
