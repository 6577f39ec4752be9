// The top's crease on a ray-cast book seen from above: the true top edge's height is the box's, known to
// the test only; the fit gets the points, the front's plane and the shelf's up direction.
#include "services/bws_detector/top_crease.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "common/config.h"
#include "synthetic_shelf.h"

namespace bookgrasp::bws {
namespace {

constexpr double kPitchDeg = 30.0;  // the camera looks this far below the horizon
constexpr double kFrontX = 0.6;     // the book's front face, metres ahead of the camera (base x)
constexpr double kTopZ = -0.16;     // the book's top face, base z (the camera is at z = 0)
constexpr double kBaseline = 0.12;

/// A book (a box) standing in front of a far wall, seen from above by a camera at the base origin pitched
/// down by kPitchDeg; the points of its depth image (left camera frame).
struct BookFromAbove {
  test::PinholeCamera cam;
  StereoGeometry g;
  cv::Mat disparity, points;   // exact disparity (NaN = nothing hit) and its points
  Eigen::Vector3d normal, up;  // the front's normal (towards the far side) and base z, camera frame
  double offset = 0.0;         // normal . p of the front
  double true_height = 0.0;    // up . p of the top edge
  cv::Mat face_id;             // the render's surface ids (box index * 6 + face + 1; the book is box 0)

  /// A book 4 cm wide; `thin_with_taller_neighbour`: 5 mm wide (5 px), with a book 4 cm taller on its left.
  explicit BookFromAbove(bool thin_with_taller_neighbour = false) {
    cam.fx = cam.fy = 625.0;
    cam.cx = 319.5;
    cam.cy = 239.5;
    const double a = kPitchDeg * M_PI / 180.0;
    Eigen::Matrix3d R;  // columns: the camera's x (right), y (down), z (forward) in base
    R.col(0) = Eigen::Vector3d(0, -1, 0);
    R.col(2) = Eigen::Vector3d(std::cos(a), 0, -std::sin(a));
    R.col(1) = R.col(2).cross(R.col(0));
    cam.in_base.linear() = R;
    std::vector<test::Box> boxes(2);
    // The book, 0.2 deep, its right side at base y = -0.02.
    const double half_width = thin_with_taller_neighbour ? 0.0025 : 0.02;
    boxes[0].pose.translation() = Eigen::Vector3d(kFrontX + 0.1, -0.02 + half_width, (kTopZ - 0.4) / 2);
    boxes[0].half = Eigen::Vector3d(0.1, half_width, (kTopZ + 0.4) / 2);
    boxes[1].pose.translation() = Eigen::Vector3d(1.2, 0.0, -0.5);  // a far wall
    boxes[1].half = Eigen::Vector3d(0.01, 1.0, 1.0);
    if (thin_with_taller_neighbour) {
      test::Box n = boxes[0];
      n.pose.translation() = Eigen::Vector3d(kFrontX + 0.1, -0.015 + 0.02, (kTopZ + 0.04 - 0.4) / 2);
      n.half = Eigen::Vector3d(0.1, 0.02, (kTopZ + 0.04 + 0.4) / 2);
      boxes.push_back(n);
    }
    const test::RenderOutput r = test::render_boxes(boxes, cam, false);
    face_id = r.face_id;
    g = {cam.fx, cam.fy, cam.cx, cam.cy, kBaseline};
    disparity = test::exact_disparity(r.depth, cam.fx, kBaseline);
    points = disparity_to_points(disparity, g);
    normal = R.transpose() * Eigen::Vector3d::UnitX();
    offset = kFrontX;  // the camera sits at the base origin
    up = R.transpose() * Eigen::Vector3d::UnitZ();
    true_height = kTopZ;
  }
  /// The image of the front's top right corner (the book's right side is at base y = -0.02).
  cv::Point corner_px() const {
    const Eigen::Vector3d c = cam.in_base.linear().transpose() * Eigen::Vector3d(kFrontX, -0.02, kTopZ);
    return {int(std::lround(cam.fx * c.x() / c.z() + cam.cx)), int(std::lround(cam.fy * c.y() / c.z() + cam.cy))};
  }
  /// Replaces the points' depth by that of a box-filtered disparity (ksize x ksize), like block matching's
  /// blur of the crease and of the book's borders.
  void blur_disparity(int ksize) {
    cv::Mat d = disparity.clone();
    d.setTo(0.0f, d != d);  // NaN (nothing hit) counts as 0 in the box, as before the points are taken
    cv::blur(d, d, {ksize, ksize});
    points = disparity_to_points(d, g);
  }
  TopCrease fit(cv::Point pi, double start, const TopCreaseParams& p, const cv::Mat& columns = cv::Mat()) const {
    return fit_top_crease(points, g, normal, offset, up, pi, start, columns, p);
  }
};

TopCreaseParams as_shipped() {
  TopCreaseParams p;
  p.enabled = true;
  return p;
}

TEST(TopCrease, FindsTheTopEdgesHeightFromBelowAndFromAbove) {
  const BookFromAbove b;
  const cv::Point pi = b.corner_px();
  // P1 started 2.5 cm too low (a missed top) and 1.2 cm too high (the growth onto the top face).
  for (const double start_error : {-0.025, 0.012}) {
    const TopCrease c = b.fit(pi, b.true_height + start_error, as_shipped());
    ASSERT_TRUE(c.found) << start_error;
    EXPECT_NEAR(c.height, b.true_height, 0.001) << start_error;
    EXPECT_GE(c.front_pixels, 12);
    EXPECT_GE(c.top_pixels, 12);
  }
}

TEST(TopCrease, ABlurredCreaseKeepsItsHeight) {
  BookFromAbove b;
  b.blur_disparity(7);  // StereoBM's block size as shipped
  const TopCrease c = b.fit(b.corner_px(), b.true_height + 0.01, as_shipped());
  ASSERT_TRUE(c.found);
  EXPECT_NEAR(c.height, b.true_height, 0.0015);
}

TEST(TopCrease, AThinFrontsWindowInATallerNeighbourFailsTheRightColumnsCheck) {
  const BookFromAbove b(true);
  const cv::Point pi = b.corner_px();
  TopCreaseParams p = as_shipped();
  p.max_right_difference_m = 0.0;
  const TopCrease unchecked = b.fit(pi, b.true_height, p);
  // Without the check the window's left columns, on the neighbour 4 cm taller, pull the height up.
  ASSERT_TRUE(unchecked.found);
  EXPECT_GT(unchecked.height - b.true_height, 0.005);
  EXPECT_GT(std::fabs(unchecked.left_height - unchecked.right_height), 0.01);
  p.max_right_difference_m = 0.01;
  EXPECT_FALSE(b.fit(pi, b.true_height, p).found);
  // The 4 cm book alone passes the check.
  const BookFromAbove wide;
  const TopCrease c = wide.fit(wide.corner_px(), wide.true_height, p);
  ASSERT_TRUE(c.found);
  EXPECT_NEAR(c.height, wide.true_height, 0.001);
}

TEST(TopCrease, NoTopFaceInTheDepthNoCrease) {
  BookFromAbove b;
  // The book's top face (box 0, face +z) unmatched, as a dark, textureless cover is: no depth on it.
  const cv::Point pi = b.corner_px();
  constexpr int kTopFace = 0 * 6 + 5 + 1;
  for (int y = 0; y < b.points.rows; ++y)
    for (int x = 0; x < b.points.cols; ++x)
      if (b.face_id.at<int>(y, x) == kTopFace) b.points.at<cv::Vec3f>(y, x) = cv::Vec3f(NAN, NAN, NAN);
  const TopCrease c = b.fit(pi, b.true_height, as_shipped());
  EXPECT_FALSE(c.found);
  EXPECT_LT(c.top_pixels, as_shipped().min_pixels_each_side);
}

TEST(TopCrease, OnlyTheFrontsColumnsCount) {
  const BookFromAbove b;
  const cv::Point pi = b.corner_px();
  cv::Mat none(1, b.points.cols, CV_8U, cv::Scalar(0));
  EXPECT_FALSE(b.fit(pi, b.true_height, as_shipped(), none).found);
  cv::Mat all(1, b.points.cols, CV_8U, cv::Scalar(1));
  EXPECT_TRUE(b.fit(pi, b.true_height, as_shipped(), all).found);
  EXPECT_THROW(fit_top_crease(cv::Mat(3, 3, CV_32F), b.g, b.normal, b.offset, b.up, pi, 0.0, cv::Mat(), as_shipped()),
               std::invalid_argument);
}

// The tests above fit with the struct's defaults (as_shipped): they must be what both implementations ship.
TEST(TopCreaseParams, TheDefaultsAreTheShippedValues) {
  const TopCreaseParams d;
  for (const char* file : {"bws_detector.yaml", "bws_detector_pcl.yaml"}) {
    const TopCreaseParams p = TopCreaseParams::from_config(
        Config::load_file(std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/" + file).child("selection"));
    EXPECT_TRUE(p.enabled) << file;
    EXPECT_EQ(p.columns, d.columns) << file;
    EXPECT_EQ(p.right_margin_px, d.right_margin_px) << file;
    EXPECT_EQ(p.rows_above, d.rows_above) << file;
    EXPECT_EQ(p.rows_below, d.rows_below) << file;
    EXPECT_DOUBLE_EQ(p.search_down_m, d.search_down_m) << file;
    EXPECT_DOUBLE_EQ(p.search_up_m, d.search_up_m) << file;
    EXPECT_DOUBLE_EQ(p.step_m, d.step_m) << file;
    EXPECT_DOUBLE_EQ(p.residual_cap_px, d.residual_cap_px) << file;
    EXPECT_EQ(p.min_pixels_each_side, d.min_pixels_each_side) << file;
    EXPECT_EQ(p.right_columns, d.right_columns) << file;
    EXPECT_DOUBLE_EQ(p.max_right_difference_m, d.max_right_difference_m) << file;
  }
}

TEST(TopCreaseParams, ReadsEveryKeyAndRefusesBadOnes) {
  const char* yaml =
      "top_crease: true\ntop_crease_columns: 5\ntop_crease_right_margin_px: 1\ntop_crease_rows_above: 10\n"
      "top_crease_rows_below: 9\ntop_crease_search_down_m: 0.02\ntop_crease_search_up_m: 0.04\n"
      "top_crease_step_m: 0.001\ntop_crease_residual_cap_px: 0.4\ntop_crease_min_pixels_each_side: 7\n"
      "top_crease_right_columns: 2\ntop_crease_max_right_difference_m: 0.02\n";
  const TopCreaseParams p = TopCreaseParams::from_config(Config::from_string(yaml, "selection"));
  EXPECT_TRUE(p.enabled);
  EXPECT_EQ(p.columns, 5);
  EXPECT_EQ(p.right_margin_px, 1);
  EXPECT_EQ(p.rows_above, 10);
  EXPECT_EQ(p.rows_below, 9);
  EXPECT_DOUBLE_EQ(p.search_down_m, 0.02);
  EXPECT_DOUBLE_EQ(p.search_up_m, 0.04);
  EXPECT_DOUBLE_EQ(p.step_m, 0.001);
  EXPECT_DOUBLE_EQ(p.residual_cap_px, 0.4);
  EXPECT_EQ(p.min_pixels_each_side, 7);
  EXPECT_EQ(p.right_columns, 2);
  EXPECT_DOUBLE_EQ(p.max_right_difference_m, 0.02);
  const std::string bad_step = std::string(yaml).replace(std::string(yaml).find("0.001"), 5, "0.000");
  try {
    TopCreaseParams::from_config(Config::from_string(bad_step, "selection"));
    FAIL() << "a zero step was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("top_crease_step_m"), std::string::npos) << e.what();
  }
  const std::string missing = std::string(yaml).substr(std::string(yaml).find('\n') + 1);
  try {
    TopCreaseParams::from_config(Config::from_string(missing, "selection"));
    FAIL() << "a missing top_crease was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("top_crease"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace bookgrasp::bws
