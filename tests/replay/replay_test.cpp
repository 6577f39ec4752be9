// Replay against a recording made by running the same component live on a bus.
#include <gtest/gtest.h>

#include <fstream>

#include "common/composition.h"
#include "services/replay/component_registry.h"
#include "common/lcm_log.h"
#include "services/replay/output_diff.h"
#include "services/replay/replay_runner.h"
#include "tests/replay/gain_component.h"

namespace bookgrasp {
namespace {

std::string gain_yaml(double gain) {
  return "service: {name: gain}\ngain: " + std::to_string(gain) +
         "\nchannels: {input: POSE_IN, output: POSE_OUT, count: COUNT}\n";
}

/// Records a "live" session: inputs published on a bus with the component
/// running, everything captured (like lcm-logger), plus unrelated traffic.
std::vector<LoggedMessage> record_session(double gain) {
  Composition comp;
  comp.add(std::make_unique<bookgrasp_test::GainComponent>(Config::from_string(gain_yaml(gain))));
  struct Rec {
    std::vector<LoggedMessage> log;
    void on(const lcm::ReceiveBuffer* rb, const std::string& ch) {
      LoggedMessage m;
      m.channel = ch;
      const auto* b = static_cast<const uint8_t*>(rb->data);
      m.data.assign(b, b + rb->data_size);
      m.log_utime = 1000000000 + static_cast<int64_t>(log.size());
      log.push_back(m);
    }
  } rec;
  comp.bus().subscribe(".*", &Rec::on, &rec);
  for (int i = 0; i < 50; ++i) {
    pose_t p{};
    p.utime = 1000000 + i * 100000;
    p.frame = "base";
    p.child = "x";
    p.position[0] = 0.01 * i;
    p.position[1] = -0.02 * i;
    p.position[2] = 0.5;
    p.orientation[0] = 1;
    comp.bus().publish("POSE_IN", &p);
    task_status_t other{};
    other.utime = p.utime;
    other.state = "unrelated";
    comp.bus().publish("OTHER", &other);
    comp.spin();
  }
  return rec.log;
}

std::unique_ptr<Component> gain(double g) {
  return std::make_unique<bookgrasp_test::GainComponent>(Config::from_string(gain_yaml(g)));
}

TEST(LcmLog, WriteReadRoundTripAndBadFiles) {
  const auto log = record_session(2.0);
  const std::string path = testing::TempDir() + "/replay_test.lcm";
  write_lcm_log(path, log);
  const auto back = read_lcm_log(path);
  ASSERT_EQ(back.size(), log.size());
  for (size_t i = 0; i < log.size(); ++i) {
    EXPECT_EQ(back[i].channel, log[i].channel);
    EXPECT_EQ(back[i].data, log[i].data);
    EXPECT_EQ(back[i].log_utime, log[i].log_utime);
  }
  EXPECT_THROW(read_lcm_log("/nonexistent.lcm"), std::runtime_error);
  const std::string junk = testing::TempDir() + "/junk.lcm";
  std::ofstream(junk) << "this is not a log";
  EXPECT_THROW(read_lcm_log(junk), std::runtime_error);
}

TEST(Replay, SameConfigGivesIdenticalOutputsBitForBit) {
  const auto log = record_session(2.0);
  std::vector<std::unique_ptr<Component>> cs;
  cs.push_back(gain(2.0));
  const ReplayRun run = replay_log(log, std::move(cs));
  EXPECT_EQ(run.fed_channels, std::set<std::string>{"POSE_IN"}) << "only subscribed channels are fed";
  EXPECT_EQ(run.messages_fed, 50);
  EXPECT_NEAR(run.log_duration_s, 4.9, 1e-9);
  const DiffReport r = diff_outputs(log, run.outputs);
  ASSERT_EQ(r.channels.size(), 2u);  // COUNT and POSE_OUT
  for (const auto& c : r.channels) {
    EXPECT_EQ(c.recorded, 50) << c.channel;
    EXPECT_EQ(c.identical, 50) << c.channel;
    EXPECT_EQ(c.differing + c.missing + c.extra, 0) << c.channel;
  }
  EXPECT_TRUE(r.identical()) << r.markdown();
}

TEST(Replay, ChangedParameterIsReportedFieldByField) {
  const auto log = record_session(2.0);
  std::vector<std::unique_ptr<Component>> cs;
  cs.push_back(gain(2.5));
  const ReplayRun run = replay_log(log, std::move(cs));
  const DiffReport r = diff_outputs(log, run.outputs);
  EXPECT_FALSE(r.identical());
  const ChannelDiff* pose = nullptr;
  for (const auto& c : r.channels)
    if (c.channel == "POSE_OUT") pose = &c;
  ASSERT_NE(pose, nullptr);
  EXPECT_EQ(pose->type, "pose_t");
  EXPECT_EQ(pose->matched, 50);
  EXPECT_EQ(pose->differing, 50) << "z = 0.5 is scaled in every message";
  ASSERT_FALSE(pose->fields.empty());
  // position[*]: the largest move is |2.5 - 2.0| * max(|x|, |y|, |z|) = 0.5 * 0.98 = 0.49 (y at i = 49).
  EXPECT_EQ(pose->fields[0].path, "position[*]");
  EXPECT_NEAR(pose->fields[0].max_abs, 0.49, 1e-9);
  EXPECT_NE(r.markdown().find("position[*]"), std::string::npos);
  EXPECT_NE(r.json().find("\"identical\": false"), std::string::npos);
}

TEST(Replay, IgnoredFieldsAndChainFeeding) {
  const auto log = record_session(2.0);
  std::vector<std::unique_ptr<Component>> cs;
  cs.push_back(gain(2.5));
  const ReplayRun run = replay_log(log, std::move(cs));
  const DiffReport r = diff_outputs(log, run.outputs, {"POSE_OUT"}, {"position[*]"});
  EXPECT_TRUE(r.identical()) << "only position moved and it is ignored:\n" << r.markdown();

  // A chain: a second gain consumes the first one's output; POSE_OUT must be
  // recomputed by the chain, not fed from the recording.
  std::vector<std::unique_ptr<Component>> chain;
  chain.push_back(gain(3.0));
  chain.push_back(std::make_unique<bookgrasp_test::GainComponent>(
      Config::from_string("service: {name: g2}\ngain: 10\nchannels: {input: POSE_OUT, output: POSE_FINAL, count: C2}\n")));
  const ReplayRun chained = replay_log(log, std::move(chain));
  EXPECT_EQ(chained.fed_channels, std::set<std::string>{"POSE_IN"});
  int finals = 0;
  for (const auto& m : chained.outputs) {
    if (m.channel != "POSE_FINAL") continue;
    pose_t p;
    ASSERT_EQ(p.decode(m.data.data(), 0, static_cast<int>(m.data.size())), static_cast<int>(m.data.size()));
    EXPECT_NEAR(p.position[2], 0.5 * 3.0 * 10.0, 1e-12);
    ++finals;
  }
  EXPECT_EQ(finals, 50);
}

TEST(ComponentRegistry, UnknownNamesAndConfigErrors) {
  ComponentRegistry reg;
  reg.add({"gain", "test", "tests/replay/gain.yaml",
           [](const Config& root) { return std::make_unique<bookgrasp_test::GainComponent>(root); }});
  EXPECT_EQ(reg.names(), std::vector<std::string>{"gain"});
  try {
    reg.get("nope");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("known: gain"), std::string::npos);
  }
  const std::string path = testing::TempDir() + "/gain_bad.yaml";
  std::ofstream(path) << "service: {name: g}\ngain: 1\nchannels: {input: A, output: B, count: C, typo: D}\n";
  EXPECT_THROW(reg.make("gain", path, ""), ConfigError);
}

}  // namespace
}  // namespace bookgrasp

namespace bookgrasp {
namespace {

TEST(Replay, LogBoundariesAreNotDifferences) {
  auto log = record_session(2.0);
  // The recording missed the first input and stopped before the last output:
  // drop the first POSE_IN and the last POSE_OUT / COUNT.
  bool dropped_in = false;
  std::vector<LoggedMessage> cut;
  for (const auto& m : log) {
    if (!dropped_in && m.channel == "POSE_IN") {
      dropped_in = true;
      continue;
    }
    cut.push_back(m);
  }
  const int64_t last = cut.back().message_utime();
  std::vector<LoggedMessage> trimmed;
  for (const auto& m : cut)
    if (!(m.message_utime() == last && (m.channel == "POSE_OUT" || m.channel == "COUNT"))) trimmed.push_back(m);
  std::vector<std::unique_ptr<Component>> cs;
  cs.push_back(gain(2.0));
  const ReplayRun run = replay_log(trimmed, std::move(cs));
  const DiffReport r = diff_outputs(trimmed, run.outputs, {"POSE_OUT"}, {}, run.fed_utimes);
  ASSERT_EQ(r.channels.size(), 1u);
  EXPECT_EQ(r.channels[0].unreplayable, 1);
  EXPECT_EQ(r.channels[0].after_log_end, 1);
  EXPECT_EQ(r.channels[0].identical, 48);
  EXPECT_TRUE(r.identical()) << r.markdown();
  // Without the fed utimes the same gaps are real differences.
  EXPECT_FALSE(diff_outputs(trimmed, run.outputs, {"POSE_OUT"}).identical());
}

}  // namespace
}  // namespace bookgrasp
