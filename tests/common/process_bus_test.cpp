// Real processes over real UDP multicast on loopback: the echo fixture process
// (bus_echo_main.cpp, the production process runtime) and this test process.
// Each test uses its own multicast port so ctest can run them in parallel.
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

#include <lcm/lcm-cpp.hpp>

#include "bookgrasp/image_t.hpp"
#include "bookgrasp/pose_t.hpp"
#include "bookgrasp/service_status_t.hpp"
#include "bookgrasp/task_status_t.hpp"

namespace {

using Clock = std::chrono::steady_clock;

int unique_port() {
  const auto* info = testing::UnitTest::GetInstance()->current_test_info();
  const std::string name = std::string(info->test_suite_name()) + info->name();
  return 7800 + static_cast<int>((std::hash<std::string>()(name) + ::getpid()) % 900);
}

std::string url_for(int port) {
  return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0&recv_buf_size=4194304";
}

/// A child process running a binary with LCM_DEFAULT_URL set; stderr goes to a file.
class Child {
 public:
  Child(const std::vector<std::string>& args, const std::string& url) {
    err_path_ = testing::TempDir() + "/child_" + std::to_string(::getpid()) + "_" + std::to_string(counter_++) + ".err";
    pid_ = ::fork();
    if (pid_ == 0) {
      ::setenv("LCM_DEFAULT_URL", url.c_str(), 1);
      const int fd = ::open(err_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(fd, 2);
      ::dup2(fd, 1);
      std::vector<char*> argv;
      for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
  }
  ~Child() {
    if (pid_ > 0 && !exited_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  bool alive() const { return !exited_ && ::kill(pid_, 0) == 0 && !reaped(); }
  /// Sends `sig` and waits up to `timeout_s` for the exit code (-1 on timeout or signal death).
  int stop(int sig, double timeout_s = 5.0) {
    ::kill(pid_, sig);
    return wait(timeout_s);
  }
  int wait(double timeout_s) {
    const auto end = Clock::now() + std::chrono::duration<double>(timeout_s);
    while (Clock::now() < end) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        exited_ = true;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return -1;
  }
  std::string output() const {
    std::ifstream in(err_path_);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }

 private:
  bool reaped() const {
    int status = 0;
    return ::waitpid(pid_, &status, WNOHANG) == pid_;
  }
  pid_t pid_ = -1;
  bool exited_ = false;
  std::string err_path_;
  static inline int counter_ = 0;
};

/// Listens on the test's bus for echo output and the echo's status.
struct Listener {
  std::vector<bookgrasp::task_status_t> echoed;
  std::vector<bookgrasp::service_status_t> status;
  void on_echo(const lcm::ReceiveBuffer*, const std::string&, const bookgrasp::task_status_t* m) {
    echoed.push_back(*m);
  }
  void on_status(const lcm::ReceiveBuffer*, const std::string&, const bookgrasp::service_status_t* m) {
    if (m->service == "test_echo") status.push_back(*m);
  }
  const bookgrasp::channel_stats_t* input(const std::string& channel) const {
    if (status.empty()) return nullptr;
    for (const auto& c : status.back().inputs)
      if (c.channel == channel) return &c;
    return nullptr;
  }
};

class ProcessBus : public testing::Test {
 protected:
  void SetUp() override {
    url_ = url_for(unique_port());
    lcm_ = std::make_unique<lcm::LCM>(url_);
    ASSERT_TRUE(lcm_->good()) << "cannot open " << url_
                              << ": run `deploy/bookgrasp setup` (multicast route on loopback, UDP buffers)";
    lcm_->subscribe("ECHO_OUT", &Listener::on_echo, &listener_);
    lcm_->subscribe("SERVICE_STATUS", &Listener::on_status, &listener_);
  }
  /// Handles the bus until `done()` or `timeout_s`.
  bool spin_until(const std::function<bool()>& done, double timeout_s) {
    const auto end = Clock::now() + std::chrono::duration<double>(timeout_s);
    while (Clock::now() < end) {
      if (done()) return true;
      lcm_->handleTimeout(20);
    }
    return done();
  }
  std::unique_ptr<Child> start_echo() {
    auto child = std::make_unique<Child>(std::vector<std::string>{ECHO_BINARY, "--config",
                                                                  std::string(BOOKGRASP_SOURCE_DIR) +
                                                                      "/tests/common/echo.yaml"},
                                         url_);
    EXPECT_TRUE(spin_until([&] { return !listener_.status.empty(); }, 10.0))
        << "the echo process published no SERVICE_STATUS: " << child->output();
    return child;
  }
  std::string url_;
  std::unique_ptr<lcm::LCM> lcm_;
  Listener listener_;
};

bookgrasp::task_status_t msg(int64_t utime, const std::string& state, const std::string& text = "") {
  bookgrasp::task_status_t m;
  m.utime = utime;
  m.state = state;
  m.message = text;
  return m;
}

TEST_F(ProcessBus, TwoProcessesExchangeMessages) {
  auto echo = start_echo();
  for (int i = 0; i < 20; ++i) {
    auto m = msg(1000 + i, "n" + std::to_string(i));
    lcm_->publish("ECHO_IN", &m);
  }
  ASSERT_TRUE(spin_until([&] { return listener_.echoed.size() == 20; }, 5.0)) << listener_.echoed.size();
  for (int i = 0; i < 20; ++i) {
    EXPECT_EQ(listener_.echoed[i].state, "echo:n" + std::to_string(i));
    EXPECT_EQ(listener_.echoed[i].utime, 1000 + i);
  }
  EXPECT_EQ(echo->stop(SIGTERM), 0);
}

TEST_F(ProcessBus, LargeImagesAt30HzForThreeSecondsArriveWithoutLoss) {
  auto echo = start_echo();
  bookgrasp::image_t img;
  img.frame = "test";
  img.width = 640;
  img.height = 640;
  img.pixel_format = bookgrasp::image_t::RGB8;
  img.row_stride = 640 * 3;
  img.data.assign(static_cast<size_t>(img.row_stride) * img.height, 0);
  for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = static_cast<uint8_t>(i * 7);
  img.size = static_cast<int32_t>(img.data.size());
  ASSERT_GE(img.getEncodedSize(), 1200000);
  const int n = 90;  // 3 s at 30 Hz
  auto next = Clock::now();
  for (int i = 0; i < n; ++i) {
    img.utime = i * 33333;
    lcm_->publish("ECHO_IMAGES", &img);
    next += std::chrono::microseconds(33333);
    while (Clock::now() < next) lcm_->handleTimeout(1);
  }
  ASSERT_TRUE(spin_until(
      [&] {
        const auto* c = listener_.input("ECHO_IMAGES");
        return c && c->count == n;
      },
      5.0));
  EXPECT_EQ(listener_.input("ECHO_IMAGES")->rejected, 0);
  EXPECT_EQ(echo->stop(SIGTERM), 0);
}

TEST_F(ProcessBus, GarbageAndWrongTypesAreCountedAndTheProcessKeepsRunning) {
  auto echo = start_echo();
  const uint8_t garbage[] = {0xde, 0xad, 0xbe, 0xef, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14};
  lcm_->publish("ECHO_IN", garbage, sizeof(garbage));
  bookgrasp::pose_t wrong;
  wrong.utime = 1;
  lcm_->publish("ECHO_IN", &wrong);
  auto thrower = msg(2, "x", "throw");
  lcm_->publish("ECHO_IN", &thrower);
  // A raw datagram that is not even LCM, straight to the multicast group and port.
  const int sock = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(std::stoi(url_.substr(url_.rfind(':') + 1))));
  ::inet_pton(AF_INET, "239.255.76.67", &addr.sin_addr);
  ::sendto(sock, garbage, sizeof(garbage), 0, reinterpret_cast<sockaddr*>(&addr), sizeof(addr));
  ::close(sock);

  auto good = msg(3, "after");
  lcm_->publish("ECHO_IN", &good);
  ASSERT_TRUE(spin_until([&] { return !listener_.echoed.empty(); }, 5.0)) << echo->output();
  EXPECT_EQ(listener_.echoed[0].state, "echo:after");
  ASSERT_TRUE(spin_until(
      [&] {
        const auto* c = listener_.input("ECHO_IN");
        return c && c->rejected == 3;
      },
      5.0));
  const auto& st = listener_.status.back();
  EXPECT_EQ(st.rejected_total, 3);
  EXPECT_NE(st.last_error.find("ECHO_IN"), std::string::npos) << st.last_error;
  EXPECT_TRUE(echo->alive());
  EXPECT_NE(echo->output().find("cannot decode"), std::string::npos) << "the rejection must be logged";
  EXPECT_EQ(echo->stop(SIGINT), 0);
}

TEST_F(ProcessBus, StopsCleanlyOnSigtermWithAFinalStatus) {
  auto echo = start_echo();
  listener_.status.clear();
  ASSERT_EQ(echo->stop(SIGTERM), 0) << echo->output();
  spin_until([&] { return !listener_.status.empty(); }, 1.0);
  ASSERT_FALSE(listener_.status.empty());
  EXPECT_EQ(listener_.status.back().state, bookgrasp::service_status_t::STOPPING);
  EXPECT_NE(echo->output().find("stopped cleanly"), std::string::npos);
}

TEST_F(ProcessBus, BadConfigurationFailsAtStartNamingTheKey) {
  const std::string path = testing::TempDir() + "/echo_bad_" + std::to_string(::getpid()) + ".yaml";
  std::ofstream(path) << "service: {name: e, implementation: echo, lcm_url: '', status_period_s: 1.0,\n"
                         "  config_period_s: 5.0, status_channel: S, config_channel: C}\n"
                         "channels: {input: A, images: B}\n";
  Child missing({ECHO_BINARY, "--config", path}, url_);
  EXPECT_EQ(missing.wait(5.0), 2);
  EXPECT_NE(missing.output().find("'channels.output'"), std::string::npos) << missing.output();

  std::ofstream(path) << "service: {name: e, implementation: echo, lcm_url: '', status_period_s: -1,\n"
                         "  config_period_s: 5.0, status_channel: S, config_channel: C}\n"
                         "channels: {input: A, output: O, images: B}\n";
  Child range({ECHO_BINARY, "--config", path}, url_);
  EXPECT_EQ(range.wait(5.0), 2);
  EXPECT_NE(range.output().find("'service.status_period_s'"), std::string::npos) << range.output();

  std::ofstream(path) << "service: {name: e, implementation: echo, lcm_url: '', status_period_s: 1,\n"
                         "  config_period_s: 5.0, status_channel: S, config_channel: C}\n"
                         "channels: {input: A, output: O, images: B, typo: X}\n";
  Child typo({ECHO_BINARY, "--config", path}, url_);
  EXPECT_EQ(typo.wait(5.0), 2);
  EXPECT_NE(typo.output().find("'channels.typo'"), std::string::npos) << typo.output();

  Child help({ECHO_BINARY, "--help"}, url_);
  EXPECT_EQ(help.wait(5.0), 0);
  EXPECT_NE(help.output().find("--config FILE"), std::string::npos);
  Child bad_arg({ECHO_BINARY, "--frobnicate"}, url_);
  EXPECT_EQ(bad_arg.wait(5.0), 2);
}

TEST_F(ProcessBus, SetOverridesAConfigValueAndTheSnapshotCarriesIt) {
  const std::string config = std::string(BOOKGRASP_SOURCE_DIR) + "/tests/common/echo.yaml";
  // The output channel moved by --set: the echo answers on the new channel.
  Child echo({ECHO_BINARY, "--config", config, "--set", "channels.output=ECHO_OUT_SET"}, url_);
  std::vector<bookgrasp::task_status_t> moved;
  struct Sink {
    std::vector<bookgrasp::task_status_t>* out;
    void on(const lcm::ReceiveBuffer*, const std::string&, const bookgrasp::task_status_t* m) { out->push_back(*m); }
  } sink{&moved};
  lcm_->subscribe("ECHO_OUT_SET", &Sink::on, &sink);
  ASSERT_TRUE(spin_until([&] { return !listener_.status.empty(); }, 10.0)) << echo.output();
  for (int i = 0; i < 5 && moved.empty(); ++i) {
    const auto m = msg(1000 + i, "PING");
    lcm_->publish("ECHO_IN", &m);
    spin_until([&] { return !moved.empty(); }, 0.5);
  }
  ASSERT_FALSE(moved.empty()) << echo.output();
  EXPECT_TRUE(listener_.echoed.empty()) << "the file's channel was used despite --set";

  // An unknown key is an error at start naming it, exit code 2.
  Child typo({ECHO_BINARY, "--config", config, "--set", "channels.outptu=X"}, url_);
  EXPECT_EQ(typo.wait(5.0), 2);
  EXPECT_NE(typo.output().find("'channels.outptu'"), std::string::npos) << typo.output();
  Child malformed({ECHO_BINARY, "--config", config, "--set", "channels.output"}, url_);
  EXPECT_EQ(malformed.wait(5.0), 2);
  EXPECT_NE(malformed.output().find("dotted.key=value"), std::string::npos) << malformed.output();
}

}  // namespace
