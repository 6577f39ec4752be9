#include "common/lcm_url.h"

#include <gtest/gtest.h>

#include <cstdlib>

namespace bookgrasp {
namespace {

TEST(LcmUrl, PrecedenceAndImageSafeBuffer) {
  ::unsetenv("LCM_DEFAULT_URL");
  EXPECT_EQ(resolve_lcm_url("", ""), kDefaultLcmUrl);
  ::setenv("LCM_DEFAULT_URL", "udpm://239.255.76.67:7700?ttl=0", 1);
  EXPECT_EQ(resolve_lcm_url("", ""), "udpm://239.255.76.67:7700?ttl=0&recv_buf_size=4194304");
  EXPECT_EQ(resolve_lcm_url("", "memq://"), "memq://");
  EXPECT_EQ(resolve_lcm_url("udpm://239.255.76.67:7701", "memq://"),
            "udpm://239.255.76.67:7701?recv_buf_size=4194304");
  EXPECT_EQ(make_image_safe("udpm://1.2.3.4:5?recv_buf_size=100"), "udpm://1.2.3.4:5?recv_buf_size=100");
  ::unsetenv("LCM_DEFAULT_URL");
}

}  // namespace
}  // namespace bookgrasp
