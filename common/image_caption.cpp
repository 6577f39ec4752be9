#include "common/image_caption.h"

#include <opencv2/imgproc.hpp>

namespace bookgrasp {

void draw_caption_line(cv::Mat* image, int line, const std::string& text, const cv::Scalar& colour) {
  const cv::Point at(6, 16 + 16 * line);
  cv::putText(*image, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
  cv::putText(*image, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.45, colour, 1, cv::LINE_AA);
}

}  // namespace bookgrasp
