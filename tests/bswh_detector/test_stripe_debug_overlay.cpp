// Tests of the BSwH debug picture on hand-made detections.
#include <cstdlib>

#include <gtest/gtest.h>

#include "services/bswh_detector/stripe_debug_overlay.h"

namespace bookgrasp {
namespace {

StripeDetection horizontal_stripe_ending_at_200() {
  StripeDetection d;
  d.found = d.end_found = true;
  d.line_start = cv::Point2d(200, 300);
  d.line_end = cv::Point2d(600, 300);
  d.end = d.line_start;
  d.thickness_px = 20;
  return d;
}

// Anti-aliased lines: a colour within 60 per channel.
::testing::AssertionResult near(const cv::Vec3b& got, const cv::Vec3b& want) {
  for (int c = 0; c < 3; ++c)
    if (std::abs(int(got[c]) - int(want[c])) > 60)
      return ::testing::AssertionFailure() << "got " << got << " want about " << want;
  return ::testing::AssertionSuccess();
}

TEST(StripeDebugOverlay, CentreLineBandAndEndAreDrawn) {
  const cv::Mat black(480, 640, CV_8UC3, cv::Scalar(0, 0, 0));
  const cv::Mat o = draw_bswh_overlay(black, horizontal_stripe_ending_at_200(), "t");
  ASSERT_EQ(o.type(), CV_8UC3);
  EXPECT_TRUE(near(o.at<cv::Vec3b>(300, 400), cv::Vec3b(255, 0, 255)));      // centre line: magenta
  EXPECT_TRUE(near(o.at<cv::Vec3b>(290, 400), cv::Vec3b(255, 160, 255)));    // band border half a thickness up
  EXPECT_TRUE(near(o.at<cv::Vec3b>(310, 400), cv::Vec3b(255, 160, 255)));    // ... and down
  EXPECT_TRUE(near(o.at<cv::Vec3b>(300 - 6, 200), cv::Vec3b(255, 40, 40)));  // the end's cross, vertical arm
  EXPECT_EQ(o.at<cv::Vec3b>(250, 400), cv::Vec3b(0, 0, 0));                  // elsewhere untouched
}

TEST(StripeDebugOverlay, NotFoundDrawsOnlyTheCaptionFromAGreyImage) {
  StripeDetection none;
  none.failure_reason = "no dark band";
  const cv::Mat grey(480, 640, CV_8UC1, cv::Scalar(90));
  const cv::Mat o = draw_bswh_overlay(grey, none, "t");
  ASSERT_EQ(o.type(), CV_8UC3);
  EXPECT_EQ(o.at<cv::Vec3b>(300, 400), cv::Vec3b(90, 90, 90));
  cv::Mat diff;
  cv::absdiff(o.rowRange(0, 40), cv::Mat(40, 640, CV_8UC3, cv::Scalar(90, 90, 90)), diff);
  EXPECT_GT(cv::countNonZero(diff.reshape(1)), 100);
}

}  // namespace
}  // namespace bookgrasp
