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

namespace {
struct UserSink {
  std::vector<user_event_t> events;
  void on(const lcm::ReceiveBuffer*, const std::string&, const user_event_t* m) { events.push_back(*m); }
};

std::string place_of(SimWorldNode& n, int id) {
  for (const auto& b : n.world().model().ground_truth(0).books)
    if (b.id == id) return b.place;
  return "?";
}
}  // namespace

// Not in the paper, simulation only: the coordinator leaves a book too tall for the lower shelf on the holder
// (WAIT_BOOK_TAKEN); take_after_s later the librarian has taken it out of the scene and says "taken", once.
TEST(SimWorldNode, TheLibrarianTakesTheBookOffTheHolderAndSaysTaken) {
  Composition comp;
  SimWorldNode& n = comp.add(std::make_unique<SimWorldNode>(settings()));
  UserSink users;
  comp.bus().subscribe("USER_EVENT", &UserSink::on, &users);
  const int64_t t0 = n.world().now_utime();
  // A book lying on its cover on the holder's base plate (top 2 cm above the holder frame's origin).
  const auto& book = n.world().model().scene().books.front();
  const int id = book.id;
  const auto& holder = n.world().model().scene().holder_pose;
  n.world().model().move_book(id, holder * Eigen::Translation3d(0.0, 0.0, 0.02 + book.width_m / 2 + 0.003) *
                                      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()));
  ASSERT_EQ(place_of(n, id), "holder");

  task_status_t st;
  st.utime = t0;
  st.state = "WAIT_USER";
  comp.bus().publish("TASK_STATUS", &st);
  comp.spin();
  n.advance_to(t0 + 3000000);
  comp.spin();
  EXPECT_TRUE(users.events.empty()) << "WAIT_USER is the user's, not the librarian's";
  EXPECT_EQ(place_of(n, id), "holder");

  st.state = "WAIT_BOOK_TAKEN";
  comp.bus().publish("TASK_STATUS", &st);
  comp.spin();
  n.advance_to(n.world().now_utime() + 1500000);  // take_after_s 2.0: not yet
  comp.spin();
  EXPECT_TRUE(users.events.empty());
  n.advance_to(n.world().now_utime() + 600000);
  comp.spin();
  ASSERT_EQ(users.events.size(), 1u);
  EXPECT_EQ(users.events[0].event, "taken");
  EXPECT_NE(users.events[0].detail.find("took book " + std::to_string(id)), std::string::npos)
      << users.events[0].detail;
  EXPECT_EQ(place_of(n, id), "other");
  comp.bus().publish("TASK_STATUS", &st);  // still waiting (the coordinator has not seen "taken" yet): once per visit
  comp.spin();
  n.advance_to(n.world().now_utime() + 3000000);
  comp.spin();
  EXPECT_EQ(users.events.size(), 1u);
}
