// diagnose on a 1 h, 100 Hz MuJoCo twin log (pan/tilt, a hidden scale error): CSV parsing,
// replay, fits, the forward selection, the noise model, summaries, report JSON. Target (issue
// 12): at most 2 s and 150 MB peak. The log is simulated once and kept in the temp folder.
#include <benchmark/benchmark.h>

#include <filesystem>

#include <sys/resource.h>

#include "diagnose/apply.hpp"
#include "diagnose/compare.hpp"
#include "diagnose/report.hpp"
#include "twin/scenario.hpp"
#include "twin/simulator.hpp"

namespace {

using namespace driftless;

twin::SensorParams log_sensor() {
  twin::SensorParams p = diagnose::deterministic_part(twin::mpu6050_defaults());
  p.white_noise.enabled = p.bias_instability.enabled = p.rate_random_walk.enabled = p.quantization.enabled = true;
  return p;
}

twin::Scenario hour_scenario() {
  twin::Scenario sc = twin::load_scenario(std::string(DRIFTLESS_SOURCE_DIR) + "/models/scenarios/pan_tilt.yaml");
  sc.duration_s = 3600.0;
  sc.seed = 1;
  sc.model.sensor1 = sc.model.sensor2 = log_sensor();
  return sc;
}

std::filesystem::path make_hour_log() {
  const auto path = std::filesystem::temp_directory_path() / "driftless_bench_compare_twin_1h.csv";
  if (std::filesystem::exists(path)) return path;
  twin::Scenario sc = hour_scenario();
  sc.model.sensor1.scale_factor.value_pct = Eigen::Vector3d(2.0, 0.0, 0.0);
  twin::simulate_to_log(sc, path);
  return path;
}

void BM_CompareDiagnose1h(benchmark::State& state) {
  const auto path = make_hour_log();
  diagnose::CompareModel m = diagnose::default_compare_model();
  const twin::Scenario sc = hour_scenario();
  m.sensor = {sc.model.sensor1, sc.model.sensor2};
  m.box = sc.model.box;
  for (auto _ : state) {
    // driftless diagnose: parse and replay the log, the forward selection, the summaries
    diagnose::CompareOptions opt;
    const diagnose::Replay r = diagnose::replay_log(path, opt.replay);
    const diagnose::CompareResult res = diagnose::compare(r, m, opt);
    benchmark::DoNotOptimize(diagnose::diagnosis_json(res));
    state.counters["selected"] = static_cast<double>(res.selected.size());
    state.counters["first_evidence"] = res.selected.empty() ? 0.0 : res.selected.front().evidence;
  }
  // the process's peak resident set, MB (includes simulating the log when it was not cached:
  // run twice for the diagnose figure alone)
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  state.counters["peak_rss_MB"] = static_cast<double>(ru.ru_maxrss) / 1024.0;
}
BENCHMARK(BM_CompareDiagnose1h)->Unit(benchmark::kSecond)->Iterations(1)->MeasureProcessCPUTime()->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
