// SensorModel::step() cost: a 14 h run at 100 Hz calls it 5 million times per sensor.
#include <benchmark/benchmark.h>

#include <cmath>

#include "twin/sensor/sensor_model.hpp"

using namespace driftless::twin;

namespace {

void run(benchmark::State& state, const SensorParams& p) {
  SensorModel m(p, 100.0, 1);
  SensorTruth tr;
  tr.f_mps2 = {0.0, 0.0, 9.81};
  long k = 0;
  for (auto _ : state) {
    tr.t_s = k * 0.01;
    tr.w_radps = {1e-3 * std::sin(0.001 * k), 2e-5, 5e-5};
    benchmark::DoNotOptimize(m.step(tr));
    ++k;
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_StepMpu6050Defaults(benchmark::State& s) { run(s, mpu6050_defaults()); }
void BM_StepIdeal(benchmark::State& s) { run(s, ideal_sensor()); }
void BM_StepEveryEffect(benchmark::State& s) {
  SensorParams p = mpu6050_defaults();
  for (const auto& id : effect_ids()) set_effect_enabled(p, id, true);
  run(s, p);
}

}  // namespace

BENCHMARK(BM_StepMpu6050Defaults);
BENCHMARK(BM_StepIdeal);
BENCHMARK(BM_StepEveryEffect);
BENCHMARK_MAIN();
