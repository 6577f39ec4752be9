// bench_markers: AprilTag detection (+ pose) per 640x480 frame with the shipped configuration.
#include <benchmark/benchmark.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/config.h"
#include "services/marker_detector/tag_detector.h"
#include "services/marker_detector/tag_pose.h"

namespace {

cv::Mat tagtest() {
  cv::Mat img = cv::imread(std::string(BOOKGRASP_SOURCE_DIR) + "/tests/data/apriltag/tagtest.jpg", cv::IMREAD_GRAYSCALE);
  if (img.empty()) throw std::runtime_error("cannot read tests/data/apriltag/tagtest.jpg");
  cv::resize(img, img, cv::Size(640, 480));
  return img;
}

bookgrasp::TagDetectorParams shipped() {
  const auto root = bookgrasp::Config::load_file(std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/marker_detector.yaml");
  return bookgrasp::TagDetectorParams::from_config(root.child("apriltag"));
}

void run(benchmark::State& state, bookgrasp::TagDetectorParams p) {
  const cv::Mat img = tagtest();
  bookgrasp::TagDetector det(p);
  bookgrasp::TagCameraIntrinsics k;
  k.fx = k.fy = 600;
  k.cx = 319.5;
  k.cy = 239.5;
  size_t n = 0;
  for (auto _ : state) {
    auto found = det.detect(img);
    for (const auto& d : found) benchmark::DoNotOptimize(bookgrasp::estimate_tag_pose(d.corners, 0.08, k));
    n = found.size();
  }
  state.counters["tags"] = static_cast<double>(n);
}

void BM_MarkersShippedConfig(benchmark::State& state) { run(state, shipped()); }
void BM_MarkersDecimate1(benchmark::State& state) {
  auto p = shipped();
  p.quad_decimate = 1.0;
  run(state, p);
}

}  // namespace

BENCHMARK(BM_MarkersShippedConfig)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MarkersDecimate1)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
