// bench_hand_detectors: BwH and BSwH per 640x480 synthetic hand image with the shipped configurations.
#include <benchmark/benchmark.h>

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

BENCHMARK(BM_BwH)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BSwH)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
