// Sweep throughput: one 1 h fast-path run, and N Monte-Carlo runs of 1 h on 1 thread against
// all threads (the speed-up reported in docs/sweep.md). Run: build/bench/bench_sweep
#include <thread>

#include <benchmark/benchmark.h>

#include "studies/jobs.hpp"
#include "studies/sweep.hpp"

namespace {

using namespace driftless::studies;

SweepConfig config(int runs) {
  SweepConfig c = parse_sweep(R"(
name: bench
runner: fast
scenario: default
duration_s: 3600
fixed:
  estimator.initial_sigma_dps: 25
)", "bench.yaml", ".");
  c.monte_carlo = runs;
  return c;
}

// one 1 h run (360 000 samples at 100 Hz) through sensor models, filter and metrics
void BM_FastRun1h(benchmark::State& state) {
  const SweepConfig c = config(1);
  const auto specs = expand(c);
  const SweepJob job = make_job(c);
  for (auto _ : state) benchmark::DoNotOptimize(job(specs[0]));
  state.counters["samples_per_s"] =
      benchmark::Counter(360000.0 * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_FastRun1h)->Unit(benchmark::kSecond)->Iterations(1);

// N runs of 1 h on `threads` threads (arg 0: runs, arg 1: threads, 0 = all cores)
void BM_Sweep1h(benchmark::State& state) {
  const SweepConfig c = config(static_cast<int>(state.range(0)));
  const auto specs = expand(c);
  std::vector<std::size_t> idx(specs.size());
  for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = i;
  const SweepJob job = make_job(c);
  for (auto _ : state) benchmark::DoNotOptimize(run_parallel(specs, idx, job, static_cast<int>(state.range(1))));
  state.counters["runs"] = static_cast<double>(specs.size());
  state.counters["threads"] = state.range(1) > 0 ? static_cast<double>(state.range(1))
                                                 : static_cast<double>(std::thread::hardware_concurrency());
}
BENCHMARK(BM_Sweep1h)->Args({20, 1})->Args({20, 0})->Args({100, 0})->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
