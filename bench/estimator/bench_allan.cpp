// The Allan analysis at the sizes the README quotes: the overlapping octave ADEV with intervals on
// 5.04 M samples (14 h at 100 Hz, in-call), the joint noise fit of its curve, and the streaming pass over
// one channel of 24 h at 400 Hz (34.6 M samples) at bounded memory.
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "estimator/allan.hpp"
#include "estimator/allan_fit.hpp"
#include "estimator/allan_stream.hpp"

namespace {

using namespace driftless;

std::vector<double> noise(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 0.05);
  std::vector<double> x(n);
  double b = 0.0;
  for (auto& v : x) v = 1.0 + g(rng) + (b += 1e-5 * g(rng));
  return x;
}

// the overlapping octave ADEV with its intervals, in-call: wall time (the levels share two threads)
void BM_AdevOctave14h(benchmark::State& state) {
  const auto x = noise(5'040'000, 1);
  est::AllanOptions o;
  for (auto _ : state) {
    const auto curve = est::allan_deviation(x, o);
    benchmark::DoNotOptimize(curve.points.data());
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * x.size()));
}
BENCHMARK(BM_AdevOctave14h)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(5);

void BM_AllanFit14h(benchmark::State& state) {
  const auto x = noise(5'040'000, 2);
  est::AllanOptions o;
  const auto curve = est::allan_deviation(x, o);
  for (auto _ : state) {
    const auto f = est::fit_noise_parameters(curve);
    benchmark::DoNotOptimize(f.N.value);
  }
}
BENCHMARK(BM_AllanFit14h)->Unit(benchmark::kMillisecond);

void BM_StreamOctave24h400Hz(benchmark::State& state) {
  const std::size_t n = 34'560'000, chunk = 1u << 20;
  const auto block = noise(chunk, 3);
  for (auto _ : state) {
    est::StreamingOptions so;
    so.sample_rate_hz = 400.0;
    est::StreamingOctaveDeviation s(so);
    for (std::size_t i = 0; i < n; i += chunk) s.push(std::span<const double>(block.data(), std::min(chunk, n - i)));
    const auto c = s.finish();
    benchmark::DoNotOptimize(c.points.data());
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * n));
}
BENCHMARK(BM_StreamOctave24h400Hz)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
