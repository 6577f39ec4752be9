// TaskRunLog: progress lines and the summary from a scripted TASK_STATUS sequence whose books,
// failures and times are known by construction.
#include "services/task_watch/task_run_log.h"

#include <gtest/gtest.h>

namespace bookgrasp {
namespace {

task_status_t st(double t_s, const std::string& state, int moved, int failures = 0, const std::string& msg = "",
                 int attempt = 1) {
  task_status_t s;
  s.utime = 1000000000 + static_cast<int64_t>(t_s * 1e6);
  s.state = state;
  s.books_moved = moved;
  s.current_book = moved;
  s.books_total = moved + 1;
  s.attempt = attempt;
  s.failures = failures;
  s.message = msg;
  return s;
}

bool contains(const std::vector<std::string>& lines, const std::string& part) {
  for (const auto& l : lines)
    if (l.find(part) != std::string::npos) return true;
  return false;
}

TEST(TaskRunLog, BooksMovedWithCycleTimesUntilDone) {
  TaskRunLog log;
  EXPECT_TRUE(contains(log.on_status(st(0, "START", 0)), "book 1 attempt 1: START"));
  EXPECT_TRUE(log.on_status(st(1, "START", 0)).empty());  // nothing changed
  log.on_status(st(50, "WAIT_USER", 0));
  EXPECT_TRUE(contains(log.on_status(st(120, "PARK", 1)), "book 1 moved to the lower shelf (cycle 120.0 s)"));
  log.on_status(st(200, "SERVO_BOOK", 1));
  EXPECT_TRUE(contains(log.on_status(st(220, "PARK", 2)), "cycle 100.0 s"));
  EXPECT_EQ(log.end(), TaskEnd::kRunning);
  log.on_status(st(230, "DONE", 2));
  EXPECT_EQ(log.end(), TaskEnd::kDone);
  ASSERT_EQ(log.moved().size(), 2u);
  EXPECT_DOUBLE_EQ(log.moved()[0].cycle_s, 120.0);
  EXPECT_DOUBLE_EQ(log.moved()[1].cycle_s, 100.0);
  EXPECT_DOUBLE_EQ(log.elapsed_s(), 230.0);
  const std::string s = log.summary();
  EXPECT_NE(s.find("task: DONE after 230.0 s"), std::string::npos) << s;
  EXPECT_NE(s.find("books moved (holder and back to the lower shelf): 2 (cycle median 120.0 s, max 120.0 s)"),
            std::string::npos)
      << s;
  EXPECT_NE(s.find("failures: 0"), std::string::npos) << s;
}

TEST(TaskRunLog, ABookHandedToTheLibrarianIsNotCountedAsOnTheLowerShelf) {
  TaskRunLog log;
  log.on_status(st(0, "START", 0));
  log.on_status(st(50, "WAIT_USER", 0));
  log.on_status(st(60, "WAIT_BOOK_TAKEN", 0, 0, "book 0 is 290.0 mm tall: ... take it off and send \"done\""));
  EXPECT_TRUE(contains(log.on_status(st(90, "PARK", 1)),
                       "book 1 taken off the holder by the librarian (too tall for, or not placeable on, the lower "
                       "shelf) (cycle 90.0 s)"));
  log.on_status(st(150, "WAIT_USER", 1));
  EXPECT_TRUE(contains(log.on_status(st(200, "PARK", 2)), "book 2 moved to the lower shelf (cycle 110.0 s)"));
  log.on_status(st(210, "DONE", 2));
  ASSERT_EQ(log.moved().size(), 2u);
  EXPECT_TRUE(log.moved()[0].handed_over);
  EXPECT_FALSE(log.moved()[1].handed_over);
  const std::string s = log.summary();
  EXPECT_NE(s.find("books moved (holder and back to the lower shelf): 1; handed to the librarian (too tall for, or "
                   "not placeable on, the lower shelf): 1"),
            std::string::npos)
      << s;
}

TEST(TaskRunLog, StopsAtTheLibrarianOnlyWhenAsked) {
  TaskRunLog follow;
  follow.on_status(st(60, "WAIT_BOOK_TAKEN", 0, 0, "book 0 is 290.0 mm tall"));
  EXPECT_EQ(follow.end(), TaskEnd::kRunning);
  TaskRunLog demo(0, true);
  demo.on_status(st(60, "WAIT_BOOK_TAKEN", 0, 0, "book 0 is 290.0 mm tall"));
  EXPECT_EQ(demo.end(), TaskEnd::kWaitingForLibrarian);
  EXPECT_NE(demo.summary().find("waiting for the librarian: book 0 is 290.0 mm tall"), std::string::npos)
      << demo.summary();
}

TEST(TaskRunLog, FailuresAndAbortAreListedOnceWithReasons) {
  TaskRunLog log;
  log.on_status(st(0, "SERVO_STRIPE", 0));
  const auto l = log.on_status(st(10, "MOVE_TO_STRIPE_START", 0, 1, "stripe servo ended TIMEOUT", 2));
  EXPECT_TRUE(contains(l, "failure 1 at book 1 in MOVE_TO_STRIPE_START: stripe servo ended TIMEOUT"));
  log.on_status(st(20, "ABORTED", 0, 2, "3 attempts failed"));
  EXPECT_EQ(log.end(), TaskEnd::kAborted);
  ASSERT_EQ(log.failures().size(), 2u);  // the abort's failure counted once, not again as the abort
  EXPECT_EQ(log.failures()[1].state, "ABORTED");
  EXPECT_EQ(log.failures()[1].reason, "3 attempts failed");
  const std::string s = log.summary();
  EXPECT_NE(s.find("task: ABORTED"), std::string::npos) << s;
  EXPECT_NE(s.find("[20.0 s] book 1 in ABORTED: 3 attempts failed"), std::string::npos) << s;
}

TEST(TaskRunLog, AnAbortWithoutAFailureCountIsStillAFailure) {
  TaskRunLog log;
  log.on_status(st(0, "PARK", 0));
  log.on_status(st(3, "ABORTED", 0, 0, "operator abort"));
  ASSERT_EQ(log.failures().size(), 1u);
  EXPECT_EQ(log.failures()[0].reason, "operator abort");
}

TEST(TaskRunLog, StopsAfterEnoughBooks) {
  TaskRunLog log(1);
  log.on_status(st(0, "PARK", 0));
  log.on_status(st(90, "PARK", 1));
  EXPECT_EQ(log.end(), TaskEnd::kEnoughBooks);
}

TEST(TaskRunLog, AResumedTaskCountsOnlyBooksMovedWhileFollowed) {
  TaskRunLog log;
  log.on_status(st(0, "PARK", 4));  // a restarted coordinator resumed after 4 books
  log.on_status(st(60, "PARK", 5));
  ASSERT_EQ(log.moved().size(), 1u);
  EXPECT_EQ(log.moved()[0].index, 4);
  EXPECT_EQ(log.books_moved(), 5);
}

TEST(TaskRunLog, AnOlderStatusIsFollowedWithOneNoteAndTimesStayMonotonic) {
  TaskRunLog log;
  log.on_status(st(10, "PARK", 0));
  EXPECT_TRUE(contains(log.on_status(st(9.5, "SERVO_BOOK", 0)), "stepped back"));
  EXPECT_EQ(log.state(), "SERVO_BOOK");
  EXPECT_FALSE(contains(log.on_status(st(9.0, "WAIT_DECISION", 0)), "stepped back"));
  EXPECT_DOUBLE_EQ(log.elapsed_s(), 0.0);  // first and latest are both 10 s
  log.on_status(st(9.8, "DONE", 0));
  EXPECT_EQ(log.end(), TaskEnd::kDone);
}

TEST(TaskRunLog, NoStatusSaysSo) {
  TaskRunLog log;
  EXPECT_NE(log.summary().find("no TASK_STATUS received"), std::string::npos);
}

}  // namespace
}  // namespace bookgrasp
