#pragma once
/// @file
/// The simulated librarian (not in the paper; simulation only): a book the coordinator leaves on the holder
/// because it is too tall for the lower shelf, or because the lower shelf could not take it (TASK_STATUS state
/// WAIT_BOOK_TAKEN), is taken off it by a person.
/// This core decides when, in simulation time; sim_world's node moves the book out of the scene and publishes
/// the person's USER_EVENT "taken". No LCM, no MuJoCo.

#include <cstdint>
#include <string>

#include "common/config.h"

namespace bookgrasp {

/// librarian.* of config/services/sim_world.yaml.
struct SimLibrarianParams {
  bool enabled = true;        ///< false: nobody comes (the task waits in WAIT_BOOK_TAKEN)
  double take_after_s = 2.0;  ///< simulation seconds from WAIT_BOOK_TAKEN to the book taken and "taken" sent
  /// Reads librarian.enabled and librarian.take_after_s of `root`. Throws ConfigError naming a bad key.
  static SimLibrarianParams from_config(const Config& root);
};

/// When the librarian acts: once per visit of the task to WAIT_BOOK_TAKEN, take_after_s after it began.
class SimLibrarian {
 public:
  /// The librarian with `params`.
  explicit SimLibrarian(const SimLibrarianParams& params) : p_(params) {}

  /// The task's state (TASK_STATUS.state) seen at simulation time `utime`: a new visit to WAIT_BOOK_TAKEN
  /// starts the wait.
  void on_task_state(const std::string& state, int64_t utime);
  /// True exactly once per visit, at the first `utime` at least take_after_s after it began.
  bool due(int64_t utime);

 private:
  SimLibrarianParams p_;
  bool waiting_ = false;  ///< the task is in WAIT_BOOK_TAKEN
  bool acted_ = false;    ///< ... and the librarian has acted in this visit
  int64_t since_ = 0;     ///< when the visit began (simulation time)
};

}  // namespace bookgrasp
