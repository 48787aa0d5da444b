// Log reader and writer speed on a twin-like log (35 columns, the written precisions): rows per
// second for parsing (LogReader::next) and for formatting (LogWriter::write), and the two number
// primitives alone. Run: build/bench/bench_log
#include <charconv>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "estimator/fixed_decimal.hpp"
#include "estimator/log.hpp"

namespace {

using namespace driftless;
namespace fs = std::filesystem;

constexpr int kRows = 200000;

// a 100 Hz twin-like sample: noisy gyro outputs, platforms at rest, every optional group
Sample twin_like_sample(int i, std::mt19937_64& rng) {
  std::normal_distribution<double> noise(0.0, 0.1);
  Sample s;
  s.t_s = 0.01 * i;
  s.gyro1_dps = Eigen::Vector3d(-11.1 + noise(rng), 0.5 + noise(rng), -6.6 + noise(rng));
  s.gyro2_dps = Eigen::Vector3d(-4.4 + noise(rng), -7.6 + noise(rng), -5.5 + noise(rng));
  s.plat1_deg = 90.0;
  s.plat2_deg = 90.0;
  s.set_q_enu_from_body(Eigen::Quaterniond(Eigen::AngleAxisd(0.52, Eigen::Vector3d::UnitZ())));
  s.ref_p_enu_m = Eigen::Vector3d(0, 0, 0.772);
  s.accel1_mps2 = Eigen::Vector3d(noise(rng), noise(rng), 9.8 + noise(rng));
  s.accel2_mps2 = Eigen::Vector3d(noise(rng), 9.6 + noise(rng), noise(rng));
  s.temp1_c = 25.001;
  s.temp2_c = 25.001;
  s.true_bias1_dps = Eigen::Vector3d(-11.198471473, 0.555447941, -6.633170910);
  s.true_bias2_dps = Eigen::Vector3d(-4.448931418, -7.609645993, -5.580433079);
  s.true_rate_body_dps = Eigen::Vector3d(0.001286140, 0.002227659, 0.003292367);
  s.true_plat1_deg = 89.926611 + noise(rng) * 0.01;
  s.true_plat2_deg = 90.079235 + noise(rng) * 0.01;
  return s;
}

constexpr std::uint32_t kAll = kFieldAccel | kFieldTemp | kFieldRefQ | kFieldRefP | kFieldTrueBias |
                               kFieldTrueRate | kFieldTruePlat;

const std::vector<Sample>& samples() {
  static const std::vector<Sample> v = [] {
    std::mt19937_64 rng(1);
    std::vector<Sample> out;
    for (int i = 0; i < kRows; ++i) out.push_back(twin_like_sample(i, rng));
    return out;
  }();
  return v;
}

const fs::path& log_file() {
  static const fs::path p = [] {
    const fs::path path = fs::temp_directory_path() / "driftless_bench_log.csv";
    log::Metadata meta;
    meta.set("sample_rate_hz", "100");
    log::LogWriter w(path, meta, kAll);
    for (const Sample& s : samples()) w.write(s);
    w.finish(true);
    return path;
  }();
  return p;
}

void BM_LogParse(benchmark::State& state) {
  const fs::path& path = log_file();
  for (auto _ : state) {
    log::LogReader reader(path);
    Sample s;
    double sum = 0.0;
    while (reader.next(s)) sum += s.gyro1_dps.x();
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * kRows);
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(fs::file_size(path)));
}
// wall time: the reader parses on a thread of its own, whose CPU the calling thread's clock misses
BENCHMARK(BM_LogParse)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_LogWrite(benchmark::State& state) {
  log::Metadata meta;
  meta.set("sample_rate_hz", "100");
  for (auto _ : state) {
    log::LogWriter w("/dev/null", meta, kAll);
    for (const Sample& s : samples()) w.write(s);
    w.finish(false);
  }
  state.SetItemsProcessed(state.iterations() * kRows);
}
BENCHMARK(BM_LogWrite)->Unit(benchmark::kMillisecond);

// the primitives: one number of a log's typical width
void BM_WriteFixed(benchmark::State& state) {
  std::vector<double> v;
  for (const Sample& s : samples()) v.push_back(s.gyro1_dps.x());
  char buf[64];
  for (auto _ : state) {
    for (double x : v) benchmark::DoNotOptimize(io::write_fixed(buf, x, 7));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(v.size()));
}
BENCHMARK(BM_WriteFixed);

void BM_ToCharsFixed(benchmark::State& state) {
  std::vector<double> v;
  for (const Sample& s : samples()) v.push_back(s.gyro1_dps.x());
  char buf[64];
  for (auto _ : state) {
    for (double x : v) benchmark::DoNotOptimize(std::to_chars(buf, buf + 64, x, std::chars_format::fixed, 7).ptr);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(v.size()));
}
BENCHMARK(BM_ToCharsFixed);

void BM_ParseDecimal(benchmark::State& state) {
  std::vector<std::string> text;
  char buf[64];
  for (const Sample& s : samples()) text.emplace_back(buf, io::write_fixed(buf, s.gyro1_dps.x(), 7));
  for (auto _ : state) {
    double v = 0.0;
    for (const auto& t : text) benchmark::DoNotOptimize(io::parse_decimal(t.data(), t.data() + t.size(), v));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(text.size()));
}
BENCHMARK(BM_ParseDecimal);

void BM_FromChars(benchmark::State& state) {
  std::vector<std::string> text;
  char buf[64];
  for (const Sample& s : samples()) text.emplace_back(buf, io::write_fixed(buf, s.gyro1_dps.x(), 7));
  for (auto _ : state) {
    double v = 0.0;
    for (const auto& t : text) benchmark::DoNotOptimize(std::from_chars(t.data(), t.data() + t.size(), v).ptr);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(text.size()));
}
BENCHMARK(BM_FromChars);

}  // namespace

BENCHMARK_MAIN();
