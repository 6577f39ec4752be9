// bench_bws: one 640x480 synthetic shelf stereo pair (seed 1), rendered once; every stage on the same input.
#include <sys/resource.h>

#include <benchmark/benchmark.h>

#include "common/config.h"
#include "services/bws_detector/book_front_selection.h"
#include "services/bws_detector/disparity.h"
#include "services/bws_detector/god_segmentation.h"
#include "services/bws_detector/pcl_plane_segmentation.h"
#include "synthetic_shelf.h"

using namespace bookgrasp::bws;

namespace {
/// Minor page faults of this thread so far.
double minor_faults() {
  rusage u{};
  getrusage(RUSAGE_THREAD, &u);
  return double(u.ru_minflt);
}
struct Input {
  test::ShelfScene scene = test::make_shelf_scene(1);
  cv::Mat left, right, disparity, points;
  StereoGeometry g;
  DisparityParams dp;
  GodParams gp;         // the shipped `god` section
  GodParams gp_stop33;  // the section shipped until stop 34: no smoothing, 16 bins, 5 x 5 voting (the baseline)
  PclPlaneParams pp, pp_metric;
  SelectionParams sp;
  SelectionParams sp_stop34;  // the selection shipped until stop 35: no front layer, holes count as gaps (baseline)
  SelectionParams sp_no_crease;  // the shipped selection without the top's crease (stop 46's; baseline)
  Input() {
    left = test::render_boxes(scene.boxes, scene.left, true).intensity;
    right = test::render_boxes(scene.boxes, scene.right, true).intensity;
    dp.block_size = 7;
    g = {scene.left.fx, scene.left.fy, scene.left.cx, scene.left.cy, scene.baseline_m};
    disparity = compute_disparity(left, right, dp);
    points = disparity_to_points(disparity, g);
    gp_stop33.window_size = 5;
    gp_stop33.jump_mgod_min = 0.6;
    gp_stop33.min_region_px = 30;
    pp_metric.min_inliers = 30;  // the metric-space PCL segmentation shipped until 2026-12-02
    pp_metric.normal_smoothing_size = 5.0;
    pp_metric.max_depth_change_factor = 0.01;
    pp_metric.angular_threshold_deg = 5.0;
    pp_metric.distance_threshold_m = 0.01;
    pp_metric.maximum_curvature = 0.01;
    pp_metric.min_region_px = 30;
    // The shipped PCL segmentation and book-front selection (every PI refinement on).
    const std::string dir = std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/";
    pp = PclPlaneParams::from_config(bookgrasp::Config::load_file(dir + "bws_detector_pcl.yaml").child("pcl"));
    sp = SelectionParams::from_config(bookgrasp::Config::load_file(dir + "bws_detector.yaml").child("selection"));
    gp = GodParams::from_config(bookgrasp::Config::load_file(dir + "bws_detector.yaml").child("god"));
    sp_stop34 = sp;
    sp_stop34.layer_disparity_px = 0.0;
    sp_stop34.top_growth.max_hole_px = -1;
    sp_no_crease = sp;
    sp_no_crease.top_crease.enabled = false;
  }
};
Input& input() {
  static Input in;
  return in;
}
}  // namespace

static void BM_Disparity_StereoBM(benchmark::State& s) {
  auto& in = input();
  for (auto _ : s) benchmark::DoNotOptimize(compute_disparity(in.left, in.right, in.dp));
}
BENCHMARK(BM_Disparity_StereoBM)->Unit(benchmark::kMillisecond);

static void BM_GodFeatures(benchmark::State& s) {
  auto& in = input();
  for (auto _ : s) benchmark::DoNotOptimize(compute_god_features(in.disparity, 1, 0.0));
}
BENCHMARK(BM_GodFeatures)->Unit(benchmark::kMillisecond);

static void BM_GodSmoothing(benchmark::State& s) {
  auto& in = input();
  for (auto _ : s)
    benchmark::DoNotOptimize(
        smooth_valid_values(in.disparity, in.gp.smoothing_radius_px, in.gp.smoothing_max_difference));
}
BENCHMARK(BM_GodSmoothing)->Unit(benchmark::kMillisecond);

static void god_segmentation(benchmark::State& s, const GodParams& gp) {
  auto& in = input();
  GodDebug dbg;  // counters from one run with debug output; the timed runs are the pipeline's (no debug)
  segment_god(in.disparity, in.points, gp, &dbg);
  const double f0 = minor_faults();
  for (auto _ : s) benchmark::DoNotOptimize(segment_god(in.disparity, in.points, gp));
  s.counters["faults"] = benchmark::Counter((minor_faults() - f0) / double(s.iterations()));
  s.counters["initial_segments"] = dbg.initial_count;
  s.counters["merge_rounds"] = dbg.merge_rounds;
}
/// GoD with the shipped parameters (smoothing included).
static void BM_GodSegmentation(benchmark::State& s) {
  god_segmentation(s, input().gp);
}
/// GoD with the parameters shipped until stop 34 (the named baseline).
static void BM_GodSegmentation_Stop33Params(benchmark::State& s) {
  god_segmentation(s, input().gp_stop33);
}
BENCHMARK(BM_GodSegmentation)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GodSegmentation_Stop33Params)->Unit(benchmark::kMillisecond);

static void selection(benchmark::State& s, const SelectionParams& params) {
  auto& in = input();
  const ShelfVolume shelf{in.scene.shelf_box_in_base, in.scene.shelf_half_extent};
  const SegmentationResult seg = segment_god(in.disparity, in.points, in.gp);
  for (auto _ : s)
    benchmark::DoNotOptimize(select_book_front(seg, in.points, in.g, in.scene.left.in_base, shelf, params));
}
static void BM_BookFrontSelection(benchmark::State& s) {
  selection(s, input().sp);
}
static void BM_BookFrontSelection_Stop34Params(benchmark::State& s) {
  selection(s, input().sp_stop34);
}
/// The shipped selection without the top's crease (`selection.top_crease: false`), against BM_BookFrontSelection.
static void BM_BookFrontSelection_NoCrease(benchmark::State& s) {
  selection(s, input().sp_no_crease);
}
/// The shipped selection on the same frame when no region passes (an empty segmentation): the
/// layer placed where the volume's points are densest (`layer_without_front_m`), against
/// BM_BookFrontSelection.
static void BM_BookFrontSelection_NoRegionPasses(benchmark::State& s) {
  auto& in = input();
  const ShelfVolume shelf{in.scene.shelf_box_in_base, in.scene.shelf_half_extent};
  SegmentationResult seg;
  seg.labels = cv::Mat(in.disparity.size(), CV_32S, cv::Scalar(0));
  for (auto _ : s)
    benchmark::DoNotOptimize(select_book_front(seg, in.points, in.g, in.scene.left.in_base, shelf, in.sp));
}
BENCHMARK(BM_BookFrontSelection)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BookFrontSelection_Stop34Params)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BookFrontSelection_NoCrease)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BookFrontSelection_NoRegionPasses)->Unit(benchmark::kMillisecond);

static void BM_PclSegmentation(benchmark::State& s) {
  auto& in = input();
  for (auto _ : s) benchmark::DoNotOptimize(segment_pcl_planes(in.disparity, in.points, in.pp));
}
BENCHMARK(BM_PclSegmentation)->Unit(benchmark::kMillisecond);

static void BM_PclSegmentation_MetricSpace(benchmark::State& s) {
  auto& in = input();
  for (auto _ : s) benchmark::DoNotOptimize(segment_pcl_planes(in.points, in.pp_metric));
}
BENCHMARK(BM_PclSegmentation_MetricSpace)->Unit(benchmark::kMillisecond);

static void whole(benchmark::State& s, bool god) {
  auto& in = input();
  const ShelfVolume shelf{in.scene.shelf_box_in_base, in.scene.shelf_half_extent};
  const double f0 = minor_faults();
  for (auto _ : s) {
    const cv::Mat d = compute_disparity(in.left, in.right, in.dp);
    const cv::Mat p = disparity_to_points(d, in.g);
    const SegmentationResult seg = god ? segment_god(d, p, in.gp) : segment_pcl_planes(d, p, in.pp);
    benchmark::DoNotOptimize(select_book_front(seg, p, in.g, in.scene.left.in_base, shelf, in.sp));
  }
  s.counters["faults"] = benchmark::Counter((minor_faults() - f0) / double(s.iterations()));
}
static void BM_WholeBwS_God(benchmark::State& s) {
  whole(s, true);
}
static void BM_WholeBwS_Pcl(benchmark::State& s) {
  whole(s, false);
}
BENCHMARK(BM_WholeBwS_God)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WholeBwS_Pcl)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
