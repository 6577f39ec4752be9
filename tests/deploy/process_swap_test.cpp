// `deploy/bookgrasp swap` on a running process system under supervisord: one implementation is
// replaced by another without touching anything else; the output continues (issue 8: within 1 s); the switch is
// on the bus (DETECTOR_SWITCH) and in SERVICE_STATUS. The swap makes before it breaks (the old implementation
// is stopped only after the new one reports and the switch is sent), so no input goes unanswered while the new
// process starts: on a loaded machine a break-before-make swap left a 2.4 s gap here (2026-12-05).
// What is asserted is that every input between the first and the last answered one has an answer (a
// break-before-make swap leaves the inputs of the new process's start-up unanswered). The longest silence
// between answers is printed and recorded, not asserted: it also measures how long this test process waits for a
// core (11 s once, behind a long evaluation at a higher priority, with every input answered; 2026-12-07), and tests
// here do not fail on timing.
#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "bookgrasp/detector_switch_t.hpp"
#include "bookgrasp/service_status_t.hpp"
#include "bookgrasp/task_status_t.hpp"

namespace {

using Clock = std::chrono::steady_clock;

struct Listener {
  std::vector<std::pair<Clock::time_point, std::string>> out;  // arrival, implementation
  std::set<int64_t> answered;                                  // utime (input number) of each answer
  std::vector<bookgrasp::detector_switch_t> switches;
  std::set<std::string> status_impls;
  void on_out(const lcm::ReceiveBuffer*, const std::string&, const bookgrasp::task_status_t* m) {
    out.emplace_back(Clock::now(), m->message);
    answered.insert(m->utime);
  }
  void on_switch(const lcm::ReceiveBuffer*, const std::string&, const bookgrasp::detector_switch_t* m) {
    switches.push_back(*m);
  }
  void on_status(const lcm::ReceiveBuffer*, const std::string&, const bookgrasp::service_status_t* m) {
    status_impls.insert(m->service + ":" + m->implementation);
  }
};

TEST(ProcessSwap, ReplacesOneImplementationAndEveryInputDuringTheSwapIsAnswered) {
  const std::string src = BOOKGRASP_SOURCE_DIR, build = BOOKGRASP_BINARY_DIR;
  const std::string tmp = testing::TempDir() + "/swap_" + std::to_string(::getpid());
  ASSERT_EQ(std::system(("mkdir -p " + tmp).c_str()), 0);
  // The second implementation: the echo fixture under another name and implementation.
  std::ifstream in(src + "/tests/common/echo.yaml");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string b = ss.str();
  b.replace(b.find("name: test_echo"), 15, "name: test_echo_b");
  b.replace(b.find("implementation: echo"), 20, "implementation: b");
  std::ofstream(tmp + "/echo_b.yaml") << b;
  std::ofstream(tmp + "/processes.txt")
      << "test_echo   tests/common/bookgrasp_test_echo tests/common/echo.yaml group=echo impl=echo logical=ECHO_OUT\n"
      << "test_echo_b tests/common/bookgrasp_test_echo " << tmp << "/echo_b.yaml group=echo impl=b logical=ECHO_OUT standby\n";
  const int port = 7300 + ::getpid() % 400;
  const std::string url = "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0&recv_buf_size=4194304";
  const std::string env = "BOOKGRASP_BUILD_DIR=" + build + " BOOKGRASP_RUN_DIR=" + tmp + "/run BOOKGRASP_PROCESSES=" +
                          tmp + "/processes.txt BOOKGRASP_LCM_URL='" + url + "' ";
  const std::string front = env + src + "/deploy/bookgrasp ";

  lcm::LCM lcm(url);
  ASSERT_TRUE(lcm.good()) << "run deploy/bookgrasp setup";
  Listener l;
  lcm.subscribe("ECHO_OUT", &Listener::on_out, &l);
  lcm.subscribe("DETECTOR_SWITCH", &Listener::on_switch, &l);
  lcm.subscribe("SERVICE_STATUS", &Listener::on_status, &l);
  ASSERT_EQ(std::system((front + "start > " + tmp + "/start.log 2>&1").c_str()), 0);

  // Feed ECHO_IN at 50 Hz while the swap runs in another thread.
  std::atomic<bool> swapped{false};
  int swap_rc = -1;
  int64_t t = 0;  // input number, in utime; the echo keeps it
  auto publish_for = [&](double seconds) {
    const auto end = Clock::now() + std::chrono::duration<double>(seconds);
    while (Clock::now() < end) {
      bookgrasp::task_status_t m{};
      m.utime = ++t;
      m.state = "x";
      lcm.publish("ECHO_IN", &m);
      const auto next = Clock::now() + std::chrono::milliseconds(20);
      while (Clock::now() < next) lcm.handleTimeout(5);
    }
  };
  publish_for(2.0);  // the first implementation answers
  std::thread swapper([&] {
    swap_rc = std::system((front + "swap echo test_echo_b > " + tmp + "/swap.log 2>&1").c_str());
    swapped = true;
  });
  publish_for(5.0);
  swapper.join();
  publish_for(1.0);
  std::system((front + "stop > /dev/null 2>&1").c_str());

  ASSERT_EQ(swap_rc, 0) << "see " << tmp << "/swap.log";
  ASSERT_TRUE(swapped);
  // Outputs: first from "echo", then from "b"; every input between the first and the last answered one answered.
  ASSERT_GT(l.out.size(), 100u);
  EXPECT_EQ(l.out.front().second, "echo");
  EXPECT_EQ(l.out.back().second, "b");
  std::vector<int64_t> unanswered;
  for (int64_t i = *l.answered.begin(); i <= *l.answered.rbegin(); ++i)
    if (!l.answered.count(i)) unanswered.push_back(i);
  double max_gap = 0;
  for (size_t i = 1; i < l.out.size(); ++i)
    max_gap = std::max(max_gap, std::chrono::duration<double>(l.out[i].first - l.out[i - 1].first).count());
  RecordProperty("longest_output_silence_s", std::to_string(max_gap));
  std::printf("longest output silence during the swap: %.3f s (%zu outputs of inputs %lld..%lld, %zu unanswered)\n",
              max_gap, l.out.size(), static_cast<long long>(*l.answered.begin()),
              static_cast<long long>(*l.answered.rbegin()), unanswered.size());
  EXPECT_TRUE(unanswered.empty()) << unanswered.size() << " inputs had no answer during the swap, the first "
                                  << (unanswered.empty() ? 0 : unanswered.front())
                                  << ": the channel went quiet (break before make?)";
  // The switch is on the bus and in SERVICE_STATUS.
  ASSERT_EQ(l.switches.size(), 1u);
  EXPECT_EQ(l.switches[0].logical_channel, "ECHO_OUT");
  EXPECT_EQ(l.switches[0].implementation, "b");
  EXPECT_TRUE(l.status_impls.count("test_echo:echo"));
  EXPECT_TRUE(l.status_impls.count("test_echo_b:b"));
}

}  // namespace
