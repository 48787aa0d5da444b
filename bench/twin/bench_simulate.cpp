// Simulator throughput: simulated seconds per CPU second (= per wall second on an idle core) for the static, pan/tilt and vehicle
// scenarios (samples generated, no log), and with the log written. The 14 h static run of the
// paper's Fig. 4 is measured with the CLI (see docs/model.md):
//   /usr/bin/time -v build/bin/driftless simulate --scenario static --out /tmp/static14h
#include <filesystem>

#include <benchmark/benchmark.h>

#include "twin/scenario.hpp"
#include "twin/simulator.hpp"

namespace {

using driftless::Sample;
using namespace driftless::twin;

void run_scenario(benchmark::State& state, const char* name, double duration_s) {
  Scenario sc = load_scenario(name);
  sc.duration_s = duration_s;
  double sim_s = 0;
  for (auto _ : state) {
    Simulator sim(sc);
    Sample s;
    while (sim.next(s)) benchmark::DoNotOptimize(s.gyro1_dps);
    sim_s += sc.duration_s;
  }
  state.counters["sim_s_per_cpu_s"] = benchmark::Counter(sim_s, benchmark::Counter::kIsRate);
}

void BM_Static(benchmark::State& state) { run_scenario(state, "static", 1800); }
void BM_PanTilt(benchmark::State& state) { run_scenario(state, "pan_tilt", 120); }
void BM_Vehicle(benchmark::State& state) { run_scenario(state, "vehicle", 120); }
void BM_Ship(benchmark::State& state) { run_scenario(state, "ship", 120); }

// static run with the log written (the 14 h figure scales from this)
void BM_StaticToLog(benchmark::State& state) {
  Scenario sc = load_scenario("static");
  sc.duration_s = 1800;
  const auto path = std::filesystem::temp_directory_path() / "driftless_bench_static.csv";
  double sim_s = 0;
  for (auto _ : state) {
    simulate_to_log(sc, path);
    sim_s += sc.duration_s;
  }
  std::filesystem::remove(path);
  state.counters["sim_s_per_cpu_s"] = benchmark::Counter(sim_s, benchmark::Counter::kIsRate);
}

BENCHMARK(BM_Static)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_StaticToLog)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_PanTilt)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_Vehicle)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_Ship)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
