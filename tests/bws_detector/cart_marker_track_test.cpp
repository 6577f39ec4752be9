// Tests of CartMarkerTrack: pairing by utime, nearest in time, absent markers, restarts, capacity.
#include <gtest/gtest.h>

#include "services/bws_detector/cart_marker_track.h"

namespace bookgrasp::bws {
namespace {

Eigen::Isometry3d at_x(double x) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.translation().x() = x;
  return p;
}

TEST(CartMarkerTrack, EmptyCoversNothingAndHasNoNearest) {
  CartMarkerTrack t;
  EXPECT_FALSE(t.covers(0));
  EXPECT_FALSE(t.nearest(100).has_value());
  EXPECT_TRUE(t.empty());
}

TEST(CartMarkerTrack, TheSameUtimeWinsOverAnEarlierAndALaterOne) {
  CartMarkerTrack t;
  t.add(1000, at_x(1));
  t.add(2000, at_x(2));
  t.add(2100, at_x(3));
  EXPECT_EQ(t.nearest(2000)->utime, 2000);
  EXPECT_DOUBLE_EQ(t.nearest(2000)->cart_in_base.translation().x(), 2.0);
  // Between two: the nearer; on a tie the earlier.
  EXPECT_EQ(t.nearest(1400)->utime, 1000);
  EXPECT_EQ(t.nearest(1600)->utime, 2000);
  EXPECT_EQ(t.nearest(1500)->utime, 1000);
  // Before the first and after the last.
  EXPECT_EQ(t.nearest(10)->utime, 1000);
  EXPECT_EQ(t.nearest(9000)->utime, 2100);
}

TEST(CartMarkerTrack, AMessageWithoutTheCartStillCoversItsUtime) {
  CartMarkerTrack t;
  t.add(1000, at_x(1));
  EXPECT_FALSE(t.covers(2000));
  t.add(2000, std::nullopt);
  EXPECT_TRUE(t.covers(2000));
  EXPECT_FALSE(t.covers(2001));
  EXPECT_EQ(t.nearest(2000)->utime, 1000);  // the cart was not seen at 2000
  // An older message arriving late does not move the covered time back.
  t.add(1500, at_x(5));
  EXPECT_TRUE(t.covers(2000));
  EXPECT_EQ(t.nearest(1600)->utime, 1500);
}

TEST(CartMarkerTrack, AClockThatStartsOverForgetsTheOldTimeline) {
  CartMarkerTrack t;
  t.add(50000000, at_x(1));
  t.add(50000000 - CartMarkerTrack::kRestartUtime + 1, at_x(2));  // within a second: late, not a restart
  EXPECT_EQ(t.nearest(0)->utime, 50000000 - CartMarkerTrack::kRestartUtime + 1);
  t.add(2000, at_x(3));  // 50 s earlier: the source restarted
  EXPECT_EQ(t.nearest(60000000)->utime, 2000);
  EXPECT_TRUE(t.covers(2000));
  EXPECT_FALSE(t.covers(3000));
}

TEST(CartMarkerTrack, KeepsAtMostItsCapacityDroppingTheOldest) {
  CartMarkerTrack t(3);
  for (int i = 1; i <= 5; ++i) t.add(i * 1000, at_x(i));
  EXPECT_EQ(t.nearest(0)->utime, 3000);
  t.clear();
  EXPECT_TRUE(t.empty());
  EXPECT_FALSE(t.covers(0));
}

}  // namespace
}  // namespace bookgrasp::bws
