// SimLibrarian (services/sim_world/sim_librarian.h): when the simulated librarian acts, in simulation time.
// Its effect on the world (the book moved, USER_EVENT "taken") is tested on the node (sim_world_node_test.cpp).
#include "services/sim_world/sim_librarian.h"

#include <gtest/gtest.h>

#include <string>
#include <utility>

namespace bookgrasp {
namespace {

TEST(SimLibrarian, ActsOncePerVisitAfterItsDelayAndNotWhenDisabled) {
  SimLibrarianParams p;
  p.take_after_s = 2.0;
  SimLibrarian l(p);
  EXPECT_FALSE(l.due(0));
  l.on_task_state("WAIT_BOOK_TAKEN", 1000000);
  EXPECT_FALSE(l.due(2900000));
  EXPECT_TRUE(l.due(3000000));
  EXPECT_FALSE(l.due(4000000));
  l.on_task_state("PARK", 5000000);
  l.on_task_state("WAIT_BOOK_TAKEN", 9000000);  // the next tall book
  EXPECT_FALSE(l.due(10000000));
  EXPECT_TRUE(l.due(11000000));
  p.enabled = false;
  SimLibrarian off(p);
  off.on_task_state("WAIT_BOOK_TAKEN", 0);
  EXPECT_FALSE(off.due(100000000));
}

TEST(SimLibrarian, BadConfigValuesNameTheKey) {
  for (const auto& [yaml, key] :
       {std::pair<std::string, std::string>{"librarian: {enabled: true, take_after_s: -1}", "librarian.take_after_s"},
        {"librarian: {take_after_s: 2}", "librarian.enabled"},
        {"librarian: {enabled: maybe, take_after_s: 2}", "librarian.enabled"}}) {
    try {
      SimLibrarianParams::from_config(Config::from_string(yaml));
      ADD_FAILURE() << yaml << " was accepted";
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
  EXPECT_NO_THROW(SimLibrarianParams::from_config(Config::from_string("librarian: {enabled: false, take_after_s: 0}")));
}

}  // namespace
}  // namespace bookgrasp
