// Ground truth of the simulator range scenes, checked against the scene's own geometry (book corners from
// the simulator's ground truth message, not the renderer's geom ids the labels come from).
#include "services/eval_segmentation/range_scene.h"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

namespace bookgrasp::eval_segmentation {
namespace {

RangeSceneOptions options(uint64_t seed, bool curved) {
  RangeSceneOptions o;
  o.scene_file = std::string(BOOKGRASP_SOURCE_DIR) + "/config/scenes/default.yaml";
  o.seed = seed;
  o.curved_objects = curved;
  return o;
}

const book_truth_t& rightmost(const ground_truth_t& t) {
  for (const book_truth_t& b : t.books)
    if (b.rightmost) return b;
  throw std::runtime_error("no right-most book");
}

// Every pixel of the right-most book's front region, back-projected with the exact depth, lies on the
// plane through the book's four front corners (simulator truth) and inside their extent.
TEST(RangeScene, RightmostFrontRegionLiesOnTheBooksFrontFace) {
  const RangeScene s = render_range_scene(options(3, false));
  const int label = s.rightmost_front_label();
  ASSERT_GT(label, 0) << "the right-most front is not a ground-truth region";
  const book_truth_t& b = rightmost(s.truth);
  // Corner index bit 0 = back: corners 0, 2, 4, 6 are the front ones.
  Eigen::Vector3d c[4];
  for (int i = 0; i < 4; ++i)
    c[i] = Eigen::Vector3d(b.corners_base[2 * i][0], b.corners_base[2 * i][1], b.corners_base[2 * i][2]);
  const Eigen::Vector3d n = (c[1] - c[0]).cross(c[2] - c[0]).normalized();
  int pixels = 0, off_plane = 0;
  for (int y = 0; y < s.gt_labels.rows; ++y)
    for (int x = 0; x < s.gt_labels.cols; ++x) {
      if (s.gt_labels.at<int>(y, x) != label) continue;
      ++pixels;
      const Eigen::Vector3d p =
          s.left_camera.camera_in_base * (s.left_camera.ray(x, y) * double(s.depth.at<float>(y, x)));
      if (std::fabs(n.dot(p - c[0])) > 0.002) ++off_plane;
    }
  EXPECT_GE(pixels, 100);
  EXPECT_EQ(off_plane, 0) << "of " << pixels;
  EXPECT_EQ(s.regions[size_t(label - 1)].owner, b.id);
  EXPECT_TRUE(s.regions[size_t(label - 1)].planar);
  EXPECT_EQ(s.curved_objects_placed, 0);
  for (const GtRegion& r : s.regions) EXPECT_EQ(r.name.rfind("evalseg_", 0), std::string::npos) << r.name;
}

// The cart marker plate (1 mm on the rear board) is one surface with the rear board: no range data can
// separate them. Labels are 1..regions.size() and every region has at least min_region_px pixels.
TEST(RangeScene, CoplanarFacesOfDifferentGeomsAreOneSurface) {
  RangeSceneOptions o = options(3, false);
  o.min_region_px = 150;
  const RangeScene s = render_range_scene(o);
  ASSERT_TRUE(s.face_label.count("cart_marker:+z"));
  EXPECT_GT(s.face_label.at("cart_marker:+z"), 0);
  EXPECT_EQ(s.face_label.at("cart_marker:+z"), s.face_label.at("cart_rear_board:-x"));
  std::vector<int> count(s.regions.size() + 1, 0);
  for (int y = 0; y < s.gt_labels.rows; ++y)
    for (int x = 0; x < s.gt_labels.cols; ++x) {
      const int l = s.gt_labels.at<int>(y, x);
      ASSERT_GE(l, 0);
      ASSERT_LE(l, int(s.regions.size()));
      ++count[size_t(l)];
    }
  for (const GtRegion& r : s.regions) {
    EXPECT_EQ(count[size_t(r.label)], r.pixel_count);
    EXPECT_GE(r.pixel_count, 150);
  }
}

// With curved objects: a cup and a ball appear as curved ground-truth regions; the books are where they are
// without them (same settled simulation), and the left margin is unlabelled.
TEST(RangeScene, CurvedObjectsAreAddedOnlyWhenAsked) {
  RangeSceneOptions o = options(2, true);
  o.left_margin_px = 64;
  const RangeScene s = render_range_scene(o);
  const RangeScene plain = render_range_scene(options(2, false));
  EXPECT_EQ(s.curved_objects_placed, 2);
  int curved = 0;
  for (const GtRegion& r : s.regions)
    if (!r.planar && r.name.rfind("evalseg_", 0) == 0) ++curved;
  EXPECT_GE(curved, 1);
  ASSERT_EQ(s.truth.books.size(), plain.truth.books.size());
  for (size_t i = 0; i < s.truth.books.size(); ++i)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(s.truth.books[i].p1_base[k], plain.truth.books[i].p1_base[k]);
  EXPECT_EQ(cv::countNonZero(s.gt_labels(cv::Rect(0, 0, 64, s.gt_labels.rows))), 0);
}

TEST(RangeScene, BadOptionsAreRefused) {
  RangeSceneOptions o = options(1, false);
  o.min_region_px = 0;
  EXPECT_THROW(render_range_scene(o), std::invalid_argument);
  o = options(1, false);
  o.max_depth_m = -1;
  EXPECT_THROW(render_range_scene(o), std::invalid_argument);
  o = options(1, false);
  o.scene_file = "/nonexistent/scene.yaml";
  EXPECT_ANY_THROW(render_range_scene(o));
}

TEST(RangeScene, ColorizeLabelsKeepsBackgroundBlackAndLabelsDistinct) {
  cv::Mat l = (cv::Mat_<int>(1, 3) << 0, 1, 2);
  const cv::Mat c = colorize_labels(l);
  EXPECT_EQ(c.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0));
  EXPECT_NE(c.at<cv::Vec3b>(0, 1), c.at<cv::Vec3b>(0, 2));
  EXPECT_NE(c.at<cv::Vec3b>(0, 1), cv::Vec3b(0, 0, 0));
}

}  // namespace
}  // namespace bookgrasp::eval_segmentation
