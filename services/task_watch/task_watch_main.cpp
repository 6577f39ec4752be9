// bookgrasp_task: follows the library task on the bus (TASK_STATUS), prints its progress and, when it
// ends, a summary: books moved, failures with reasons, cycle times, and in simulation where the books really are
// (SIM_GROUND_TRUTH). Used by `deploy/bookgrasp demo`.
#include <iostream>
#include <optional>

#include <lcm/lcm-cpp.hpp>

#include "common/lcm_url.h"
#include "common/stop_signal.h"
#include "common/time_source.h"
#include "services/task_watch/task_run_log.h"
#include "services/task_watch/truth_count.h"

namespace {

void help() {
  std::cout << "bookgrasp_task - follow the library task (TASK_STATUS) and summarise it\n\n"
               "usage: bookgrasp_task [--lcm-url URL] [--channel TASK_STATUS] [--truth-channel SIM_GROUND_TRUTH]\n"
               "                      [--books K] [--timeout S]\n\n"
               "  --truth-channel C  the simulation's ground truth: at the end, where the books really are\n"
               "                (nothing is printed without it, e.g. on the robot; '' = do not listen)\n"
               "  --books K     stop following once K books went through the whole cycle (default 0: until\n"
               "                the coordinator reports DONE or ABORTED)\n"
               "  --timeout S   give up after S seconds of wall time (default 0: never)\n"
               "  --stop-at-librarian  stop when the task waits for the librarian to take a book too tall for\n"
               "                the lower shelf off the holder (WAIT_BOOK_TAKEN): a demo with nobody to do it\n"
               "Exit code: 0 DONE or K books moved, 1 ABORTED, 4 timeout or Ctrl-C while running,\n"
               "5 no TASK_STATUS at all, 6 waiting for the librarian (--stop-at-librarian), 2 bad command\n"
               "line, 3 no bus.\n";
}

struct Listener {
  bookgrasp::TaskRunLog log;
  bool any = false;
  Listener(int books, bool stop_at_librarian) : log(books, stop_at_librarian) {}
  std::optional<bookgrasp::ground_truth_t> truth;  ///< the latest SIM_GROUND_TRUTH
  int64_t first_status_utime = 0;
  void on(const lcm::ReceiveBuffer*, const std::string&, const bookgrasp::task_status_t* m) {
    if (!any) first_status_utime = m->utime;
    any = true;
    for (const auto& line : log.on_status(*m)) std::cout << line << "\n" << std::flush;
  }
  void on_truth(const lcm::ReceiveBuffer*, const std::string&, const bookgrasp::ground_truth_t* m) { truth = *m; }
};

}  // namespace

int main(int argc, char** argv) {
  std::string url_arg, channel = "TASK_STATUS", truth_channel = "SIM_GROUND_TRUTH";
  int books = 0;
  double timeout_s = 0;
  bool stop_at_librarian = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "bookgrasp_task: " << a << " needs a value (see --help)\n";
        std::exit(2);
      }
      return argv[++i];
    };
    try {
      if (a == "--help" || a == "-h") {
        help();
        return 0;
      } else if (a == "--lcm-url") {
        url_arg = value();
      } else if (a == "--channel") {
        channel = value();
      } else if (a == "--truth-channel") {
        truth_channel = value();
      } else if (a == "--books") {
        books = std::stoi(value());
      } else if (a == "--stop-at-librarian") {
        stop_at_librarian = true;
      } else if (a == "--timeout") {
        timeout_s = std::stod(value());
      } else {
        std::cerr << "bookgrasp_task: unknown argument '" << a << "' (see --help)\n";
        return 2;
      }
    } catch (const std::exception&) {
      std::cerr << "bookgrasp_task: " << a << " needs a number (see --help)\n";
      return 2;
    }
  }
  if (books < 0 || timeout_s < 0) {
    std::cerr << "bookgrasp_task: --books and --timeout must not be negative\n";
    return 2;
  }
  lcm::LCM lcm(bookgrasp::resolve_lcm_url(url_arg, ""));
  if (!lcm.good()) {
    std::cerr << "bookgrasp_task: cannot open the bus: run `deploy/bookgrasp setup`\n";
    return 3;
  }
  bookgrasp::install_stop_signals();

  Listener listener(books, stop_at_librarian);
  lcm.subscribe(channel, &Listener::on, &listener);
  if (!truth_channel.empty()) lcm.subscribe(truth_channel, &Listener::on_truth, &listener);
  // Wall time only bounds how long a person waits; the task's own times are message time.
  const bookgrasp::WallTimeSource wall;
  const int64_t until = timeout_s > 0 ? wall.now_utime() + static_cast<int64_t>(timeout_s * 1e6) : INT64_MAX;
  while (!bookgrasp::stop_requested() && listener.log.end() == bookgrasp::TaskEnd::kRunning && wall.now_utime() < until)
    lcm.handleTimeout(100);

  std::cout << "\n" << listener.log.summary();
  // The coordinator counts what it did; in simulation the truth says where the books ended (fallen, carried along).
  if (listener.truth)
    std::cout << bookgrasp::truth_summary(
                     bookgrasp::count_books_by_place(*listener.truth),
                     static_cast<double>(listener.truth->utime - listener.first_status_utime) * 1e-6)
              << "\n";
  if (!listener.any) {
    std::cout << "no TASK_STATUS on " << channel << ": is the coordinator running?\n";
    return 5;
  }
  switch (listener.log.end()) {
    case bookgrasp::TaskEnd::kDone:
    case bookgrasp::TaskEnd::kEnoughBooks:
      return 0;
    case bookgrasp::TaskEnd::kAborted:
      return 1;
    case bookgrasp::TaskEnd::kWaitingForLibrarian:
      return 6;
    case bookgrasp::TaskEnd::kRunning:
      break;
  }
  std::cout << (bookgrasp::stop_requested() ? "interrupted" : "timed out") << " while the task was running\n";
  return 4;
}
