// Command-line overrides of configuration values: applied before validation, only to keys that exist.
#include "common/config_overrides.h"

#include <gtest/gtest.h>

#include "common/config.h"

namespace bookgrasp {
namespace {

const char* kYaml =
    "service:\n  name: a\n  period_s: 1.0\nlimits:\n  joints: [1, 2, 3]\n  enabled: false\nlabel: text\n";

TEST(ConfigOverrides, NoOverridesReturnsTheTextUnchanged) {
  EXPECT_EQ(apply_config_overrides(kYaml, {}, "f.yaml"), kYaml);
}

TEST(ConfigOverrides, ScalarsListsAndNestedKeysAreReplaced) {
  const std::string out = apply_config_overrides(
      kYaml, {"service.period_s=0.25", "limits.joints=[4, 5]", "limits.enabled=true", "label=other words"}, "f.yaml");
  const Config c = Config::from_string(out, "f.yaml");
  EXPECT_DOUBLE_EQ(c.get<double>("service.period_s"), 0.25);
  EXPECT_EQ(c.get<std::vector<int>>("limits.joints"), (std::vector<int>{4, 5}));
  EXPECT_TRUE(c.get<bool>("limits.enabled"));
  EXPECT_EQ(c.get<std::string>("label"), "other words");
  EXPECT_EQ(c.get<std::string>("service.name"), "a");  // untouched
}

TEST(ConfigOverrides, TheLastOverrideOfAKeyWins) {
  const Config c = Config::from_string(apply_config_overrides(kYaml, {"label=x", "label=y"}, "f.yaml"));
  EXPECT_EQ(c.get<std::string>("label"), "y");
}

TEST(ConfigOverrides, AValueEqualsSignStaysInTheValue) {
  const Config c = Config::from_string(apply_config_overrides(kYaml, {"label=a=b"}, "f.yaml"));
  EXPECT_EQ(c.get<std::string>("label"), "a=b");
}

void expect_error(const std::vector<std::string>& ov, const std::string& part) {
  try {
    apply_config_overrides(kYaml, ov, "f.yaml");
    ADD_FAILURE() << "no error for " << ov.front();
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(part), std::string::npos) << what;
    EXPECT_NE(what.find("f.yaml"), std::string::npos) << what;
  }
}

TEST(ConfigOverrides, BadOverridesNameTheProblem) {
  expect_error({"service.period_s"}, "dotted.key=value");
  expect_error({"=3"}, "dotted.key=value");
  expect_error({"service.period_s="}, "dotted.key=value");
  expect_error({"service..period_s=1"}, "empty key part");
  expect_error({"service.perod_s=1"}, "unknown key 'service.perod_s'");
  expect_error({"nosection.key=1"}, "no section 'nosection'");
  expect_error({"label.sub=1"}, "no section 'label'");
  expect_error({"label=[1, 2"}, "not valid YAML");
}

TEST(ConfigOverrides, ABadDocumentIsAnError) {
  EXPECT_THROW(apply_config_overrides("- a\n- b\n", {"a=1"}, "f.yaml"), ConfigError);
  EXPECT_THROW(apply_config_overrides("a: [1,\n", {"a=1"}, "f.yaml"), ConfigError);
}

}  // namespace
}  // namespace bookgrasp
