// One-off migration (2026-12-04, stop 26): rewrites the SERVO_STATUS events of an LCM log recorded before
// servo_status_t got neighbour_offset_m and neighbour_width_m (set to 0, "not seen") so that the replay tests can
// still read logs/samples/. Build by hand, see logs/README.md.
#include "bookgrasp_old/servo_status_t.hpp"
#include "servo_status_migration.h"

int main(int argc, char** argv) {
  return migrate_servo_status<bookgrasp_old::servo_status_t>(
      argc, argv, [](const bookgrasp_old::servo_status_t& o, bookgrasp::servo_status_t* m) {
        m->front_width_m = o.front_width_m;
        m->neighbour_offset_m = 0.0;
        m->neighbour_width_m = 0.0;
      });
}
