#include "services/sim_world/sim_librarian.h"

namespace bookgrasp {

SimLibrarianParams SimLibrarianParams::from_config(const Config& root) {
  SimLibrarianParams p;
  p.enabled = root.get<bool>("librarian.enabled");
  p.take_after_s = root.get_double("librarian.take_after_s", 0.0, 3600.0);
  return p;
}

void SimLibrarian::on_task_state(const std::string& state, int64_t utime) {
  const bool waiting = state == "WAIT_BOOK_TAKEN";
  if (waiting && !waiting_) {
    since_ = utime;
    acted_ = false;
  }
  waiting_ = waiting;
}

bool SimLibrarian::due(int64_t utime) {
  if (!p_.enabled || !waiting_ || acted_) return false;
  if (static_cast<double>(utime - since_) < p_.take_after_s * 1e6) return false;
  acted_ = true;
  return true;
}

}  // namespace bookgrasp
