// One-off migration (2026-12-04, stop 26): rewrites the SERVO_STATUS events of an LCM log recorded before
// servo_status_t got neighbour_offset_m and neighbour_width_m (set to 0, "not seen") so that the replay tests can still
// read logs/samples/. Build by hand, see logs/README.md.
#include <cstdio>
#include <cstring>
#include <lcm/lcm-cpp.hpp>
#include <vector>
#include "bookgrasp/servo_status_t.hpp"
#include "bookgrasp_old/servo_status_t.hpp"
int main(int argc, char** argv) {
  lcm::LogFile in(argv[1], "r"), out(argv[2], "w");
  int n = 0, conv = 0;
  while (const lcm::LogEvent* e = in.readNextEvent()) {
    lcm::LogEvent ev = *e;
    std::vector<unsigned char> buf;
    bookgrasp_old::servo_status_t o;
    if (o.decode(e->data, 0, e->datalen) == e->datalen) {
      bookgrasp::servo_status_t m;
      m.utime = o.utime;
      m.request_id = o.request_id;
      m.mode = o.mode;
      m.state = o.state;
      m.iterations = o.iterations;
      for (int i = 0; i < 2; ++i) m.error_px[i] = o.error_px[i];
      m.slope_error_rad = o.slope_error_rad;
      m.converged_pose.utime = o.converged_pose.utime;
      m.converged_pose.frame = o.converged_pose.frame;
      m.converged_pose.child = o.converged_pose.child;
      for (int i = 0; i < 3; ++i) m.converged_pose.position[i] = o.converged_pose.position[i];
      for (int i = 0; i < 4; ++i) m.converged_pose.orientation[i] = o.converged_pose.orientation[i];
      m.corner_triangulated = o.corner_triangulated;
      for (int i = 0; i < 3; ++i) m.corner_base[i] = o.corner_base[i];
      m.corner_baseline_m = o.corner_baseline_m;
      m.corner_rms_px = o.corner_rms_px;
      m.front_width_m = o.front_width_m;
      m.neighbour_offset_m = 0.0;
      m.neighbour_width_m = 0.0;
      m.message = o.message;
      buf.resize(m.getEncodedSize());
      m.encode(buf.data(), 0, buf.size());
      ev.data = buf.data();
      ev.datalen = buf.size();
      ++conv;
    }
    out.writeEvent(&ev);
    ++n;
  }
  std::printf("%d events, %d servo_status_t converted\n", n, conv);
}
