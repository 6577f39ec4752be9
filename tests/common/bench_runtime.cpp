// Benchmarks of the runtime's hot paths at 640x480: image message encode/decode
// raw vs PNG vs JPEG (raw is the baseline), and memq dispatch through a component.
#include <benchmark/benchmark.h>

#include <vector>

#include "bookgrasp/stereo_frame_t.hpp"
#include "common/composition.h"
#include "common/image_conversion.h"
#include "tests/common/echo_component.h"

namespace {

cv::Mat test_image() {
  // A textured image (not flat: compression ratios of flat images mean nothing).
  cv::Mat m(480, 640, CV_8UC3);
  cv::RNG rng(7);
  rng.fill(m, cv::RNG::UNIFORM, 0, 40);
  for (int y = 0; y < m.rows; ++y)
    for (int x = 0; x < m.cols; ++x) m.at<cv::Vec3b>(y, x) += cv::Vec3b(x / 4, y / 3, (x + y) / 6);
  return m;
}

void BM_EncodeRaw(benchmark::State& s) {
  const cv::Mat img = test_image();
  for (auto _ : s) {
    const auto msg = bookgrasp::mat_to_image(img, bookgrasp::image_t::RGB8, 1, "cam");
    std::vector<uint8_t> buf(msg.getEncodedSize());
    benchmark::DoNotOptimize(msg.encode(buf.data(), 0, static_cast<int>(buf.size())));
    s.counters["bytes"] = static_cast<double>(buf.size());
  }
}
BENCHMARK(BM_EncodeRaw)->Unit(benchmark::kMillisecond);

void BM_EncodePng(benchmark::State& s) {
  const cv::Mat img = test_image();
  for (auto _ : s) {
    const auto msg = bookgrasp::encode_png(img, 1, "cam");
    s.counters["bytes"] = static_cast<double>(msg.size);
  }
}
BENCHMARK(BM_EncodePng)->Unit(benchmark::kMillisecond);

void BM_EncodeJpeg90(benchmark::State& s) {
  const cv::Mat img = test_image();
  for (auto _ : s) {
    const auto msg = bookgrasp::encode_jpeg(img, 1, "cam", 90);
    s.counters["bytes"] = static_cast<double>(msg.size);
  }
}
BENCHMARK(BM_EncodeJpeg90)->Unit(benchmark::kMillisecond);

void BM_DecodeRaw(benchmark::State& s) {
  const auto msg = bookgrasp::mat_to_image(test_image(), bookgrasp::image_t::RGB8, 1, "cam");
  for (auto _ : s) benchmark::DoNotOptimize(bookgrasp::image_to_mat(msg));
}
BENCHMARK(BM_DecodeRaw)->Unit(benchmark::kMillisecond);

void BM_DecodePng(benchmark::State& s) {
  const auto msg = bookgrasp::encode_png(test_image(), 1, "cam");
  for (auto _ : s) benchmark::DoNotOptimize(bookgrasp::image_to_mat(msg));
}
BENCHMARK(BM_DecodePng)->Unit(benchmark::kMillisecond);

void BM_DecodeJpeg90(benchmark::State& s) {
  const auto msg = bookgrasp::encode_jpeg(test_image(), 1, "cam", 90);
  for (auto _ : s) benchmark::DoNotOptimize(bookgrasp::image_to_mat(msg));
}
BENCHMARK(BM_DecodeJpeg90)->Unit(benchmark::kMillisecond);

void BM_MemqDispatchSmallMessage(benchmark::State& s) {
  bookgrasp::Composition comp;
  const auto cfg = bookgrasp::Config::from_string(
      "service: {name: e, implementation: echo}\nchannels: {input: IN, output: OUT, images: IMG}\n");
  comp.add(std::make_unique<bookgrasp_test::EchoComponent>(cfg));
  bookgrasp::task_status_t m{};
  m.state = "x";
  int64_t t = 0;
  for (auto _ : s) {
    m.utime = ++t;
    comp.bus().publish("IN", &m);
    comp.spin();
  }
}
BENCHMARK(BM_MemqDispatchSmallMessage)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
