// bench_markers: AprilTag detection (+ pose) per 640x480 frame with the shipped configuration: the whole
// image (the baseline) and the shipped tracking (regions around the previous frame's tags between
// whole-image searches) on a still view, as the stereo camera sees the cart and holder.
#include <benchmark/benchmark.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/config.h"
#include "services/marker_detector/tag_detector.h"
#include "services/marker_detector/tag_pose.h"
#include "services/marker_detector/tag_search.h"

namespace {

cv::Mat tagtest() {
  cv::Mat img =
      cv::imread(std::string(BOOKGRASP_SOURCE_DIR) + "/tests/data/apriltag/tagtest.jpg", cv::IMREAD_GRAYSCALE);
  if (img.empty()) throw std::runtime_error("cannot read tests/data/apriltag/tagtest.jpg");
  cv::resize(img, img, cv::Size(640, 480));
  return img;
}

bookgrasp::Config shipped_root() {
  return bookgrasp::Config::load_file(std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/marker_detector.yaml");
}

bookgrasp::TagDetectorParams shipped() {
  return bookgrasp::TagDetectorParams::from_config(shipped_root().child("apriltag"));
}

bookgrasp::TagCameraIntrinsics intrinsics() {
  bookgrasp::TagCameraIntrinsics k;
  k.fx = k.fy = 600;
  k.cx = 319.5;
  k.cy = 239.5;
  return k;
}

void run(benchmark::State& state, bookgrasp::TagDetectorParams p) {
  const cv::Mat img = tagtest();
  bookgrasp::TagDetector det(p);
  const bookgrasp::TagCameraIntrinsics k = intrinsics();
  size_t n = 0;
  for (auto _ : state) {
    auto found = det.detect(img);
    for (const auto& d : found) benchmark::DoNotOptimize(bookgrasp::estimate_tag_pose(d.corners, 0.08, k));
    n = found.size();
  }
  state.counters["tags"] = static_cast<double>(n);
}

// Baseline: every frame searched whole with the shipped detector settings (quad_decimate 1).
void BM_MarkersWholeImage(benchmark::State& state) {
  run(state, shipped());
}
// For reference: whole image at quad_decimate 2 (misses the ~45 px rendered cart tag, see the config).
void BM_MarkersWholeImageDecimate2(benchmark::State& state) {
  auto p = shipped();
  p.quad_decimate = 2.0;
  run(state, p);
}

// Frames at `frame_s` intervals of message time through the shipped TagSearch (whole-image search every
// tracking.full_search_period_s, regions in between), with pose; the first, whole search is outside the loop.
void run_tracked(benchmark::State& state, double frame_s, double period_s) {
  const cv::Mat img = tagtest();
  bookgrasp::TagTrackingParams tracking = bookgrasp::TagTrackingParams::from_config(shipped_root().child("tracking"));
  tracking.full_search_period_s = period_s;
  bookgrasp::TagSearch search(shipped(), 0.0, tracking, {});
  const bookgrasp::TagCameraIntrinsics k = intrinsics();
  int64_t utime = 0;
  search.detect(img, utime);
  size_t n = 0, whole = 0, frames = 0;
  for (auto _ : state) {
    utime += static_cast<int64_t>(frame_s * 1e6);
    const bookgrasp::TagSearchResult r = search.detect(img, utime);
    for (const auto& d : r.tags) benchmark::DoNotOptimize(bookgrasp::estimate_tag_pose(d.corners, 0.08, k));
    n = r.tags.size();
    whole += r.mode == bookgrasp::TagSearchMode::kFull;
    ++frames;
  }
  state.counters["tags"] = static_cast<double>(n);
  state.counters["whole_fraction"] = frames ? static_cast<double>(whole) / static_cast<double>(frames) : 0.0;
}

// The shipped tracking at the stereo camera's 10 Hz: one whole search a second, regions in between.
void BM_MarkersTrackedShipped10Hz(benchmark::State& state) {
  run_tracked(state, 0.1, shipped_root().get<double>("tracking.full_search_period_s"));
}
// Regions only (no whole search due): the cost of a frame between whole searches.
void BM_MarkersTrackedRegionsOnly(benchmark::State& state) {
  run_tracked(state, 0.1, 1e9);
}

}  // namespace

BENCHMARK(BM_MarkersWholeImage)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MarkersWholeImageDecimate2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MarkersTrackedShipped10Hz)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MarkersTrackedRegionsOnly)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
