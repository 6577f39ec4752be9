// P1 over several still frames (services/arbiter/p1_frames.h): the per-axis median, worked out by hand.
#include <gtest/gtest.h>

#include <stdexcept>

#include "services/arbiter/p1_frames.h"

using namespace bookgrasp;

TEST(P1Frames, OneFrameIsTheLatestFramesP1) {
  P1Frames w(1);
  EXPECT_FALSE(w.full());
  EXPECT_FALSE(w.p1());
  w.add(Eigen::Vector3d(1, 2, 3));
  ASSERT_TRUE(w.p1());
  EXPECT_EQ(*w.p1(), Eigen::Vector3d(1, 2, 3));
  w.add(std::nullopt);
  EXPECT_TRUE(w.full());
  EXPECT_FALSE(w.p1());  // BwS found nothing in the latest frame
}

TEST(P1Frames, ACornerThatClimbedInOneFrameOfFiveDoesNotMoveTheMedian) {
  // X is the height: four frames at the corner (0.300 +- 3 mm), one 55 mm above it (a climb onto a neighbour).
  P1Frames w(5);
  w.add(Eigen::Vector3d(0.80, -0.10, 0.301));
  w.add(Eigen::Vector3d(0.80, -0.10, 0.355));
  w.add(Eigen::Vector3d(0.81, -0.09, 0.298));
  w.add(Eigen::Vector3d(0.79, -0.11, 0.303));
  EXPECT_FALSE(w.p1()) << "four frames are not five";
  w.add(Eigen::Vector3d(0.80, -0.10, 0.300));
  ASSERT_TRUE(w.p1());
  EXPECT_NEAR(w.p1()->x(), 0.80, 1e-12);
  EXPECT_NEAR(w.p1()->y(), -0.10, 1e-12);
  EXPECT_NEAR(w.p1()->z(), 0.301, 1e-12);
}

TEST(P1Frames, FramesWithoutP1AreLeftOutUnlessTheyAreHalf) {
  P1Frames w(4);
  w.add(Eigen::Vector3d(0, 0, 1));
  w.add(std::nullopt);
  w.add(Eigen::Vector3d(0, 0, 2));
  w.add(Eigen::Vector3d(0, 0, 4));
  ASSERT_TRUE(w.p1());
  EXPECT_DOUBLE_EQ(w.p1()->z(), 2);  // the median of 1, 2, 4
  w.add(std::nullopt);               // drops (0, 0, 1): 2, 4 found of 4
  EXPECT_FALSE(w.p1()) << "two found of four is not more than half";
  w.add(Eigen::Vector3d(0, 0, 3));  // drops the first nullopt: 2, 4, 3 of 4
  ASSERT_TRUE(w.p1());
  EXPECT_DOUBLE_EQ(w.p1()->z(), 3);
}

TEST(P1Frames, AnEvenCountTakesTheMeanOfTheMiddleTwo) {
  P1Frames w(2);
  w.add(Eigen::Vector3d(0, 1, 2));
  w.add(Eigen::Vector3d(2, 3, 6));
  ASSERT_TRUE(w.p1());
  EXPECT_EQ(*w.p1(), Eigen::Vector3d(1, 2, 4));
}

TEST(P1Frames, ClearForgetsTheFramesAndZeroFramesIsRefused) {
  P1Frames w(2);
  w.add(Eigen::Vector3d(0, 1, 2));
  w.add(Eigen::Vector3d(0, 1, 2));
  w.clear();
  EXPECT_EQ(w.size(), 0);
  EXPECT_FALSE(w.p1());
  EXPECT_THROW(P1Frames(0), std::invalid_argument);
}
