// diagnose on a 1 h, 100 Hz MuJoCo twin log (pan/tilt, a hidden scale error): CSV parsing,
// replay, fits, the forward selection, the noise model, summaries, report JSON. Target (issue
// 12): at most 2 s and 150 MB peak. The log is simulated once and kept in the temp folder.
// Besides, the two inner loops most of its CPU goes through (the likelihood of the white-density
// search, the whitened Gram of a channel's columns), on an hour's 36 000 blocks.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <random>
#include <vector>

#include <sys/resource.h>

#include "diagnose/apply.hpp"
#include "diagnose/bias_filter.hpp"
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

// the hot inner loops of a 1 h diagnosis (36 000 blocks of 0.1 s, the MPU6050's noise): one
// likelihood evaluation of the white-density search (~1 000 per diagnosis) and one whitened Gram
// of 24 regressor columns (each channel's rebuild after a noise refit)
struct HourBlocks {
  diagnose::BlockSeries blocks;
  diagnose::ChannelNoise noise;
  std::vector<double> z;
  Eigen::MatrixXf cols;
  HourBlocks() {
    std::mt19937_64 rng(3);
    std::normal_distribution<double> n(0.0, 1.0);
    const std::size_t m = 36000;
    cols.resize(static_cast<Eigen::Index>(m), 24);
    for (std::size_t j = 0; j < m; ++j) {
      blocks.t_s.push_back(0.05 + 0.1 * static_cast<double>(j));
      blocks.count.push_back(j % 200 < 20 ? 0 : 10);  // a flip every 20 s
      z.push_back(0.01 * n(rng));
      for (Eigen::Index i = 0; i < 24; ++i) cols(static_cast<Eigen::Index>(j), i) = static_cast<float>(n(rng));
    }
    noise.white_dps_rthz = 0.005;
    noise.gm_sigma_dps = 0.1;
    noise.gm_tau_s = 10800.0;
    noise.rrw_dps_rts = 2e-5;
  }
};

void BM_WhiteDensityLikelihood1h(benchmark::State& state) {
  const HourBlocks h;
  for (auto _ : state) benchmark::DoNotOptimize(diagnose::BiasWhitener::neg2_loglik(h.blocks, h.noise, h.z));
}
BENCHMARK(BM_WhiteDensityLikelihood1h)->Unit(benchmark::kMicrosecond);

void BM_WhitenedGram24Columns1h(benchmark::State& state) {
  const HourBlocks h;
  for (auto _ : state) benchmark::DoNotOptimize(diagnose::BiasWhitener::whitened_gram(h.blocks, h.noise, h.cols, h.z).gram(0, 0));
}
BENCHMARK(BM_WhitenedGram24Columns1h)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
