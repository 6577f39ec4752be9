// SIGINT / SIGTERM become a flag once the handler is installed; the process is not killed.
#include "common/stop_signal.h"

#include <gtest/gtest.h>

#include <csignal>

namespace bookgrasp {
namespace {

TEST(StopSignal, SigtermSetsTheFlagInsteadOfKilling) {
  install_stop_signals();
  EXPECT_FALSE(stop_requested());
  ASSERT_EQ(std::raise(SIGTERM), 0);
  EXPECT_TRUE(stop_requested());  // still running: the handler caught it
  install_stop_signals();         // harmless a second time
  EXPECT_TRUE(stop_requested());
}

}  // namespace
}  // namespace bookgrasp
