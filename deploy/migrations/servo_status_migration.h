// Shared by the one-off servo_status_t migrations of logs/samples/ (see logs/README.md): every event is copied byte
// for byte except the SERVO_STATUS ones, which are re-encoded in the new type.
#pragma once
#include "bookgrasp/servo_status_t.hpp"
#include "log_migration.h"

/// Copies the fields every servo_status_t version has had since the triangulated corner (stop 20).
template <class Old>
void copy_common_fields(const Old& o, bookgrasp::servo_status_t* m) {
  m->utime = o.utime;
  m->request_id = o.request_id;
  m->mode = o.mode;
  m->state = o.state;
  m->iterations = o.iterations;
  for (int i = 0; i < 2; ++i) m->error_px[i] = o.error_px[i];
  m->slope_error_rad = o.slope_error_rad;
  m->converged_pose.utime = o.converged_pose.utime;
  m->converged_pose.frame = o.converged_pose.frame;
  m->converged_pose.child = o.converged_pose.child;
  for (int i = 0; i < 3; ++i) m->converged_pose.position[i] = o.converged_pose.position[i];
  for (int i = 0; i < 4; ++i) m->converged_pose.orientation[i] = o.converged_pose.orientation[i];
  m->corner_triangulated = o.corner_triangulated;
  for (int i = 0; i < 3; ++i) m->corner_base[i] = o.corner_base[i];
  m->corner_baseline_m = o.corner_baseline_m;
  m->corner_rms_px = o.corner_rms_px;
  m->message = o.message;
}

/// Rewrites log argv[1] into argv[2]: events that decode as `Old` become servo_status_t with the common fields
/// copied and `set_new_fields(old, &new)` applied. Prints the counts.
template <class Old, class SetNewFields>
int migrate_servo_status(int argc, char** argv, SetNewFields set_new_fields) {
  return migrate_log<Old>(argc, argv, "servo_status_t", [&](const Old& o) {
    bookgrasp::servo_status_t m{};
    copy_common_fields(o, &m);
    set_new_fields(o, &m);
    return m;
  });
}
