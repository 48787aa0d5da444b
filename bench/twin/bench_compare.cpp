// compare + diagnose on a 1 h, 100 Hz pan/tilt log (CSV parsing, replay, fits, report JSON).
// Target (issue 5): at most 10 s.
#include <benchmark/benchmark.h>

#include <filesystem>

#include "estimator/log.hpp"
#include "tests/twin/compare_test_log.hpp"
#include "twin/compare/compare.hpp"
#include "twin/compare/report.hpp"

namespace {

std::filesystem::path make_hour_log() {
  using namespace driftless;
  const auto path = std::filesystem::temp_directory_path() / "driftless_bench_compare_1h.csv";
  if (std::filesystem::exists(path)) return path;
  twin::SensorParams p = twin::deterministic_part(twin::mpu6050_defaults());
  p.white_noise.enabled = p.bias_instability.enabled = p.rate_random_walk.enabled = p.quantization.enabled = true;
  twin::SensorParams p1 = p;
  p1.scale_factor.value_pct = Eigen::Vector3d(2.0, 0.0, 0.0);
  const auto lg = twin::testlog::make_log(p1, p, 3600.0, 1);
  log::LogWriter w(path, lg.meta, lg.fields);
  for (const auto& s : lg.samples) w.write(s);
  w.finish(true);
  return path;
}

void BM_CompareDiagnose1h(benchmark::State& state) {
  using namespace driftless;
  const auto path = make_hour_log();
  twin::CompareModel m = twin::default_compare_model();
  twin::SensorParams p = twin::deterministic_part(twin::mpu6050_defaults());
  p.white_noise.enabled = p.bias_instability.enabled = p.rate_random_walk.enabled = p.quantization.enabled = true;
  m.sensor = {p, p};
  for (auto _ : state) {
    twin::CompareOptions opt;
    const twin::Replay r = twin::replay_log(path, opt.replay);
    const twin::CompareResult res = twin::compare(r, m, opt);
    benchmark::DoNotOptimize(twin::diagnosis_json(res));
    state.counters["evidence_best"] = res.ranking.front().evidence;
  }
}
BENCHMARK(BM_CompareDiagnose1h)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
