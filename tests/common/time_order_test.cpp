#include "common/time_order.h"

#include <gtest/gtest.h>

namespace bookgrasp {
namespace {

TEST(TimeOrder, NextStaleAndRestart) {
  TimeOrderGuard g(1000000);
  EXPECT_EQ(g.check(5000000), TimeOrder::kNext);
  EXPECT_EQ(g.check(5010000), TimeOrder::kNext);
  EXPECT_EQ(g.check(5010000), TimeOrder::kStale) << "a repeated time";
  EXPECT_EQ(g.check(4500000), TimeOrder::kStale) << "0.51 s back: reordering, not a restart";
  EXPECT_EQ(g.last(), 5010000) << "stale times change nothing";
  EXPECT_NE(g.describe(4500000, TimeOrder::kStale).find("not after the previous 5010000"), std::string::npos);
  EXPECT_EQ(g.check(20000), TimeOrder::kRestarted) << "4.99 s back: the source restarted";
  EXPECT_NE(g.describe(20000, TimeOrder::kRestarted).find("4990 ms before the previous 5010000"), std::string::npos);
  EXPECT_EQ(g.check(30000), TimeOrder::kNext) << "after a restart the new clock is followed";
  EXPECT_EQ(g.check(25000), TimeOrder::kStale);
}

}  // namespace
}  // namespace bookgrasp
