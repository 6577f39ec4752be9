// Replay of the committed sample recording (logs/samples/system_jpeg.lcm, made by
// deploy/make_sample_log.sh from the real running system) through the production services:
// with their shipped configuration the outputs are identical bit for bit; with a changed
// parameter the report shows what moved.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>
#include <utility>
#include <vector>

#include "bookgrasp/arm_command_t.hpp"
#include "bookgrasp/plan_result_t.hpp"
#include "services/replay/component_registry.h"
#include "services/replay/output_diff.h"
#include "services/replay/replay_runner.h"

namespace bookgrasp {
namespace {

const std::string kSample = std::string(BOOKGRASP_SOURCE_DIR) + "/logs/samples/system_jpeg.lcm";
// Wall-clock timing fields are the only ones that are not reproducible.
const std::set<std::string> kTiming = {"processing_ms", "disparity_ms", "segmentation_ms", "total_ms"};

// config/services/<service>.yaml with every (pattern, replacement) applied in order, written to the test's temporary
// directory as `file`; "" when some pattern is not in the text it is applied to.
std::string shipped_config_with(const std::string& service,
                                const std::vector<std::pair<std::string, std::string>>& replacements,
                                const std::string& file) {
  std::ifstream in(std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/" + service + ".yaml");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  for (const auto& [pattern, replacement] : replacements) {
    if (!std::regex_search(text, std::regex(pattern))) return "";
    text = std::regex_replace(text, std::regex(pattern), replacement);
  }
  const std::string path = testing::TempDir() + "/" + file;
  std::ofstream(path) << text;
  return path;
}

// The same with one (pattern, replacement).
std::string shipped_config_with(const std::string& service, const std::string& pattern, const std::string& replacement,
                                const std::string& file) {
  return shipped_config_with(service, {{pattern, replacement}}, file);
}

DiffReport replay_chain(const std::vector<std::string>& services) {
  const auto log = read_lcm_log(kSample);
  std::vector<std::unique_ptr<Component>> cs;
  for (const auto& s : services) cs.push_back(project_services().make(s, "", BOOKGRASP_SOURCE_DIR));
  const ReplayRun run = replay_log(log, std::move(cs));
  EXPECT_GT(run.messages_fed, 5) << "the sample has too few inputs for the chain";
  return diff_outputs(log, run.outputs, {}, kTiming, run.fed_utimes);
}

DiffReport replay(const std::string& service, const std::string& config_path = "") {
  const auto log = read_lcm_log(kSample);
  std::vector<std::unique_ptr<Component>> cs;
  cs.push_back(project_services().make(service, config_path, BOOKGRASP_SOURCE_DIR));
  const ReplayRun run = replay_log(log, std::move(cs));
  EXPECT_GT(run.messages_fed, 5) << service << ": the sample has too few inputs for it";
  return diff_outputs(log, run.outputs, {}, kTiming, run.fed_utimes);
}

class SampleReplay : public testing::TestWithParam<std::string> {};

TEST_P(SampleReplay, ShippedConfigReproducesTheRecordingBitForBit) {
  const DiffReport r = replay(GetParam());
  ASSERT_FALSE(r.channels.empty());
  for (const auto& c : r.channels) {
    // Every output the live process published is reproduced, byte for byte.
    EXPECT_GT(c.matched, 5) << r.markdown();
    EXPECT_EQ(c.identical, c.matched) << r.markdown();
    EXPECT_EQ(c.differing, 0) << r.markdown();
    EXPECT_EQ(c.missing, 0) << r.markdown();
    // The live recording went over UDP on a loaded machine: an input the logger kept but the live
    // process never saw (or an output the logger lost) makes an extra replayed output. That is the
    // transport, not the component; it must stay rare.
    EXPECT_LE(c.extra * 10, c.matched) << r.markdown();
  }
}

// The arbiter is replayed on logs/samples/arbiter_seed5.lcm (ArbiterReplay below, > 10 decisions): 20 s of the
// deployed system on far_cart.yaml (the sample, re-recorded 2026-12-02 for the stereo-ranged markers) end inside the
// first stripe servo, with one or two arbiter decisions, too few to judge by.
INSTANTIATE_TEST_SUITE_P(Services, SampleReplay,
                         testing::Values("marker_detector", "bws_detector", "bwh_detector", "bswh_detector"));

// Chain mode from the cameras' output: marker_detector recomputes MARKERS in the same process and
// bws_detector pairs each frame with the MARKERS of its utime, so although the two now arrive in
// another order than between the live processes, P1 is reproduced bit for bit.
TEST(SampleReplay, ChainFromTheStereoCameraReproducesMarkersAndP1) {
  const DiffReport r = replay_chain({"marker_detector", "bws_detector"});
  ASSERT_EQ(r.channels.size(), 2u) << r.markdown();
  for (const auto& c : r.channels) {
    EXPECT_GT(c.matched, 5) << r.markdown();
    EXPECT_EQ(c.identical, c.matched) << r.markdown();
    EXPECT_EQ(c.missing, 0) << r.markdown();
  }
}

TEST(SampleReplay, ChangedParameterIsReported) {
  // bswh_detector with a different stripe threshold: the stripe outputs move and the report says where.
  const std::string path =
      shipped_config_with("bswh_detector", "dark_ratio: 0\\.5", "dark_ratio: 0.8", "bswh_changed.yaml");
  ASSERT_FALSE(path.empty());
  const DiffReport r = replay("bswh_detector", path);
  EXPECT_FALSE(r.identical()) << r.markdown();
  ASSERT_EQ(r.channels.size(), 1u);
  EXPECT_GT(r.channels[0].differing, 0);
  EXPECT_FALSE(r.channels[0].fields.empty());
}

}  // namespace
}  // namespace bookgrasp

namespace bookgrasp {
namespace {

// Every registered service builds from its shipped configuration (config/services/<name>.yaml):
// every key present, valid and read.
TEST(ShippedConfigs, EveryRegisteredServiceBuildsFromItsDefaultConfig) {
  const ComponentRegistry reg = project_services();
  EXPECT_GE(reg.names().size(), 8u);
  for (const auto& name : reg.names()) {
    EXPECT_NO_THROW(reg.make(name, "", BOOKGRASP_SOURCE_DIR)) << name;
  }
}

}  // namespace
}  // namespace bookgrasp

namespace bookgrasp {
namespace {

// logs/samples/arbiter_seed5.lcm: the arbiter's inputs and outputs from the composed full-cycle harness
// on seed 5 (bookgrasp_eval_full --scenes 1 --seed 5 --scene config/scenes/default.yaml --books 3 --stereo-hz 2
// --log --log-channels BOOK_CORNER_STEREO,SERVO_STATUS,SERVO_REQUEST,MARKERS,ARM_STATE,DETECTOR_SWITCH,GRASP_POINT
// --out DIR, then DIR/logs/seed_5.lcmlog: three books through the whole cycle (stop 27); at first two, the third
// ABORTED when the corner servo stopped at a joint limit); re-recorded 2026-12-07 (stop 43) when an attempt's P1 came
// to be judged on the distance its P1 check measured (three grasps held: two books moved, the third handed over);
// re-recorded 2026-12-05 (stop 28) when the arbiter began
// to check P2 against a PS the stripe servo measured (tolerances.p2_measured_ps_y_m, one more step in GRASP);
// re-recorded 2026-12-04 (stop 27) when the cart tag moved 0.10 m right (scene markers.cart.y_m 0.20); re-recorded
// 2026-12-04 (stop 26) when the arbiter began to read the book width only while the arm executes no motion (three books
// through the whole cycle); re-recorded 2026-12-03 (stop 20) when SERVO_STATUS gained the triangulated corner; before
// (stop 19) when the P1 check's gp_grasp Z became the corner servo's front depth and the stereo front left of PS
// (arbiter.yaml stereo_front) joined GP.z's rules.
DiffReport replay_arbiter(const std::string& config_path) {
  const auto log = read_lcm_log(std::string(BOOKGRASP_SOURCE_DIR) + "/logs/samples/arbiter_seed5.lcm");
  std::vector<std::unique_ptr<Component>> cs;
  cs.push_back(project_services().make("arbiter", config_path, BOOKGRASP_SOURCE_DIR));
  const ReplayRun run = replay_log(log, std::move(cs));
  return diff_outputs(log, run.outputs, {"GRASP_POINT"}, {}, run.fed_utimes);
}

TEST(ArbiterReplay, ShippedConfigReproducesEveryDecisionBitForBit) {
  const DiffReport r = replay_arbiter("");
  ASSERT_EQ(r.channels.size(), 1u);
  EXPECT_GT(r.channels[0].matched, 10) << r.markdown();
  EXPECT_TRUE(r.identical()) << r.markdown();
}

TEST(ArbiterReplay, TighterP1ToleranceChangesTheDecisions) {
  const std::string path =
      shipped_config_with("arbiter", "p1_ps_y_m: 0\\.010", "p1_ps_y_m: 0.0001", "arbiter_tight.yaml");
  ASSERT_FALSE(path.empty());
  const DiffReport r = replay_arbiter(path);
  EXPECT_FALSE(r.identical()) << "a 0.1 mm P1-PS tolerance must reject the recorded P1:\n" << r.markdown();
}

}  // namespace
}  // namespace bookgrasp

namespace bookgrasp {
namespace {

// logs/samples/planner_lower_shelf.lcm: PLAN_REQUEST, PLAN_RESULT and MARKERS of the deployed main job
// (logs/demo-20261205-153617.lcm, 400-600 s, cut by deploy/filter_log.py), recorded with planner.yaml's
// max_search_steps at 30000. Books 5, 6 and 7 went from the holder towards lower-shelf slots near y = 0; the first
// request of each (and all but one retry) ended "CellBiRRT found no path within 30000 search steps", so two of them
// were handed over to the librarian.
const std::string kPlannerSample = std::string(BOOKGRASP_SOURCE_DIR) + "/logs/samples/planner_lower_shelf.lcm";

// planner.yaml with the wall clock out of the search (`wall_clock_stop: false`) and, unless `steps` is empty, the
// search's step limit at `steps`: the recorded requests carry a time budget in seconds of the recording machine's
// clock, which a starved test process can exhaust before the step limit; the step count alone gives the recorded
// answers.
std::string planner_config_without_the_clock(const std::string& steps = "") {
  std::vector<std::pair<std::string, std::string>> replacements = {{"wall_clock_stop: true", "wall_clock_stop: false"}};
  if (!steps.empty()) replacements.emplace_back("max_search_steps: [0-9]+", "max_search_steps: " + steps);
  const std::string path = shipped_config_with("planner", replacements, "planner_steps_" + steps + ".yaml");
  EXPECT_FALSE(path.empty()) << "planner.yaml has no wall_clock_stop: true or no max_search_steps";
  return path;
}

std::vector<plan_result_t> plan_results(const std::vector<LoggedMessage>& messages) {
  std::vector<plan_result_t> out;
  for (const auto& m : messages) {
    if (m.channel != "PLAN_RESULT") continue;
    plan_result_t r;
    EXPECT_GT(r.decode(m.data.data(), 0, static_cast<int>(m.data.size())), 0);
    out.push_back(r);
  }
  return out;
}

ReplayRun replay_planner(const std::vector<LoggedMessage>& log, const std::string& config_path) {
  std::vector<std::unique_ptr<Component>> cs;
  cs.push_back(project_services().make("planner", config_path, BOOKGRASP_SOURCE_DIR));
  return replay_log(log, std::move(cs));
}

// The planner is seeded by each request's identity, and its search ends after a count of steps, not by the clock:
// with the configuration it ran with, every recorded plan and every recorded failure comes back byte for byte.
TEST(PlannerReplay, TheRecordedBudgetReproducesEveryPlanAndFailureBitForBit) {
  const auto log = read_lcm_log(kPlannerSample);
  const ReplayRun run = replay_planner(log, planner_config_without_the_clock("30000"));
  const DiffReport r = diff_outputs(log, run.outputs, {"PLAN_RESULT"}, {"planning_time_s"}, run.fed_utimes);
  ASSERT_EQ(r.channels.size(), 1u) << r.markdown();
  EXPECT_EQ(r.channels[0].matched, 26) << r.markdown();
  EXPECT_TRUE(r.identical()) << r.markdown();
  int failed = 0;
  for (const auto& p : plan_results(run.outputs)) failed += p.success ? 0 : 1;
  EXPECT_EQ(failed, 7) << "the sample holds the deployed run's seven 'no path' answers";
}

// With the shipped step budget (the wall clock out of the search, as in the test above) the first request of every move
// in the sample gets a collision-free path, among them the three the deployed run failed (a retry carries its first
// request's utime, so a first request has request_id == utime). Plans the recording found are found again unchanged:
// the budget only matters where a search ran out.
TEST(PlannerReplay, TheShippedBudgetPlansEveryFirstRequestTheRecordingMissed) {
  const auto log = read_lcm_log(kPlannerSample);
  const std::vector<plan_result_t> recorded = plan_results(log);
  const std::vector<plan_result_t> replayed =
      plan_results(replay_planner(log, planner_config_without_the_clock()).outputs);
  ASSERT_EQ(replayed.size(), recorded.size());
  int missed_first_tries = 0;
  for (size_t i = 0; i < recorded.size(); ++i) {
    ASSERT_EQ(replayed[i].request_id, recorded[i].request_id);
    if (recorded[i].success) {
      EXPECT_TRUE(replayed[i].success) << replayed[i].request_id;
      EXPECT_EQ(replayed[i].trajectory.num_points, recorded[i].trajectory.num_points) << replayed[i].request_id;
      EXPECT_EQ(replayed[i].path_length_rad, recorded[i].path_length_rad) << replayed[i].request_id;
    }
    if (recorded[i].request_id != recorded[i].utime) continue;
    EXPECT_TRUE(replayed[i].success) << replayed[i].request_id << ": " << replayed[i].message;
    if (!recorded[i].success) ++missed_first_tries;
  }
  EXPECT_EQ(missed_first_tries, 3);
}

}  // namespace
}  // namespace bookgrasp

namespace bookgrasp {
namespace {

// The visual servo on the committed sample: every SERVO_STATUS and every ARM_COMMAND it published comes back byte
// for byte. ARM_COMMAND is shared with the coordinator (trajectories and the heartbeat), whose commands the servo
// alone does not make: exactly those are missing from the replay.
TEST(VisualServoReplay, EveryServoCommandAndStatusIsReproducedBitForBit) {
  const auto log = read_lcm_log(kSample);
  int coordinator_commands = 0;
  for (const auto& m : log) {
    if (m.channel != "ARM_COMMAND") continue;
    arm_command_t c;
    ASSERT_GT(c.decode(m.data.data(), 0, static_cast<int>(m.data.size())), 0);
    if (c.mode == arm_command_t::HEARTBEAT || c.mode == arm_command_t::TRAJECTORY) ++coordinator_commands;
  }
  std::vector<std::unique_ptr<Component>> cs;
  cs.push_back(project_services().make("visual_servo", "", BOOKGRASP_SOURCE_DIR));
  const ReplayRun run = replay_log(log, std::move(cs));
  const DiffReport r = diff_outputs(log, run.outputs, {"ARM_COMMAND", "SERVO_STATUS"}, {}, run.fed_utimes);
  ASSERT_EQ(r.channels.size(), 2u) << r.markdown();
  for (const auto& c : r.channels) {
    EXPECT_GT(c.matched, 100) << r.markdown();
    EXPECT_EQ(c.identical, c.matched) << r.markdown();
    EXPECT_EQ(c.differing, 0) << r.markdown();
    EXPECT_EQ(c.extra, 0) << r.markdown();
    EXPECT_EQ(c.missing, c.channel == "ARM_COMMAND" ? coordinator_commands : 0) << r.markdown();
  }
  EXPECT_GT(coordinator_commands, 0);
}

}  // namespace
}  // namespace bookgrasp
