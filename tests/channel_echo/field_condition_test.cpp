// Conditions and formatting over flattened messages (an arm_state_t built here, fields known).
#include "services/channel_echo/field_condition.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace bookgrasp {
namespace {

std::vector<FieldValue> arm(int8_t state, const std::string& message) {
  arm_state_t m{};
  m.utime = 5;
  m.num_joints = 1;
  m.joint_names = {"j1"};
  m.positions = {0.5};
  m.velocities = {0.0};
  m.state = state;
  m.message = message;
  std::vector<FieldValue> out;
  flatten(m, "", &out);
  return out;
}

TEST(FieldCondition, NumbersCompareAsNumbers) {
  const auto f = arm(arm_state_t::EXECUTING, "");
  EXPECT_TRUE(FieldCondition::parse("state=1").holds(f));
  EXPECT_TRUE(FieldCondition::parse("state=1.0").holds(f));
  EXPECT_FALSE(FieldCondition::parse("state=2").holds(f));
  EXPECT_TRUE(FieldCondition::parse("state!=2").holds(f));
  EXPECT_FALSE(FieldCondition::parse("state!=1").holds(f));
  EXPECT_TRUE(FieldCondition::parse("positions[0]=0.5").holds(f));
  EXPECT_FALSE(FieldCondition::parse("state=one").holds(f));  // not a number: never equal
}

TEST(FieldCondition, TextComparesAsText) {
  const auto f = arm(arm_state_t::STOPPED, "heartbeat lost");
  EXPECT_TRUE(FieldCondition::parse("message=heartbeat lost").holds(f));
  EXPECT_TRUE(FieldCondition::parse("message!=ok").holds(f));
  EXPECT_TRUE(FieldCondition::parse("message=").holds(arm(0, "")));
}

TEST(FieldCondition, AMissingFieldNeverHolds) {
  const auto f = arm(0, "");
  const auto c = FieldCondition::parse("stat!=1");
  EXPECT_FALSE(c.has_field(f));
  EXPECT_FALSE(c.holds(f));
}

TEST(FieldCondition, MalformedConditionsAreErrors) {
  EXPECT_THROW(FieldCondition::parse("state"), std::invalid_argument);
  EXPECT_THROW(FieldCondition::parse("=1"), std::invalid_argument);
  EXPECT_THROW(FieldCondition::parse("!=1"), std::invalid_argument);
}

TEST(FormatFields, LargeIntegersArePrintedExactly) {
  std::vector<FieldValue> f{{"utime", true, 1000000004530000.0, {}}, {"x", true, -1.25, {}}};
  EXPECT_EQ(format_fields(f, {}), "utime=1000000004530000 x=-1.25");
}

TEST(FormatFields, SelectedFieldsInOrderAndMissingOnesNamed) {
  const auto f = arm(arm_state_t::STOPPED, "stop");
  EXPECT_EQ(format_fields(f, {"message", "state", "nope"}), "message=\"stop\" state=2 nope=<no such field>");
  const std::string all = format_fields(f, {});
  EXPECT_NE(all.find("utime=5 "), std::string::npos) << all;
  EXPECT_NE(all.find("positions[0]=0.5"), std::string::npos) << all;
  EXPECT_NE(all.find("joint_names[0]=\"j1\""), std::string::npos) << all;
}

}  // namespace
}  // namespace bookgrasp
