// Tests of the sim_world component on an in-process bus (services/sim_world/sim_world_node.h).
#include "services/sim_world/sim_world_node.h"

#include <cmath>

#include <gtest/gtest.h>

#include "common/composition.h"

using namespace bookgrasp;

namespace {
SimWorldSettings settings() {
  const Config cfg = Config::load_file(std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/sim_world.yaml");
  SimWorldSettings s = SimWorldSettings::from_config(cfg);
  s.drive = "external";
  return s;
}

struct Sink {
  std::vector<sim_state_t> states;
  void on_state(const lcm::ReceiveBuffer*, const std::string&, const sim_state_t* m) { states.push_back(*m); }
};
}  // namespace

TEST(SimWorldNode, ConfigFileIsCompleteAndValid) {
  const Config cfg = Config::load_file(std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/sim_world.yaml");
  const SimWorldSettings s = SimWorldSettings::from_config(cfg);
  ServiceSettings::from_config(cfg);
  EXPECT_NO_THROW(cfg.require_all_read());
  EXPECT_EQ(s.sim_state_channel, "SIM_STATE");
  EXPECT_EQ(s.timing.epoch_utime, 1000000000000000);
}

TEST(SimWorldNode, ComposedModePublishesAndRejectsBadSetpoints) {
  Composition comp;
  auto node = std::make_unique<SimWorldNode>(settings());
  SimWorldNode& n = comp.add(std::move(node));
  Sink sink;
  comp.bus().subscribe("SIM_STATE", &Sink::on_state, &sink);

  arm_setpoint_t bad;
  bad.utime = 1000000000000000;
  bad.num_joints = 3;
  bad.positions = {0, 0, 0};
  bad.velocities = {0, 0, 0};
  comp.bus().publish("ARM_SETPOINT", &bad);
  gripper_setpoint_t g;
  g.utime = bad.utime;
  g.width_m = std::nan("");
  g.max_force_n = 10;
  comp.bus().publish("GRIPPER_SETPOINT", &g);
  comp.spin();
  EXPECT_EQ(n.rejected_total(), 2);
  EXPECT_NE(n.last_error().find("width_m"), std::string::npos) << n.last_error();

  n.advance_to(1000000000000000 + 50000);
  comp.spin();
  ASSERT_EQ(sink.states.size(), 6u);
  EXPECT_EQ(sink.states.back().utime, 1000000000000000 + 50000);
  EXPECT_EQ(n.outputs().at("SIM_GROUND_TRUTH").count, 1);
}
