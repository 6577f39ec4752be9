#include "common/scene/textures.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

extern "C" {
#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>
}

namespace bookgrasp::scene {

namespace {
cv::Vec3b to_px(const Eigen::Vector3d& rgb) {
  return cv::Vec3b(static_cast<uint8_t>(std::clamp(rgb[0], 0.0, 1.0) * 255.0 + 0.5),
                   static_cast<uint8_t>(std::clamp(rgb[1], 0.0, 1.0) * 255.0 + 0.5),
                   static_cast<uint8_t>(std::clamp(rgb[2], 0.0, 1.0) * 255.0 + 0.5));
}
}  // namespace

cv::Mat page_edge_texture(const Book& book, const RenderSettings& render) {
  const double ppm = render.page_px_per_mm;
  const int cols = std::max(8, static_cast<int>(std::lround(book.width_m * 1000.0 * ppm)));
  const int rows = std::max(8, static_cast<int>(std::lround(book.height_m * 1000.0 * ppm)));
  Rng rng(book.texture_seed);
  // Per-column darkness: page lines (every column is ~1/ppm mm), a few deeper gaps.
  std::vector<double> col_factor(cols);
  for (int c = 0; c < cols; ++c) {
    double f = 1.0 - render.page_line_contrast * rng.uniform01();
    if (rng.bernoulli(0.08)) f -= render.page_line_contrast * 1.5;
    col_factor[c] = f;
  }
  // Cover edges: ~1 mm of cover colour on both sides (hard covers).
  const int cover_px = std::max(1, static_cast<int>(std::lround(1.0 * ppm)));
  cv::Mat img(rows, cols, CV_8UC3);
  for (int r = 0; r < rows; ++r) {
    const double row_noise = 1.0 + 0.015 * (rng.uniform01() - 0.5);
    for (int c = 0; c < cols; ++c) {
      Eigen::Vector3d rgb;
      if (c < cover_px || c >= cols - cover_px) {
        rgb = book.cover_rgb;
      } else {
        rgb = book.page_rgb * (col_factor[c] * row_noise);
      }
      img.at<cv::Vec3b>(r, c) = to_px(rgb);
    }
  }
  // Slightly darker top and bottom page ends (dust, shading), 2 mm.
  const int band = std::max(1, static_cast<int>(2.0 * ppm));
  for (int r = 0; r < band && r < rows; ++r)
    for (int c = cover_px; c < cols - cover_px; ++c) {
      img.at<cv::Vec3b>(r, c) *= 0.93;
      img.at<cv::Vec3b>(rows - 1 - r, c) *= 0.93;
    }
  // Stamps: u = 0 at the right side (column 0), v = 0 at the top.
  for (const Stamp& st : book.stamps) {
    const cv::Point centre(static_cast<int>(st.u * cols), static_cast<int>(st.v * rows));
    const int radius = std::max(2, static_cast<int>(st.diameter_m * 500.0 * ppm));
    cv::Mat layer = img.clone();
    const cv::Vec3b ink = to_px(st.rgb);
    const cv::Scalar colour(ink[0], ink[1], ink[2]);
    const int thick = std::max(1, radius / 7);
    if (st.round) {
      cv::circle(layer, centre, radius, colour, thick, cv::LINE_AA);
      cv::circle(layer, centre, radius * 2 / 3, colour, std::max(1, thick / 2), cv::LINE_AA);
    } else {
      cv::rectangle(layer, centre - cv::Point(radius, radius * 2 / 3), centre + cv::Point(radius, radius * 2 / 3),
                    colour, thick, cv::LINE_AA);
    }
    // Text-like marks inside.
    for (int k = 0; k < 3; ++k) {
      const int y = centre.y + (k - 1) * radius / 3;
      const int half = static_cast<int>(radius * rng.uniform(0.3, 0.55));
      cv::line(layer, {centre.x - half, y}, {centre.x + half, y}, colour, std::max(1, thick / 2), cv::LINE_AA);
    }
    cv::addWeighted(layer, 0.8, img, 0.2, 0.0, img);
  }
  return img;
}

cv::Mat apriltag_texture(int id, int px_per_cell) {
  apriltag_family_t* fam = tag36h11_create();
  if (id < 0 || id >= static_cast<int>(fam->ncodes)) {
    const int n = static_cast<int>(fam->ncodes);
    tag36h11_destroy(fam);
    throw std::invalid_argument("tag36h11 id " + std::to_string(id) + " out of range 0.." + std::to_string(n - 1));
  }
  image_u8_t* im = apriltag_to_image(fam, id);
  cv::Mat small(im->height, im->width, CV_8UC1);
  for (int r = 0; r < im->height; ++r)
    for (int c = 0; c < im->width; ++c) small.at<uint8_t>(r, c) = im->buf[r * im->stride + c];
  // image_u8_destroy is not exported by Debian's libapriltag: free as it does.
  free(im->buf);
  free(im);
  tag36h11_destroy(fam);
  cv::Mat big;
  cv::resize(small, big, cv::Size(), px_per_cell, px_per_cell, cv::INTER_NEAREST);
  cv::Mat rgb;
  cv::cvtColor(big, rgb, cv::COLOR_GRAY2RGB);
  return rgb;
}

}  // namespace bookgrasp::scene
