// Estimator speed (the Allan analysis: bench_allan.cpp): `estimate` on a 14 h log (CSV parsing
// included), and the per-sample cost of the live push() path.
#include <cmath>
#include <filesystem>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "estimator/filter.hpp"
#include "estimator/log.hpp"
#include "estimator/pipeline.hpp"
#include "tests/estimator/synth.hpp"

namespace {

using namespace driftless;


test::SynthParams live_params(double duration_s) {
  test::SynthParams p;
  p.duration_s = duration_s;
  p.noise_sigma_dps = 0.05;
  p.gm_sigma_dps = 0.01;
  p.body_rate_dps = [](double t) { return Eigen::Vector3d(3.0 * std::sin(0.05 * t), 1.0, 0.5); };
  return p;
}

void BM_PushLive(benchmark::State& state) {
  const auto p = live_params(600.0);
  const auto samples = test::synth_all(p);
  const auto meta = test::synth_metadata(p);
  std::size_t n = 0;
  for (auto _ : state) {
    est::DriftlessFilter f(est::EstimatorConfig{}, est::box_geometry_from_metadata(meta));
    for (const auto& s : samples) benchmark::DoNotOptimize(f.push(s));
    n += samples.size();
  }
  state.SetItemsProcessed(static_cast<int64_t>(n));
  state.counters["ns_per_sample"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_PushLive)->Unit(benchmark::kMillisecond);

// the same in self-calibrating mode on a box at rest: samples with accel and temperature columns,
// 48 states; each sample's correction is b + k dT + G f and (I - E). `box_at_rest`: 4-dim
// updates; else box dwells (docs/estimator.md section 1d): every sample between flips passes
// the dwell detector and its buffer, a 1-dim update per dwell
void push_live_selfcal(benchmark::State& state, bool box_at_rest) {
  auto p = live_params(600.0);
  p.body_rate_dps = nullptr;
  p.write_accel_temp = true;
  p.temp_rise_c = 2.0;
  p.G_dps_per_g[1](1, 1) = 0.05;
  const auto samples = test::synth_all(p);
  const auto meta = test::synth_metadata(p);
  est::EstimatorConfig cfg;
  cfg.self_calibration = true;
  cfg.box_at_rest = box_at_rest;
  std::size_t n = 0;
  for (auto _ : state) {
    est::DriftlessFilter f(cfg, est::box_geometry_from_metadata(meta));
    for (const auto& s : samples) benchmark::DoNotOptimize(f.push(s));
    n += samples.size();
  }
  state.SetItemsProcessed(static_cast<int64_t>(n));
  state.counters["ns_per_sample"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
void BM_PushLiveSelfCal(benchmark::State& state) { push_live_selfcal(state, true); }
BENCHMARK(BM_PushLiveSelfCal)->Unit(benchmark::kMillisecond);
void BM_PushLiveSelfCalDwells(benchmark::State& state) { push_live_selfcal(state, false); }
BENCHMARK(BM_PushLiveSelfCalDwells)->Unit(benchmark::kMillisecond);

void BM_Estimate14hLog(benchmark::State& state) {
  // setup: a 14 h log as the twin writes it (ref_q and truth columns), once per process
  static const std::filesystem::path path = [] {
    const auto p = std::filesystem::temp_directory_path() / "driftless_bench_14h.csv";
    test::synth_log(live_params(14.0 * 3600.0), p);
    return p;
  }();
  for (auto _ : state) {
    log::LogReader reader(path);
    auto s = est::run_estimate(reader, est::EstimatorConfig{}, nullptr);
    benchmark::DoNotOptimize(s.bias_dps.data());
    state.counters["rows"] = static_cast<double>(s.rows);
    state.counters["updates"] = static_cast<double>(s.counters.updates);
  }
}
BENCHMARK(BM_Estimate14hLog)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
