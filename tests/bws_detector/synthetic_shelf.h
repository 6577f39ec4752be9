#pragma once
/// @file
/// Test helper: an analytic book-cart scene (boxes) rendered by ray casting
/// into exact depth, face-id (ground-truth segmentation) and textured
/// intensity images for a pinhole stereo pair. The scene's geometry is known
/// to the test (it built it); the detector only gets the images, the camera
/// and the upper-shelf volume, never the truth.

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

namespace bookgrasp::bws::test {

/// An oriented box.
struct Box {
  /// Box centre and axes in base.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  /// Half sizes along the box axes.
  Eigen::Vector3d half = Eigen::Vector3d::Zero();
  /// Grey level of the surface (0..1) and texture seed.
  float albedo = 0.5f;
  /// Seed of the value-noise texture.
  uint32_t seed = 1;
};

/// A pinhole camera (optical frame x right, y down, z forward).
struct PinholeCamera {
  /// Image size.
  int width = 640;
  /// See width.
  int height = 480;
  /// Intrinsics in pixels.
  double fx = 0, fy = 0, cx = 0, cy = 0;
  /// Optical frame in base.
  Eigen::Isometry3d in_base = Eigen::Isometry3d::Identity();
};

/// What a render gives.
struct RenderOutput {
  /// z depth in metres (CV_32F), NaN where the ray hits nothing.
  cv::Mat depth;
  /// Ground-truth surface id (CV_32S): box index * 6 + face + 1, 0 = nothing.
  cv::Mat face_id;
  /// Textured, shaded grey image (CV_8U), only if asked.
  cv::Mat intensity;
};

/// Ray-casts `boxes` with `camera` (pixel centres). If `intensity` is true, also
/// a textured image supersampled ss x ss.
RenderOutput render_boxes(const std::vector<Box>& boxes, const PinholeCamera& camera, bool intensity, int ss = 2);

/// A cart with an upper shelf and books, and what the test knows about it.
struct ShelfScene {
  /// All boxes (cart boards first, then the books from right to left).
  std::vector<Box> boxes;
  /// Index of the first book in `boxes`.
  int first_book = 0;
  /// Number of books.
  int num_books = 0;
  /// Cart frame in base: x = into the shelf (away from the robot), y = left, z = up; origin at the
  /// middle of the front edge of the upper shelf board's top surface.
  Eigen::Isometry3d cart_in_base = Eigen::Isometry3d::Identity();
  /// Upper-shelf volume: box pose in base and half extents (axes as the cart's).
  Eigen::Isometry3d shelf_box_in_base = Eigen::Isometry3d::Identity();
  /// See shelf_box_in_base.
  Eigen::Vector3d shelf_half_extent = Eigen::Vector3d::Zero();
  /// True upper-right front corner of the right-most book, base frame.
  Eigen::Vector3d true_corner_base = Eigen::Vector3d::Zero();
  /// Box index of the right-most book; its front face id = index * 6 + face_front + 1.
  int rightmost_book = 0;
  /// Left stereo camera and baseline.
  PinholeCamera left;
  /// Right camera = left shifted by baseline along its x axis.
  PinholeCamera right;
  /// Stereo baseline in metres.
  double baseline_m = 0.12;
};

/// Face index of a box: 0:-x 1:+x 2:-y 3:+y 4:-z 5:+z (box frame). For books and the cart, -x faces the robot.
constexpr int kFaceMinusX = 0;

/// A seeded random scene: cart yaw +-4 deg, 8..14 books alternating portrait
/// (height 0.21..0.26, depth 0.15..0.19 m) and landscape (height 0.15..0.19,
/// depth 0.21..0.26 m), 1..3.5 cm thick, pushed against the rear board, gaps 0..3 mm (with
/// `fronts_at_the_edge`, the same books with their fronts 1 cm behind the shelf's front edge, as on the
/// simulated cart). Stereo camera ~1.4 m from the shelf, 640x480, fovy 45 deg, baseline 0.12 m.
ShelfScene make_shelf_scene(uint32_t seed, bool fronts_at_the_edge = false);

/// Exact disparity f B / z of a depth image (NaN where depth is NaN).
cv::Mat exact_disparity(const cv::Mat& depth, double fx, double baseline_m);

}  // namespace bookgrasp::bws::test
