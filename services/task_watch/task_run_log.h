#pragma once
/// @file
/// The library task as seen from the bus: follows the coordinator's TASK_STATUS, turns it into
/// progress lines for people and a summary at the end (books moved, failures with their reasons,
/// time per book). Pure: no LCM; message time only.

#include <cstdint>
#include <string>
#include <vector>

#include "bookgrasp/task_status_t.hpp"

namespace bookgrasp {

/// A book that went through the whole cycle.
struct MovedBook {
  int index = 0;         ///< 0-based order in which it was taken
  double cycle_s = 0.0;  ///< message time from the start of its cycle to the report of it moved
  bool handed_over =
      false;  ///< too tall for, or not placeable on, the lower shelf: taken off the holder by the librarian
};

/// A failure the coordinator reported (TASK_STATUS.failures went up, or the task aborted).
struct TaskFailure {
  double at_s = 0.0;   ///< message time since the first status
  int book = 0;        ///< TASK_STATUS.current_book
  std::string state;   ///< where it happened
  std::string reason;  ///< TASK_STATUS.message
};

/// Why following stopped.
enum class TaskEnd { kRunning, kDone, kAborted, kEnoughBooks, kWaitingForLibrarian };

/// Follows TASK_STATUS messages of one task.
class TaskRunLog {
 public:
  /// `stop_after_books` > 0: the run counts as finished once that many books were moved.
  /// `stop_at_librarian`: the run ends when the task waits for the librarian (WAIT_BOOK_TAKEN: a book too tall
  /// for the lower shelf on the holder), e.g. a demo with nobody to take it.
  explicit TaskRunLog(int stop_after_books = 0, bool stop_at_librarian = false)
      : stop_after_books_(stop_after_books), stop_at_librarian_(stop_at_librarian) {}

  /// Feeds one TASK_STATUS. Returns the progress lines to show (state changes, books moved,
  /// failures); empty when nothing changed. A status older than the previous one is still
  /// followed (noted once); elapsed and cycle times use the latest message time seen.
  std::vector<std::string> on_status(const task_status_t& s);

  /// kRunning until DONE, ABORTED, enough books moved or (stop_at_librarian) WAIT_BOOK_TAKEN.
  TaskEnd end() const { return end_; }
  /// Books moved so far (the coordinator's count).
  int books_moved() const { return books_moved_; }
  /// Every book moved, in order, with its cycle time.
  const std::vector<MovedBook>& moved() const { return moved_; }
  /// Every failure seen.
  const std::vector<TaskFailure>& failures() const { return failures_; }
  /// Message time covered, seconds (first to last status).
  double elapsed_s() const;
  /// The last state seen ("" before any status).
  const std::string& state() const { return state_; }
  /// Several lines: outcome, books moved, median / max cycle time, the failures with reasons.
  std::string summary() const;

 private:
  int stop_after_books_;
  bool stop_at_librarian_ = false;
  TaskEnd end_ = TaskEnd::kRunning;
  int64_t first_utime_ = -1, last_utime_ = -1, book_start_utime_ = -1;
  std::string state_;
  std::string last_message_;
  int books_moved_ = 0, failures_count_ = 0;
  bool warned_old_ = false;
  std::vector<MovedBook> moved_;
  std::vector<TaskFailure> failures_;
};

/// Upper-case name of an end ("RUNNING", "DONE", "ABORTED", "ENOUGH_BOOKS", "WAITING_FOR_LIBRARIAN").
std::string task_end_name(TaskEnd e);

}  // namespace bookgrasp
