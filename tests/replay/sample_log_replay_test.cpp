// Replay of the committed sample recording (logs/samples/system_jpeg.lcm, made by
// deploy/make_sample_log.sh from the real running system) through the production services:
// with their shipped configuration the outputs are identical bit for bit; with a changed
// parameter the report shows what moved.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>

#include "services/replay/component_registry.h"
#include "services/replay/output_diff.h"
#include "services/replay/replay_runner.h"

namespace bookgrasp {
namespace {

const std::string kSample = std::string(BOOKGRASP_SOURCE_DIR) + "/logs/samples/system_jpeg.lcm";
// Wall-clock timing fields are the only ones that are not reproducible.
const std::set<std::string> kTiming = {"processing_ms", "disparity_ms", "segmentation_ms", "total_ms"};

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

INSTANTIATE_TEST_SUITE_P(Detectors, SampleReplay,
                         testing::Values("marker_detector", "bwh_detector", "bswh_detector"));

TEST(SampleReplay, ChangedParameterIsReported) {
  // bswh_detector with a different stripe threshold: the stripe outputs move and the report says where.
  std::ifstream in(std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/bswh_detector.yaml");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string changed = std::regex_replace(ss.str(), std::regex("dark_ratio: 0\\.5"), "dark_ratio: 0.8");
  ASSERT_NE(changed, ss.str());
  const std::string path = testing::TempDir() + "/bswh_changed.yaml";
  std::ofstream(path) << changed;
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
