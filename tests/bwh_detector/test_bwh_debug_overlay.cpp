// Tests of the BwH debug picture on hand-made detections: what is drawn where, in which colour.
#include <gtest/gtest.h>

#include "services/bwh_detector/bwh_debug_overlay.h"

namespace bookgrasp {
namespace {

BookCandidate candidate(int id, cv::Rect box, bool accepted) {
  BookCandidate c;
  c.id = id;
  c.bbox = box;
  c.corner_r = cv::Point2d(box.x + box.width - 1, box.y);
  c.width_px = box.width;
  c.accepted = accepted;
  c.reject_reason = accepted ? "" : "too narrow";
  return c;
}

BookDetection two_books_and_a_reject() {
  BookDetection d;
  d.found = true;
  d.candidates = {candidate(0, {100, 200, 40, 150}, true), candidate(1, {300, 210, 50, 140}, true),
                  candidate(2, {450, 220, 8, 100}, false)};
  d.ranking = {1, 0};
  return d;
}

cv::Vec3b at(const cv::Mat& m, int x, int y) {
  return m.at<cv::Vec3b>(y, x);
}

TEST(BwhDebugOverlay, TheReportedBookIsRedTheOtherAcceptedGreenRejectsGrey) {
  const cv::Mat grey(480, 640, CV_8UC1, cv::Scalar(0));
  const cv::Mat o = draw_bwh_overlay(grey, two_books_and_a_reject(), 0, "t");
  ASSERT_EQ(o.type(), CV_8UC3);
  ASSERT_EQ(o.size(), grey.size());
  // Left edges of the boxes, half-way down (away from crosses, slope lines and labels).
  EXPECT_EQ(at(o, 300, 280), cv::Vec3b(255, 40, 40));    // rank 0 = candidate 1: red
  EXPECT_EQ(at(o, 100, 275), cv::Vec3b(40, 220, 40));    // candidate 0: green
  EXPECT_EQ(at(o, 450, 270), cv::Vec3b(170, 170, 170));  // rejected: grey
  // R of the reported book (349, 210) is marked: the cross' vertical arm above the box.
  EXPECT_GT(at(o, 349, 205)[0], 200);
  EXPECT_LT(at(o, 349, 205)[1], 100);
  EXPECT_EQ(at(o, 340, 205), cv::Vec3b(0, 0, 0));
}

TEST(BwhDebugOverlay, AnotherRankMovesTheRedBox) {
  const cv::Mat rgb(480, 640, CV_8UC3, cv::Scalar(0, 0, 0));
  const cv::Mat o = draw_bwh_overlay(rgb, two_books_and_a_reject(), 1, "t");
  EXPECT_EQ(at(o, 100, 275), cv::Vec3b(255, 40, 40));
  EXPECT_EQ(at(o, 300, 280), cv::Vec3b(40, 220, 40));
}

TEST(BwhDebugOverlay, NoBookLeavesTheImageButTheCaptionAndDoesNotTouchTheInput) {
  BookDetection none;
  none.failure_reason = "no region passes the book criteria";
  const cv::Mat rgb(480, 640, CV_8UC3, cv::Scalar(10, 20, 30));
  const cv::Mat o = draw_bwh_overlay(rgb, none, 0, "t");
  EXPECT_EQ(rgb.at<cv::Vec3b>(10, 10), cv::Vec3b(10, 20, 30));
  // Below the two caption lines nothing is drawn.
  cv::Mat diff;
  cv::absdiff(o.rowRange(40, 480), rgb.rowRange(40, 480), diff);
  EXPECT_EQ(cv::countNonZero(diff.reshape(1)), 0);
  cv::absdiff(o.rowRange(0, 40), rgb.rowRange(0, 40), diff);
  EXPECT_GT(cv::countNonZero(diff.reshape(1)), 100);
}

}  // namespace
}  // namespace bookgrasp
