// One-off migration (2026-12-04): rewrites the SERVO_STATUS events of an LCM log recorded before servo_status_t got
// front_width_m (set to 0) so that the replay tests can still read logs/samples/. Build by hand, see logs/README.md.
#include "bookgrasp_old/servo_status_t.hpp"
#include "servo_status_migration.h"

int main(int argc, char** argv) {
  return migrate_servo_status<bookgrasp_old::servo_status_t>(
      argc, argv, [](const bookgrasp_old::servo_status_t&, bookgrasp::servo_status_t* m) { m->front_width_m = 0.0; });
}
