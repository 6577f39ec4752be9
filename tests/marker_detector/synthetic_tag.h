#pragma once
/// @file
/// Test helper: renders an AprilTag from its family's code bits at a known
/// pose with a pinhole camera (independent of the detector's own code).

#include <array>
#include <cstdint>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <apriltag/apriltag.h>

namespace bookgrasp::test {

/// The tag image (total_width x total_width cells, `cell_px` pixels a cell)
/// drawn from the code bits: white outer ring, black border, data bits.
inline cv::Mat tag_cells_image(const apriltag_family_t* fam, int id, int cell_px) {
  const int n = static_cast<int>(fam->total_width);
  cv::Mat cells(n, n, CV_8UC1, cv::Scalar(0));
  const int white_start = (n - (fam->width_at_border + 2)) / 2;
  const int white_w = fam->width_at_border + 2;
  // White ring just outside the black border (for families without reversed border).
  for (int i = 0; i < white_w; ++i) {
    cells.at<uint8_t>(white_start, white_start + i) = 255;
    cells.at<uint8_t>(white_start + white_w - 1, white_start + i) = 255;
    cells.at<uint8_t>(white_start + i, white_start) = 255;
    cells.at<uint8_t>(white_start + i, white_start + white_w - 1) = 255;
  }
  const int border_start = (n - fam->width_at_border) / 2;
  const uint64_t code = fam->codes[id];
  for (uint32_t i = 0; i < fam->nbits; ++i) {
    if (code & (uint64_t{1} << (fam->nbits - i - 1))) {
      cells.at<uint8_t>(static_cast<int>(fam->bit_y[i]) + border_start,
                        static_cast<int>(fam->bit_x[i]) + border_start) = 255;
    }
  }
  cv::Mat big;
  cv::resize(cells, big, cv::Size(n * cell_px, n * cell_px), 0, 0, cv::INTER_NEAREST);
  return big;
}

/// Draws tag `id` of side `size_m` (outer edge of the black border) at
/// `tag_in_camera` (AprilTag tag frame: x right, y down, z into the tag) into
/// `image` (CV_8UC1) for intrinsics fx, fy, cx, cy (pixel centres at integer
/// coordinates, as OpenCV's projection).
inline void draw_tag(cv::Mat& image, const apriltag_family_t* fam, int id, double size_m,
                     const Eigen::Isometry3d& tag_in_camera, double fx, double fy, double cx, double cy) {
  const int cell_px = 40;
  const cv::Mat tag = tag_cells_image(fam, id, cell_px);
  const double n = fam->total_width;
  const double cell_m = size_m / fam->width_at_border;
  // Tag image pixel (u, v) (centre of pixel index) -> tag plane (X, Y, 1).
  Eigen::Matrix3d a;
  a << cell_m / cell_px, 0, cell_m * (0.5 / cell_px - n / 2.0), 0, cell_m / cell_px,
      cell_m * (0.5 / cell_px - n / 2.0), 0, 0, 1;
  Eigen::Matrix3d k;
  k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
  Eigen::Matrix3d rt;
  rt.col(0) = tag_in_camera.linear().col(0);
  rt.col(1) = tag_in_camera.linear().col(1);
  rt.col(2) = tag_in_camera.translation();
  const Eigen::Matrix3d h = k * rt * a;
  cv::Mat hcv(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) hcv.at<double>(r, c) = h(r, c);
  cv::Mat mask(tag.size(), CV_8UC1, cv::Scalar(255));
  cv::Mat warped, warped_mask;
  // Supersample x4 to anti-alias the edges like a real sensor.
  const double ss = 4.0;
  cv::Mat s = (cv::Mat_<double>(3, 3) << ss, 0, (ss - 1) / 2, 0, ss, (ss - 1) / 2, 0, 0, 1);
  cv::Mat hs = s * hcv;
  const cv::Size big(image.cols * 4, image.rows * 4);
  cv::warpPerspective(tag, warped, hs, big, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::warpPerspective(mask, warped_mask, hs, big, cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::Mat up;
  cv::resize(image, up, big, 0, 0, cv::INTER_NEAREST);
  warped.copyTo(up, warped_mask);
  cv::resize(up, image, image.size(), 0, 0, cv::INTER_AREA);
}

}  // namespace bookgrasp::test
