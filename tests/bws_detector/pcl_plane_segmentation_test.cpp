// The PCL planar segmentation and the jump-component baseline on the synthetic shelf (exact depth),
// judged against the rendered face ids with the Hoover metric, beside GoD in the same scene.
#include "services/bws_detector/pcl_plane_segmentation.h"

#include <cstdio>
#include <map>

#include <gtest/gtest.h>

#include "services/bws_detector/baseline_segmentation.h"
#include "services/bws_detector/book_front_selection.h"
#include "services/bws_detector/disparity.h"
#include "services/bws_detector/god_segmentation.h"
#include "services/eval_segmentation/hoover_comparison.h"
#include "synthetic_shelf.h"

namespace bookgrasp::bws {
namespace {

PclPlaneParams pcl_params() {
  PclPlaneParams p;
  p.covariance_normals = true;
  p.max_depth_change_factor = 0.01;
  p.normal_smoothing_size = 5.0;
  p.min_inliers = 30;
  p.angular_threshold_deg = 5.0;
  p.distance_threshold_m = 0.01;
  p.maximum_curvature = 0.01;
  p.min_region_px = 30;
  return p;
}

cv::Mat ground_truth(const cv::Mat& face_id, int min_px) {
  cv::Mat gt = face_id.clone();
  std::map<int, int> size;
  for (int y = 0; y < gt.rows; ++y)
    for (int x = 0; x < gt.cols; ++x) ++size[gt.at<int>(y, x)];
  for (int y = 0; y < gt.rows; ++y)
    for (int x = 0; x < gt.cols; ++x)
      if (size[gt.at<int>(y, x)] < min_px) gt.at<int>(y, x) = 0;
  return gt;
}

TEST(PclPlaneSegmentation, FindsTheShelfPlanesWithExactNormals) {
  const test::ShelfScene scene = test::make_shelf_scene(11);
  const test::RenderOutput ren = test::render_boxes(scene.boxes, scene.left, false);
  const cv::Mat disp = test::exact_disparity(ren.depth, scene.left.fx, scene.baseline_m);
  const StereoGeometry g{scene.left.fx, scene.left.fy, scene.left.cx, scene.left.cy, scene.baseline_m};
  const cv::Mat pts = disparity_to_points(disp, g);
  const SegmentationResult r = segment_pcl_planes(pts, pcl_params());
  ASSERT_FALSE(r.regions.empty());
  // The rear board's front face (box 1, face -x): a region mostly on it has the board's normal.
  const int face = 1 * 6 + test::kFaceMinusX + 1;
  const Eigen::Vector3d board_n_cam =
      scene.left.in_base.linear().transpose() * (scene.cart_in_base.linear() * -Eigen::Vector3d::UnitX());
  bool found = false;
  for (const PlaneRegion& reg : r.regions) {
    int on = 0;
    for (int y = reg.bbox.y; y < reg.bbox.y + reg.bbox.height; ++y)
      for (int x = reg.bbox.x; x < reg.bbox.x + reg.bbox.width; ++x)
        on += r.labels.at<int>(y, x) == reg.label && ren.face_id.at<int>(y, x) == face;
    if (on > 0.9 * reg.pixel_count && reg.pixel_count > 10000) {
      found = true;
      EXPECT_GT(std::fabs(reg.normal.dot(board_n_cam)), std::cos(0.5 * M_PI / 180.0));
    }
  }
  EXPECT_TRUE(found);
}

// The shipped configuration (config/services/bws_detector_pcl.yaml): PCL in the image space of the disparity.
PclPlaneParams shipped_image_space_params() {
  PclPlaneParams p = pcl_params();
  p.space = PclSpace::kImage;
  p.max_depth_change_factor = 0.02;
  p.angular_threshold_deg = 15.0;
  p.distance_threshold_m = 2.0;  // pixels
  p.maximum_curvature = 0.1;
  return p;
}

// In image space with the shipped thresholds every normal is within a few degrees of the viewing axis, so
// the segmentation follows disparity continuity, not orientation: on exact disparity a book's front, top and
// side stay one region and no front passes the selection (seeds 1-4, printed, not asserted); on StereoBM
// disparity of the rendered scenes the noise breaks those regions apart and the column bands find the
// right-most front in about half the scenes (docs/BWS.md). What must hold here: metric planes come out.
TEST(PclPlaneSegmentation, ImageSpaceDescribesItsRegionsWithMetricPlanes) {
  for (uint32_t seed : {1u, 2u, 3u, 4u}) {
    const test::ShelfScene scene = test::make_shelf_scene(seed);
    const test::RenderOutput ren = test::render_boxes(scene.boxes, scene.left, false);
    const cv::Mat disp = test::exact_disparity(ren.depth, scene.left.fx, scene.baseline_m);
    const StereoGeometry g{scene.left.fx, scene.left.fy, scene.left.cx, scene.left.cy, scene.baseline_m};
    const cv::Mat pts = disparity_to_points(disp, g);
    const SegmentationResult r = segment_pcl_planes(disp, pts, shipped_image_space_params());
    ASSERT_FALSE(r.regions.empty());
    int largest = 0;
    for (const PlaneRegion& reg : r.regions) {
      EXPECT_NEAR(reg.normal.norm(), 1.0, 1e-9);
      EXPECT_NEAR(reg.normal.dot(reg.centroid), reg.offset, 1e-6);
      // A plane in metres of the camera frame (oriented to the camera): it passes 0-10 m from the camera,
      // never closer than the region's centroid; a plane of (column, row, disparity) would be hundreds away.
      EXPECT_LE(reg.offset, 0.0);
      EXPECT_LT(-reg.offset, 10.0);
      EXPECT_LE(-reg.offset, reg.centroid.norm() + 1e-9);
      largest = std::max(largest, reg.pixel_count);
    }
    std::printf("pcl image space, exact disparity, seed %u: %zu regions, largest %d px\n", seed, r.regions.size(),
                largest);
  }
  // The points space through the same entry point is the metric segmentation.
  const test::ShelfScene scene = test::make_shelf_scene(11);
  const test::RenderOutput ren = test::render_boxes(scene.boxes, scene.left, false);
  const cv::Mat disp = test::exact_disparity(ren.depth, scene.left.fx, scene.baseline_m);
  const cv::Mat pts =
      disparity_to_points(disp, {scene.left.fx, scene.left.fy, scene.left.cx, scene.left.cy, scene.baseline_m});
  const SegmentationResult m1 = segment_pcl_planes(disp, pts, pcl_params());
  const SegmentationResult m2 = segment_pcl_planes(pts, pcl_params());
  EXPECT_EQ(cv::countNonZero(m1.labels != m2.labels), 0);
  // The disparity must match the points.
  EXPECT_THROW(segment_pcl_planes(cv::Mat(4, 4, CV_32F), pts, shipped_image_space_params()), std::invalid_argument);
}

TEST(SegmentationComparison, HooverOnTheShelfSceneGodPclAndBaseline) {
  const test::ShelfScene scene = test::make_shelf_scene(11);
  const test::RenderOutput ren = test::render_boxes(scene.boxes, scene.left, false);
  const cv::Mat disp = test::exact_disparity(ren.depth, scene.left.fx, scene.baseline_m);
  const StereoGeometry g{scene.left.fx, scene.left.fy, scene.left.cx, scene.left.cy, scene.baseline_m};
  const cv::Mat pts = disparity_to_points(disp, g);
  const cv::Mat gt = ground_truth(ren.face_id, 200);

  GodParams gp;  // the values of config/services/bws_detector.yaml
  gp.gradient_step = 1;
  gp.direction_bins = 16;
  gp.flat_mgod_max = 0.0;
  gp.window_size = 5;
  gp.jump_mgod_min = 0.6;
  gp.merge_distance = 0.75;
  gp.merge_space = MergeSpace::kImage;
  gp.merge_max_angle_deg = 30.0;
  gp.merge_angle_min_px = 100;
  gp.adjacency_radius_px = 2;
  gp.boundary_growth_px = 2;
  gp.boundary_growth_distance = 0.25;
  gp.min_region_px = 30;
  const SegmentationResult god = segment_god(disp, pts, gp);
  const SegmentationResult pcl = segment_pcl_planes(pts, pcl_params());
  JumpComponentsParams jp;
  jp.max_jump = 0.5;
  jp.min_region_px = 30;
  const SegmentationResult jump = segment_jump_components(disp, pts, jp);

  std::map<std::string, std::map<double, eval_segmentation::HooverResult>> table;
  for (double T : {0.51, 0.6, 0.7, 0.8, 0.9}) {
    table["god"][T] = eval_segmentation::hoover_compare(gt, god.labels, T);
    table["pcl"][T] = eval_segmentation::hoover_compare(gt, pcl.labels, T);
    table["jump_components"][T] = eval_segmentation::hoover_compare(gt, jump.labels, T);
  }
  for (const auto& [name, rows] : table)
    for (const auto& [T, s] : rows)
      std::printf("%-16s T=%.2f  GT %d: correct %d, over %d, under %d, missed %d, noise %d\n", name.c_str(), T,
                  s.num_gt(), s.correct, s.over, s.under, s.missed, s.noise);
  // Jump components cannot split creases (a book's top from its front): it must do worse than GoD.
  EXPECT_GT(table["god"][0.8].correct, table["jump_components"][0.8].correct);
  EXPECT_GE(double(table["god"][0.8].correct) / table["god"][0.8].num_gt(), 0.6);
  EXPECT_GT(table["pcl"][0.8].correct, 0);
}

TEST(PclPlaneSegmentation, BadInputThrows) {
  EXPECT_THROW(segment_pcl_planes(cv::Mat(4, 4, CV_32F), pcl_params()), std::invalid_argument);
  // All-NaN cloud: no planes, no crash.
  const SegmentationResult r =
      segment_pcl_planes(cv::Mat(20, 20, CV_32FC3, cv::Scalar::all(std::nan(""))), pcl_params());
  EXPECT_TRUE(r.regions.empty());
}

}  // namespace
}  // namespace bookgrasp::bws
