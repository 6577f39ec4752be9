// A component composed on memq://: dispatch, rejection, status and snapshots in message time.
#include "common/component.h"

#include <gtest/gtest.h>

#include "bookgrasp/config_snapshot_t.hpp"
#include "bookgrasp/pose_t.hpp"
#include "bookgrasp/service_status_t.hpp"
#include "common/composition.h"
#include "tests/common/echo_component.h"

namespace bookgrasp_test {
namespace {

using bookgrasp::Composition;
using bookgrasp::Config;

const char* kEchoYaml = R"(
service: {name: echo, implementation: echo, lcm_url: "", status_period_s: 1.0, config_period_s: 5.0,
          status_channel: SERVICE_STATUS, config_channel: CONFIG_SNAPSHOT}
channels: {input: IN, output: OUT, images: IMAGES}
)";

/// Collects messages of one type from a channel.
template <typename Msg>
struct Collector {
  std::vector<Msg> got;
  void on(const lcm::ReceiveBuffer*, const std::string&, const Msg* m) { got.push_back(*m); }
};

bookgrasp::task_status_t status_msg(int64_t utime, const std::string& state, const std::string& message = "") {
  bookgrasp::task_status_t m;
  m.utime = utime;
  m.state = state;
  m.message = message;
  return m;
}

TEST(Composition, DispatchesInOrderWithMessageTime) {
  Composition comp;
  const Config cfg = Config::from_string(kEchoYaml);
  comp.add(std::make_unique<EchoComponent>(cfg));
  Collector<bookgrasp::task_status_t> out;
  comp.bus().subscribe("OUT", &Collector<bookgrasp::task_status_t>::on, &out);
  for (int i = 1; i <= 5; ++i) {
    auto m = status_msg(1000 * i, "s" + std::to_string(i));
    comp.bus().publish("IN", &m);
  }
  comp.spin();
  ASSERT_EQ(out.got.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(out.got[i].state, "echo:s" + std::to_string(i + 1));
    EXPECT_EQ(out.got[i].utime, 1000 * (i + 1)) << "output must carry the input's utime";
  }
  EXPECT_EQ(comp.now_utime(), 5000);
}

TEST(Composition, GarbageWrongTypeAndThrowingHandlerAreRejectedAndDispatchGoesOn) {
  Composition comp;
  const Config cfg = Config::from_string(kEchoYaml);
  auto& echo = comp.add(std::make_unique<EchoComponent>(cfg));
  Collector<bookgrasp::task_status_t> out;
  comp.bus().subscribe("OUT", &Collector<bookgrasp::task_status_t>::on, &out);

  const uint8_t garbage[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17};
  comp.bus().publish("IN", garbage, sizeof(garbage));
  bookgrasp::pose_t wrong;
  wrong.utime = 7;
  comp.bus().publish("IN", &wrong);
  auto thrower = status_msg(8, "x", "throw");
  comp.bus().publish("IN", &thrower);
  auto good = status_msg(9, "ok");
  comp.bus().publish("IN", &good);
  comp.spin();

  EXPECT_EQ(echo.rejected_total(), 3);
  EXPECT_EQ(echo.inputs().at("IN").rejected, 3);
  EXPECT_NE(echo.last_error().find("asked to throw"), std::string::npos) << echo.last_error();
  ASSERT_EQ(out.got.size(), 1u) << "the good message after the bad ones must still be handled";
  EXPECT_EQ(out.got[0].state, "echo:ok");
}

TEST(Composition, ServicePublishesStatusAndConfigInMessageTime) {
  Composition comp;
  const Config cfg = Config::from_string(kEchoYaml);
  comp.add_service(std::make_unique<EchoComponent>(cfg), bookgrasp::ServiceSettings::from_config(cfg), kEchoYaml);
  Collector<bookgrasp::service_status_t> status;
  Collector<bookgrasp::config_snapshot_t> config;
  comp.bus().subscribe("SERVICE_STATUS", &Collector<bookgrasp::service_status_t>::on, &status);
  comp.bus().subscribe("CONFIG_SNAPSHOT", &Collector<bookgrasp::config_snapshot_t>::on, &config);
  // 10 s of message time at 10 Hz.
  for (int i = 0; i <= 100; ++i) {
    auto m = status_msg(1000000 + i * 100000, "t");
    comp.bus().publish("IN", &m);
    comp.spin();
  }
  // Status at 1 Hz: t = 1.0 .. 11.0 s -> 11 messages; config every 5 s -> 3.
  EXPECT_EQ(status.got.size(), 11u);
  EXPECT_EQ(config.got.size(), 3u);
  ASSERT_FALSE(status.got.empty());
  const auto& last = status.got.back();
  EXPECT_EQ(last.service, "echo");
  EXPECT_EQ(last.implementation, "echo");
  EXPECT_EQ(last.state, bookgrasp::service_status_t::RUNNING);
  bool found_in = false;
  for (const auto& in : last.inputs) {
    if (in.channel != "IN") continue;
    found_in = true;
    EXPECT_EQ(in.count, 101);
    EXPECT_NEAR(in.rate_hz, 10.0, 0.01);
  }
  EXPECT_TRUE(found_in);
  ASSERT_FALSE(config.got.empty());
  EXPECT_EQ(config.got[0].config_yaml, kEchoYaml);
}

// A 1 Hz stream whose messages fall just before and just after the 1 s status reports by turns: the
// status rate is averaged over kStatusRateWindowS, so it reads about 1 Hz instead of 0 and 2 by turns.
TEST(Composition, StatusRateOfASlowJitteryStreamIsAveragedOverTheWindow) {
  Composition comp;
  const Config cfg = Config::from_string(kEchoYaml);
  comp.add_service(std::make_unique<EchoComponent>(cfg), bookgrasp::ServiceSettings::from_config(cfg), kEchoYaml);
  Collector<bookgrasp::service_status_t> status;
  comp.bus().subscribe("SERVICE_STATUS", &Collector<bookgrasp::service_status_t>::on, &status);
  // A 10 Hz image stream keeps message time going (status every second); IN comes at 1 Hz, 20 ms early and
  // late by turns, so a 1 s period holds 0 or 2 of them by turns.
  bookgrasp::image_t tick;
  tick.width = tick.height = 1;
  tick.size = 0;
  int next_in = 1;
  for (int t = 1; t <= 200; ++t) {
    tick.utime = t * 100000;
    const int64_t in_utime = next_in * 1000000 + 100000 + (next_in % 2 ? -20000 : 20000);  // reports at k + 0.1 s
    if (in_utime < tick.utime) {                                                           // in message-time order
      auto m = status_msg(in_utime, "t");
      comp.bus().publish("IN", &m);
      comp.spin();
      ++next_in;
    }
    comp.bus().publish("IMAGES", &tick);
    comp.spin();
  }
  ASSERT_GE(status.got.size(), 15u);
  // Once the window is full, every report reads 1 Hz within one message per window.
  for (size_t k = 7; k < status.got.size(); ++k) {
    for (const auto& in : status.got[k].inputs) {
      if (in.channel != "IN") continue;
      EXPECT_NEAR(in.rate_hz, 1.0, 1.0 / bookgrasp::kStatusRateWindowS + 1e-9) << "report " << k;
    }
  }
}

TEST(Composition, SameInputSameOutputBitForBit) {
  auto run = [] {
    Composition comp;
    const Config cfg = Config::from_string(kEchoYaml);
    comp.add(std::make_unique<EchoComponent>(cfg));
    Collector<bookgrasp::task_status_t> out;
    comp.bus().subscribe("OUT", &Collector<bookgrasp::task_status_t>::on, &out);
    for (int i = 0; i < 50; ++i) {
      auto m = status_msg(i * 33, "v" + std::to_string(i * 7 % 13));
      comp.bus().publish("IN", &m);
    }
    comp.spin();
    std::vector<uint8_t> all;
    for (auto& m : out.got) {
      std::vector<uint8_t> b(m.getEncodedSize());
      m.encode(b.data(), 0, static_cast<int>(b.size()));
      all.insert(all.end(), b.begin(), b.end());
    }
    return all;
  };
  const auto a = run();
  EXPECT_FALSE(a.empty());
  EXPECT_EQ(a, run());
}

}  // namespace
}  // namespace bookgrasp_test
