// One-off migration (2026-12-05, stop 32): plan_request_t got `num_obstacles` and `obstacles` (the books the
// coordinator placed on the lower shelf, for the planner to avoid). The PLAN_REQUEST events of logs/samples/ are
// re-encoded in the new type with no obstacles (what the coordinator sends before the first book is on the lower
// shelf); every other byte of the log is kept. Build by hand, see logs/README.md.
#include "bookgrasp/plan_request_t.hpp"
#include "bookgrasp_old/plan_request_t.hpp"
#include "log_migration.h"

namespace {

bookgrasp::pose_t convert(const bookgrasp_old::pose_t& o) {
  bookgrasp::pose_t m;
  m.utime = o.utime;
  m.frame = o.frame;
  m.child = o.child;
  for (int i = 0; i < 3; ++i) m.position[i] = o.position[i];
  for (int i = 0; i < 4; ++i) m.orientation[i] = o.orientation[i];
  return m;
}

bookgrasp::plan_request_t convert(const bookgrasp_old::plan_request_t& o) {
  bookgrasp::plan_request_t m;
  m.utime = o.utime;
  m.request_id = o.request_id;
  m.planner = o.planner;
  m.goal_type = o.goal_type;
  m.num_joints = o.num_joints;
  m.start_joints = o.start_joints;
  m.goal_joints = o.goal_joints;
  m.goal_pose = convert(o.goal_pose);
  m.position_tolerance_m = o.position_tolerance_m;
  m.orientation_tolerance_rad = o.orientation_tolerance_rad;
  m.keep_orientation = o.keep_orientation;
  m.time_budget_s = o.time_budget_s;
  m.holding_book = o.holding_book;
  for (int i = 0; i < 3; ++i) m.held_book_size_m[i] = o.held_book_size_m[i];
  m.num_then_poses = o.num_then_poses;
  for (const auto& p : o.then_poses) m.then_poses.push_back(convert(p));
  m.num_obstacles = 0;  // no book on the lower shelf in the samples
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  return migrate_log<bookgrasp_old::plan_request_t>(argc, argv, "plan_request_t",
                                                    [](const bookgrasp_old::plan_request_t& o) { return convert(o); });
}
