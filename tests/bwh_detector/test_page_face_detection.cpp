// page_faces (services/bwh_detector/page_face_detection.h) on synthetic views whose answer is known by
// construction: page-coloured fore-edges (bright, unsaturated) on a saturated brown backdrop, the plates' band at
// the bottom. Rendered views are tested in the closed loop (tests/visual_servo/test_servo_closed_loop).
#include "services/bwh_detector/page_face_detection.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace bookgrasp {
namespace {

const cv::Scalar kPages(200, 195, 185);   // RGB: S ~ 19, V 200
const cv::Scalar kBackdrop(120, 90, 60);  // S ~ 127: wood

cv::Mat backdrop() {
  return cv::Mat(480, 640, CV_8UC3, kBackdrop);
}

/// A fore-edge from column x0 to x1 (inclusive) and from row `top` down to the image's bottom.
void fore_edge(cv::Mat& img, int x0, int x1, int top) {
  cv::rectangle(img, cv::Point(x0, top), cv::Point(x1, img.rows - 1), kPages, cv::FILLED);
}

const BookCandidate* rightmost_accepted(const BookDetection& d) {
  return d.ranking.empty() ? nullptr : &d.candidates[static_cast<size_t>(d.ranking.front())];
}

TEST(PageFaces, ALoneForeEdgeGivesItsTopRightCorner) {
  cv::Mat img = backdrop();
  fore_edge(img, 300, 379, 300);
  const BookDetection d = detect_books_page_faces(img, PageFaceParams{});
  ASSERT_TRUE(d.found) << d.failure_reason;
  const BookCandidate* c = rightmost_accepted(d);
  ASSERT_NE(c, nullptr);
  EXPECT_NEAR(c->corner_r.x, 380.0, 1.0);  // the boundary right of column 379
  EXPECT_NEAR(c->corner_r.y, 300.0, 1.0);
}

// far_cart seed 6 (stop 22): a taller neighbour's fore-edge that runs out of the top of the image touches the
// right-most book's in the image. The two are one region; rejecting the region for touching the top border lost
// the right-most book every other frame, and the servo jumped between it and a book further left.
TEST(PageFaces, AForeEdgeTouchingATallerOneThatLeavesTheImageIsKept) {
  cv::Mat img = backdrop();
  fore_edge(img, 60, 99, 340);    // a book further left
  fore_edge(img, 180, 249, 0);    // tall, its top out of view
  fore_edge(img, 250, 342, 368);  // the right-most, touching it
  const BookDetection d = detect_books_page_faces(img, PageFaceParams{});
  ASSERT_TRUE(d.found) << d.failure_reason;
  const BookCandidate* c = rightmost_accepted(d);
  ASSERT_NE(c, nullptr);
  EXPECT_NEAR(c->corner_r.x, 343.0, 1.0);
  EXPECT_NEAR(c->corner_r.y, 368.0, 1.0);
  bool tall_rejected = false;
  for (const BookCandidate& k : d.candidates)
    tall_rejected |= k.reject_reason.find("touches the top border") != std::string::npos && k.bbox.x >= 170 &&
                     k.bbox.x + k.bbox.width <= 255;
  EXPECT_TRUE(tall_rejected) << "the tall fore-edge itself has no top in view";
}

TEST(PageFaces, OnlyAForeEdgeWithoutItsTopIsNotABook) {
  cv::Mat img = backdrop();
  fore_edge(img, 180, 249, 0);
  const BookDetection d = detect_books_page_faces(img, PageFaceParams{});
  EXPECT_FALSE(d.found);
  EXPECT_NE(d.failure_reason.find("top border"), std::string::npos) << d.failure_reason;
}

}  // namespace
}  // namespace bookgrasp
