#include "services/task_watch/task_run_log.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

namespace bookgrasp {

namespace {

std::string seconds(double s) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f s", s);
  return b;
}

}  // namespace

std::string task_end_name(TaskEnd e) {
  switch (e) {
    case TaskEnd::kRunning:
      return "RUNNING";
    case TaskEnd::kDone:
      return "DONE";
    case TaskEnd::kAborted:
      return "ABORTED";
    case TaskEnd::kEnoughBooks:
      return "ENOUGH_BOOKS";
    case TaskEnd::kWaitingForLibrarian:
      return "WAITING_FOR_LIBRARIAN";
  }
  return "?";
}

double TaskRunLog::elapsed_s() const {
  return first_utime_ < 0 ? 0.0 : static_cast<double>(last_utime_ - first_utime_) * 1e-6;
}

std::vector<std::string> TaskRunLog::on_status(const task_status_t& s) {
  std::vector<std::string> lines;
  if (last_utime_ >= 0 && s.utime < last_utime_ && !warned_old_) {
    // The coordinator's clock is the latest event it saw; events of different sources can step it
    // back a little. Followed anyway (a state change is never dropped); times stay monotonic.
    lines.push_back("note: a TASK_STATUS older than the previous one (message time stepped back)");
    warned_old_ = true;
  }
  if (first_utime_ < 0) {
    first_utime_ = s.utime;
    book_start_utime_ = s.utime;
    books_moved_ = s.books_moved;  // a resumed task starts with books already moved
    failures_count_ = s.failures;
  }
  last_utime_ = std::max(last_utime_, s.utime);
  const std::string t = "[" + seconds(elapsed_s()) + "] ";
  while (books_moved_ < s.books_moved) {
    MovedBook b;
    b.index = books_moved_;
    b.cycle_s = static_cast<double>(last_utime_ - book_start_utime_) * 1e-6;
    b.handed_over = state_ == "WAIT_BOOK_TAKEN";  // the count went up when the librarian said "taken"
    moved_.push_back(b);
    ++books_moved_;
    book_start_utime_ = last_utime_;
    lines.push_back(t + "book " + std::to_string(b.index + 1) +
                    (b.handed_over
                         ? " taken off the holder by the librarian (too tall for, or not placeable on, the lower shelf)"
                         : " moved to the lower shelf") +
                    " (cycle " + seconds(b.cycle_s) + ")");
  }
  if (s.failures > failures_count_) {
    failures_count_ = s.failures;
    failures_.push_back({elapsed_s(), s.current_book, s.state, s.message});
    lines.push_back(t + "failure " + std::to_string(s.failures) + " at book " + std::to_string(s.current_book + 1) +
                    " in " + s.state + ": " + s.message);
  }
  if (s.state != state_) {
    lines.push_back(t + "book " + std::to_string(s.current_book + 1) + " attempt " + std::to_string(s.attempt) + ": " +
                    s.state + (s.message.empty() ? "" : " (" + s.message + ")"));
    state_ = s.state;
  }
  last_message_ = s.message;
  if (s.state == "DONE") {
    end_ = TaskEnd::kDone;
  } else if (s.state == "ABORTED") {
    if (end_ != TaskEnd::kAborted && (failures_.empty() || failures_.back().reason != s.message))
      failures_.push_back({elapsed_s(), s.current_book, s.state, s.message});
    end_ = TaskEnd::kAborted;
  } else if (stop_after_books_ > 0 && static_cast<int>(moved_.size()) >= stop_after_books_) {
    end_ = TaskEnd::kEnoughBooks;
  } else if (stop_at_librarian_ && s.state == "WAIT_BOOK_TAKEN") {
    end_ = TaskEnd::kWaitingForLibrarian;
  }
  return lines;
}

std::string TaskRunLog::summary() const {
  std::ostringstream o;
  o << "task: " << (first_utime_ < 0 ? "no TASK_STATUS received" : task_end_name(end_)) << " after "
    << seconds(elapsed_s()) << " of message time, last state " << (state_.empty() ? "-" : state_) << "\n";
  if (end_ == TaskEnd::kWaitingForLibrarian) o << "waiting for the librarian: " << last_message_ << "\n";
  const auto handed = std::count_if(moved_.begin(), moved_.end(), [](const MovedBook& b) { return b.handed_over; });
  o << "books moved (holder and back to the lower shelf): " << books_moved_ - handed;
  if (handed > 0) o << "; handed to the librarian (too tall for, or not placeable on, the lower shelf): " << handed;
  if (!moved_.empty()) {
    std::vector<double> c;
    for (const auto& b : moved_) c.push_back(b.cycle_s);
    std::sort(c.begin(), c.end());
    o << " (cycle median " << seconds(c[c.size() / 2]) << ", max " << seconds(c.back()) << ")";
  }
  o << "\nfailures: " << failures_.size() << "\n";
  for (const auto& f : failures_)
    o << "  [" << seconds(f.at_s) << "] book " << f.book + 1 << " in " << f.state << ": " << f.reason << "\n";
  return o.str();
}

}  // namespace bookgrasp
