// bench_hand_detectors: BwH and BSwH per 640x480 hand image with the shipped configurations: on a synthetic
// image (shadows, stamps) and on rendered views of the eval scene (services/eval_hand/scenes/hand_eval.yaml):
// the converged corner view of seed 2 (tests/bwh_detector/data, `hand_view_dump OUT 2 1`) for BwH's shipped
// method page_faces, the converged stripe view of seed 1 (tests/bswh_detector/data) for BSwH.
#include <benchmark/benchmark.h>

#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "services/bwh_detector/page_face_detection.h"

#include "services/bswh_detector/stripe_detection.h"
#include "services/bwh_detector/book_detection_hand.h"
#include "synthetic_hand_image.h"

namespace {

const std::string kConfigDir = std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/";

cv::Mat scene() {
  bookgrasp::test::SynthScene s = bookgrasp::test::default_scene();
  s.shadows.push_back({{{0, 230}, {640, 170}, {640, 260}, {0, 320}}, 0.5, 1.0});
  s.stamps.push_back({4, 0.55, 0.5, 30});
  bookgrasp::test::SynthTruth t;
  return bookgrasp::test::render_scene(s, &t);
}

cv::Mat rendered(const std::string& path) {
  const cv::Mat bgr = cv::imread(std::string(BOOKGRASP_SOURCE_DIR) + "/tests/" + path);
  if (bgr.empty()) throw std::runtime_error("cannot read tests/" + path);
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

void BM_BwH_PageFaces_Rendered(benchmark::State& state) {
  const auto p = bookgrasp::PageFaceParams::from_config(
      bookgrasp::Config::load_file(kConfigDir + "bwh_detector.yaml").child("page_faces"));
  const cv::Mat img = rendered("bwh_detector/data/hand_eval_seed2_corner.png");
  for (auto _ : state) benchmark::DoNotOptimize(bookgrasp::detect_books_page_faces(img, p));
}

void BM_BSwH_Rendered(benchmark::State& state) {
  const auto p = bookgrasp::StripeDetectionParams::from_config(
      bookgrasp::Config::load_file(kConfigDir + "bswh_detector.yaml").child("stripe"));
  const cv::Mat img = rendered("bswh_detector/data/hand_eval_seed1_converged.png");
  for (auto _ : state) benchmark::DoNotOptimize(bookgrasp::detect_stripe(img, p));
}

void BM_BwH(benchmark::State& state) {
  const auto p = bookgrasp::BookDetectionParams::from_config(
      bookgrasp::Config::load_file(kConfigDir + "bwh_detector.yaml").child("books"));
  const cv::Mat img = scene();
  for (auto _ : state) benchmark::DoNotOptimize(bookgrasp::detect_books_hand(img, p));
}

void BM_BSwH(benchmark::State& state) {
  const auto p = bookgrasp::StripeDetectionParams::from_config(
      bookgrasp::Config::load_file(kConfigDir + "bswh_detector.yaml").child("stripe"));
  const cv::Mat img = scene();
  for (auto _ : state) benchmark::DoNotOptimize(bookgrasp::detect_stripe(img, p));
}

}  // namespace

BENCHMARK(BM_BwH_PageFaces_Rendered)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BSwH_Rendered)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BwH)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BSwH)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
