#include "common/config.h"

#include <gtest/gtest.h>

#include <fstream>

namespace bookgrasp {
namespace {

const char* kYaml = R"(
service:
  name: demo
  rate_hz: 10.5
  count: 3
stereo:
  num_disparities: 64
  mode: bm
  offsets: [0.1, 0.2, 0.3]
)";

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(Config, ReadsTypedValues) {
  const Config c = Config::from_string(kYaml, "test.yaml");
  EXPECT_EQ(c.get<std::string>("service.name"), "demo");
  EXPECT_DOUBLE_EQ(c.get<double>("service.rate_hz"), 10.5);
  EXPECT_EQ(c.get<int>("service.count"), 3);
  const Config s = c.child("stereo");
  EXPECT_EQ(s.get_int("num_disparities", 16, 256), 64);
  EXPECT_EQ(s.get_choice("mode", {"bm", "sgbm"}), "bm");
  EXPECT_EQ(s.get_vector("offsets", 3), (std::vector<double>{0.1, 0.2, 0.3}));
}

TEST(Config, MissingKeyNamesTheKeyAndFile) {
  const Config c = Config::from_string(kYaml, "test.yaml");
  const std::string e = error_of([&] { c.child("stereo").get<int>("block_size"); });
  EXPECT_NE(e.find("'stereo.block_size'"), std::string::npos) << e;
  EXPECT_NE(e.find("test.yaml"), std::string::npos) << e;
  EXPECT_NE(e.find("missing"), std::string::npos) << e;
}

TEST(Config, WrongTypeAndRangeAndChoice) {
  const Config c = Config::from_string(kYaml, "test.yaml");
  EXPECT_NE(error_of([&] { c.get<int>("stereo.mode"); }).find("wrong type"), std::string::npos);
  EXPECT_NE(error_of([&] { c.get_int("stereo.num_disparities", 1, 16); }).find("out of range"), std::string::npos);
  EXPECT_NE(error_of([&] { c.get_choice("stereo.mode", {"sgbm"}); }).find("not one of"), std::string::npos);
  EXPECT_NE(error_of([&] { c.get_vector("stereo.offsets", 2); }).find("list of 2"), std::string::npos);
  EXPECT_NE(error_of([&] { c.child("service.name"); }).find("mapping"), std::string::npos);
}

TEST(Config, ChannelNamesMustBeNonEmptyWithoutSpaces) {
  const Config c = Config::from_string("channels: {a: STEREO_IMAGES, b: \"\", c: \"MY CH\"}", "ch.yaml");
  EXPECT_EQ(c.get_channel("channels.a"), "STEREO_IMAGES");
  const std::string empty = error_of([&] { c.get_channel("channels.b"); });
  EXPECT_NE(empty.find("channels.b"), std::string::npos) << empty;
  EXPECT_NE(empty.find("must not be empty"), std::string::npos) << empty;
  const std::string spaced = error_of([&] { c.get_channel("channels.c"); });
  EXPECT_NE(spaced.find("no spaces"), std::string::npos) << spaced;
  EXPECT_NE(error_of([&] { c.get_channel("channels.d"); }).find("missing"), std::string::npos);
}

TEST(Config, NonFiniteNumbersRejected) {
  const Config c = Config::from_string("a: .nan\nb: .inf\n", "nan.yaml");
  EXPECT_NE(error_of([&] { c.get<double>("a"); }).find("finite"), std::string::npos);
  EXPECT_NE(error_of([&] { c.get<double>("b"); }).find("finite"), std::string::npos);
}

TEST(Config, UnknownKeysAreReportedAsTypos) {
  const Config c = Config::from_string(kYaml, "test.yaml");
  c.get<std::string>("service.name");
  c.get<double>("service.rate_hz");
  c.get<int>("service.count");
  c.child("stereo").mark_read("offsets");
  c.get<int>("stereo.num_disparities");
  const auto unused = c.unused_keys();
  ASSERT_EQ(unused.size(), 1u);
  EXPECT_EQ(unused[0], "stereo.mode");
  EXPECT_NE(error_of([&] { c.require_all_read(); }).find("'stereo.mode'"), std::string::npos);
  c.get<std::string>("stereo.mode");
  EXPECT_NO_THROW(c.require_all_read());
}

TEST(Config, LookupDoesNotModifyTheTree) {
  const Config c = Config::from_string(kYaml, "test.yaml");
  EXPECT_FALSE(c.has("stereo.nothing"));
  EXPECT_FALSE(c.has("service.name.deeper"));
  const std::string before = c.dump();
  error_of([&] { c.get<int>("a.b.c"); });
  EXPECT_EQ(c.dump(), before);
}

TEST(Config, BadFilesFailWithTheirName) {
  EXPECT_NE(error_of([] { Config::load_file("/nonexistent/x.yaml"); }).find("/nonexistent/x.yaml"),
            std::string::npos);
  EXPECT_NE(error_of([] { Config::from_string("a: [1, 2", "broken.yaml"); }).find("broken.yaml"), std::string::npos);
  EXPECT_NE(error_of([] { Config::from_string("- 1\n- 2\n", "list.yaml"); }).find("mapping"), std::string::npos);
  const std::string path = testing::TempDir() + "/config_test.yaml";
  std::ofstream(path) << kYaml;
  EXPECT_EQ(Config::load_file(path).get<int>("service.count"), 3);
}

}  // namespace
}  // namespace bookgrasp
