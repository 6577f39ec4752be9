#include "common/image_caption.h"

#include <opencv2/imgproc.hpp>

namespace bookgrasp {
namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kScale = 0.45;
constexpr int kMarginPx = 6;
constexpr int kLineHeightPx = 16;

int text_width(const std::string& s) {
  int baseline = 0;
  return cv::getTextSize(s, kFont, kScale, 1, &baseline).width;
}

}  // namespace

int draw_caption(cv::Mat* image, int line, const std::string& text, const cv::Scalar& colour) {
  const int room = image->cols - 2 * kMarginPx;
  std::string rest = text;
  do {
    // The longest prefix that fits, cut at a space when there is one.
    size_t n = rest.size();
    while (n > 1 && text_width(rest.substr(0, n)) > room) {
      const size_t space = rest.rfind(' ', n - 1);
      n = space != std::string::npos && space > 0 ? space : n - 1;
    }
    const cv::Point at(kMarginPx, kLineHeightPx * (line + 1));
    const std::string piece = rest.substr(0, n);
    cv::putText(*image, piece, at, kFont, kScale, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
    cv::putText(*image, piece, at, kFont, kScale, colour, 1, cv::LINE_AA);
    ++line;
    rest = n < rest.size() ? rest.substr(rest[n] == ' ' ? n + 1 : n) : "";
  } while (!rest.empty());
  return line;
}

}  // namespace bookgrasp
