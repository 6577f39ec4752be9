// Physics speed of the simulated world: steps per second for the default scene.
#include <benchmark/benchmark.h>

#include "services/sim_world/sim_world.h"

namespace {
const std::string kScene = std::string(BOOKGRASP_SOURCE_DIR) + "/config/scenes/default.yaml";

void BM_PhysicsStep(benchmark::State& state) {
  bookgrasp::SimWorld w(bookgrasp::scene::load_scene(kScene, static_cast<uint64_t>(state.range(0))), {});
  w.model().set_arm_setpoint({0.3, 0.4, 0.0, 0.8, 0.0, 0.5, 0.0});
  int64_t steps = 0;
  for (auto _ : state) {
    w.model().step(100);
    steps += 100;
  }
  state.counters["steps_per_s"] = benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate);
  state.counters["books"] = static_cast<double>(w.model().scene().books.size());
}
BENCHMARK(BM_PhysicsStep)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

void BM_AdvanceWithOutputs(benchmark::State& state) {
  bookgrasp::SimWorld w(bookgrasp::scene::load_scene(kScene, 1), {});
  int64_t t = w.now_utime();
  for (auto _ : state) {
    t += 100000;  // 0.1 s: 50 steps, 10 SIM_STATE, 1 SIM_GROUND_TRUTH
    benchmark::DoNotOptimize(w.advance_to(t));
  }
  state.counters["sim_s_per_s"] = benchmark::Counter(0.1 * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_AdvanceWithOutputs)->Unit(benchmark::kMillisecond);

void BM_BuildModel(benchmark::State& state) {
  const auto scene = bookgrasp::scene::load_scene(kScene, 1);
  for (auto _ : state) benchmark::DoNotOptimize(bookgrasp::scene::SimModel::build(scene));
}
BENCHMARK(BM_BuildModel)->Unit(benchmark::kMillisecond);
}  // namespace

BENCHMARK_MAIN();
