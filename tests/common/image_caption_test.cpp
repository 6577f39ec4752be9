// Tests of the debug pictures' captions: placement, outline, wrapping at the right edge.
#include "common/image_caption.h"

#include <gtest/gtest.h>

namespace bookgrasp {
namespace {

// Rows [16 * line - 13, 16 * line + 4) hold caption line `line - 1` (baseline at 16 * line).
int changed_pixels_in_line(const cv::Mat& img, int line) {
  const cv::Mat band = img.rowRange(std::max(0, 16 * (line + 1) - 13), 16 * (line + 1) + 4);
  cv::Mat grey;
  cv::extractChannel(band, grey, 0);
  return cv::countNonZero(grey != 100);
}

TEST(ImageCaption, AShortTextTakesOneLine) {
  cv::Mat img(200, 640, CV_8UC3, cv::Scalar(100, 100, 100));
  EXPECT_EQ(draw_caption(&img, 0, "P1 found", cv::Scalar(255, 255, 255)), 1);
  EXPECT_GT(changed_pixels_in_line(img, 0), 50);
  EXPECT_EQ(changed_pixels_in_line(img, 2), 0);
  // White text outlined in black: both are there (the 1 px white stroke is anti-aliased, rarely pure white).
  cv::Mat white, black;
  cv::inRange(img, cv::Scalar(200, 200, 200), cv::Scalar(255, 255, 255), white);  // anti-aliased strokes
  cv::inRange(img, cv::Scalar(0, 0, 0), cv::Scalar(5, 5, 5), black);
  EXPECT_GT(cv::countNonZero(white), 10);
  EXPECT_GT(cv::countNonZero(black), 10);
}

TEST(ImageCaption, ALongTextWrapsAtSpacesAndNothingIsCutOff) {
  cv::Mat img(200, 320, CV_8UC3, cv::Scalar(100, 100, 100));
  const std::string text =
      "no fore-edge passes the book criteria; last: touches the top border (no book top in view) at 12 px";
  const int next = draw_caption(&img, 1, text, cv::Scalar(255, 80, 80));
  EXPECT_GE(next, 4);  // ~600 px of text on 308 px lines
  EXPECT_EQ(changed_pixels_in_line(img, 0), 0);
  for (int l = 1; l < next; ++l) EXPECT_GT(changed_pixels_in_line(img, l), 20) << "line " << l;
  EXPECT_EQ(changed_pixels_in_line(img, next + 1), 0);
  // The last column stays untouched: every piece fits.
  cv::Mat last;
  cv::extractChannel(img.col(img.cols - 1), last, 0);
  EXPECT_EQ(cv::countNonZero(last != 100), 0);
}

TEST(ImageCaption, AWordWiderThanTheImageIsSplit) {
  cv::Mat img(100, 60, CV_8UC3, cv::Scalar(100, 100, 100));
  EXPECT_GE(draw_caption(&img, 0, "BOOK_CORNER_STEREO_AND_MORE", cv::Scalar(255, 255, 255)), 3);
}

}  // namespace
}  // namespace bookgrasp
