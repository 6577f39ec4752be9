// Render time of the simulated cameras of the default scene at 640x480 with
// shadows (shadow map 1024): per camera RGB, RGB+depth, segmentation, and all
// three cameras together as the camera services render them (with sensor noise).
// Run on one core, with llvmpipe rendering in the calling thread:
//   LP_NUM_THREADS=0 taskset -c 1 build/tests/cameras/bench_render
// (CPU time is then the whole cost; real time also counts other processes on the core.)
#include <benchmark/benchmark.h>

#include <memory>

#include "common/sim_render/sim_camera_rig.h"

namespace {

using bookgrasp::sim_render::SimCameraRig;

SimCameraRig& rig() {
  static SimCameraRig r(BOOKGRASP_SOURCE_DIR "/config/scenes/default.yaml", 1);
  return r;
}

const char* kCameras[] = {"stereo_left", "stereo_right", "hand_camera"};

void BM_Rgb(benchmark::State& state) {
  const char* cam = kCameras[state.range(0)];
  for (auto _ : state) benchmark::DoNotOptimize(rig().capture(cam, 0).rgb.data);
  state.SetLabel(cam);
}
void BM_RgbDepth(benchmark::State& state) {
  const char* cam = kCameras[state.range(0)];
  for (auto _ : state) benchmark::DoNotOptimize(rig().capture(cam, 0, true).depth.data);
  state.SetLabel(cam);
}
void BM_RgbDepthSegmentation(benchmark::State& state) {
  const char* cam = kCameras[state.range(0)];
  for (auto _ : state) benchmark::DoNotOptimize(rig().capture(cam, 0, true, true).owner.data);
  state.SetLabel(cam);
}
void BM_AllThreeCameras(benchmark::State& state) {
  int64_t t = 0;
  for (auto _ : state) {
    for (const char* cam : kCameras) benchmark::DoNotOptimize(rig().capture(cam, t).rgb.data);
    t += 100000;
  }
  state.SetLabel("stereo_left + stereo_right + hand_camera, RGB with shadows and noise");
}

/// Builds the scene model and the GL context once, outside the timed benchmarks.
void BM_Setup(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(&rig());
}
/// The renderer alone (no sensor model) on the rig's model: shadow map size
/// range(0) (0 = shadows off).
void BM_RenderOnly(benchmark::State& state) {
  using namespace bookgrasp::sim_render;
  RendererSettings settings;
  settings.shadows = state.range(0) != 0;
  settings.shadow_size = settings.shadows ? static_cast<int>(state.range(0)) : 1024;
  mjModel* m = rig().model().model();
  const auto saved = m->vis.quality;
  OffscreenRenderer r(m, settings);  // the GL context reads the shadow size once, at creation
  m->vis.quality = saved;
  RenderRequest req;
  req.camera = "stereo_left";
  for (auto _ : state) benchmark::DoNotOptimize(r.render(rig().model().data(), req).rgb.data);
  state.SetLabel(settings.shadows ? "stereo_left RGB, shadow map " + std::to_string(settings.shadow_size)
                                  : std::string("stereo_left RGB, no shadows"));
}
BENCHMARK(BM_RenderOnly)->Arg(0)->Arg(512)->Arg(1024)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Setup)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Rgb)->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RgbDepth)->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RgbDepthSegmentation)->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_AllThreeCameras)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
