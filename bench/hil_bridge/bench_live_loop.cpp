// The live loop at 1 kHz from the emulated I2C bus with the estimator and the log writer in the
// loop. Two figures:
//  - LiveLoop1kHzRealtime: wall-clock run; per-sample latency = time the estimate is updated
//    minus the time the sample was due on the bus (p50, p99, max, us), and whether the loop kept
//    up (no FIFO overflow, no sample lost); the second argument 1 holds the CPUs out of deep idle
//    states as `driftless hil` does (hil_bridge/cpu_latency.hpp), 0 does not;
//  - LiveLoopEmulatedI2cAfap: the same loop on a virtual clock: samples per second of CPU.
// The argument fdi = 1 (LiveLoop1kHzRealtime's third, LiveLoopEmulatedI2cAfap's only) runs the
// fault detection beside the filter (driftless hil --fdi).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <vector>

#include <unistd.h>

#include <benchmark/benchmark.h>

#include "estimator/filter.hpp"
#include "estimator/log.hpp"
#include "hil_bridge/clock.hpp"
#include "hil_bridge/cpu_latency.hpp"
#include "hil_bridge/i2c/emulated_bus.hpp"
#include "hil_bridge/i2c/i2c_source.hpp"
#include "hil_bridge/fdi_watch.hpp"
#include "hil_bridge/live_loop.hpp"

namespace driftless::hil {
namespace {

log::Metadata meta_1khz() {
  log::Metadata m;
  m.set("sample_rate_hz", "1000");
  m.set("latitude_deg", "52.0");
  return m;
}

est::FdiParams fdi_1khz() {
  est::FdiParams p;
  p.sample_rate_hz = 1000.0;
  return p;
}

std::filesystem::path temp_log() {
  return std::filesystem::temp_directory_path() / ("driftless-bench-hil-" + std::to_string(::getpid()) + ".csv");
}

template <class ClockT>
struct Rig {
  ClockT clock;
  EmulatedMotors motors{clock, {}};
  BoxAtRestGenerator gen;
  Mpu6050Emulator chip1{0, gen, clock}, chip2{1, gen, clock};
  EmulatedI2cBus bus;
  I2cSource src;
  FlipSchedule schedule{{5.0, 10.0}};
  Rig()
      : gen(params(), &motors),
        bus(clock, virtual_clock()),
        src(bus, clock, source_params()) {
    bus.attach(0x68, &chip1);
    bus.attach(0x69, &chip2);
  }
  VirtualClock* virtual_clock() {
    if constexpr (std::is_same_v<ClockT, VirtualClock>) return &clock;
    return nullptr;
  }
  static BoxAtRestGenerator::Params params() {
    BoxAtRestGenerator::Params p;
    p.sample_rate_hz = 1000.0;
    return p;
  }
  static I2cSourceParams source_params() {
    I2cSourceParams p;
    p.sample_rate_hz = 1000.0;
    p.reset_wait_s = 0.0;
    return p;
  }
};

// samples later than limit_us in a sorted list of latencies (us): how often the bound was missed
std::size_t over_us(const std::vector<double>& sorted_us, double limit_us) {
  return static_cast<std::size_t>(sorted_us.end() - std::upper_bound(sorted_us.begin(), sorted_us.end(), limit_us));
}

void LiveLoop1kHzRealtime(benchmark::State& state) {
  const double duration_s = static_cast<double>(state.range(0));
  std::vector<double> latency_us;
  LiveStats st;
  for (auto _ : state) {
    Rig<SteadyClock> rig;
    if (!rig.src.configure().ok()) state.SkipWithError("configure failed");
    est::DriftlessFilter filter(est::EstimatorConfig{}, est::box_geometry_from_metadata(meta_1khz()));
    log::LogWriter writer(temp_log(), meta_1khz(), rig.src.fields());
    LiveParams lp;
    lp.duration_s = duration_s;
    LiveLoop loop(lp, rig.clock, &writer, &filter);
    loop.set_motors(&rig.src, &rig.motors, &rig.schedule);
    FdiWatch fdi(fdi_1khz());
    if (state.range(2) != 0) loop.set_fdi(&fdi);
    latency_us.clear();
    latency_us.reserve(static_cast<std::size_t>(duration_s * 1000.0) + 10);
    // session time = source time here (the first sample is t = 0 on both)
    loop.on_sample([&](const Sample& s, SampleSource&) {
      latency_us.push_back((rig.clock.now_s() - rig.src.host_time_of(s.t_s)) * 1e6);
    });
    std::atomic<bool> stop{false};
    // range(1) = 1: keep the CPUs out of deep idle states, as `driftless hil` does for a session paced
    // by the wall clock; 0: as with --allow-deep-idle
    std::optional<CpuLatencyRequest> awake;
    if (state.range(1) != 0) awake.emplace(0);
    state.counters["pm_qos_held"] = awake && awake->held();
    st = loop.run(rig.src, nullptr, stop);
    writer.finish(st.complete);
  }
  std::filesystem::remove(temp_log());
  std::sort(latency_us.begin(), latency_us.end());
  auto pct = [&](double p) {
    return latency_us.empty() ? NAN : latency_us[static_cast<std::size_t>(p * static_cast<double>(latency_us.size() - 1))];
  };
  state.counters["samples"] = static_cast<double>(st.samples);
  state.counters["lost"] = static_cast<double>(st.lost_samples);
  state.counters["faults"] = static_cast<double>(st.faults);
  state.counters["kept_up"] = st.samples == static_cast<std::uint64_t>(duration_s * 1000.0) && st.lost_samples == 0;
  state.counters["p50_us"] = pct(0.50);
  state.counters["p99_us"] = pct(0.99);
  state.counters["max_us"] = latency_us.empty() ? NAN : latency_us.back();
  state.counters["over_1ms"] = static_cast<double>(over_us(latency_us, 1000.0));
  state.counters["log_waits"] = static_cast<double>(st.log_waits);
}
BENCHMARK(LiveLoop1kHzRealtime)
    ->ArgNames({"s", "awake", "fdi"})
    ->Args({5, 1, 0})
    ->Args({5, 1, 1})
    ->Args({5, 0, 0})
    ->Args({5, 0, 1})
    ->Args({20, 1, 0})  // long enough for the log writer to hand a 1 MiB chunk to the OS
    ->Iterations(1)
    ->Unit(benchmark::kSecond);

// The machine's floor for the figures above: the same pacing (SteadyClock::sleep_until with its
// 1 us timer slack) at 1 kHz with no work between the wake-ups; lateness = wake-up time minus the
// time asked for (p50, p99, max, us). A live-loop maximum near this one is the machine's (a virtual
// machine's host preempting it, an interrupt), not the loop's. Arguments as LiveLoop1kHzRealtime's.
void SleepLoop1kHzFloor(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0)) * 1000;
  std::vector<double> late_us(n, 0.0);  // touched before the loop: no page fault inside it
  for (auto _ : state) {
    SteadyClock clock;
    std::optional<CpuLatencyRequest> awake;
    if (state.range(1) != 0) awake.emplace(0);
    state.counters["pm_qos_held"] = awake && awake->held();
    const double t0_s = clock.now_s();
    for (std::size_t i = 0; i < n; ++i) {
      const double due_s = t0_s + static_cast<double>(i + 1) * 1e-3;
      clock.sleep_until(due_s);
      late_us[i] = (clock.now_s() - due_s) * 1e6;
    }
  }
  std::sort(late_us.begin(), late_us.end());
  state.counters["p50_us"] = late_us[n / 2];
  state.counters["p99_us"] = late_us[(n - 1) * 99 / 100];
  state.counters["max_us"] = late_us.back();
  state.counters["over_1ms"] = static_cast<double>(over_us(late_us, 1000.0));
}
BENCHMARK(SleepLoop1kHzFloor)->ArgNames({"s", "awake"})->Args({5, 1})->Args({5, 0})->Iterations(1)->Unit(benchmark::kSecond);

void LiveLoopEmulatedI2cAfap(benchmark::State& state) {
  const double duration_s = 20.0;
  std::uint64_t samples = 0;
  for (auto _ : state) {
    Rig<VirtualClock> rig;
    if (!rig.src.configure().ok()) state.SkipWithError("configure failed");
    est::DriftlessFilter filter(est::EstimatorConfig{}, est::box_geometry_from_metadata(meta_1khz()));
    log::LogWriter writer(temp_log(), meta_1khz(), rig.src.fields());
    LiveParams lp;
    lp.duration_s = duration_s;
    LiveLoop loop(lp, rig.clock, &writer, &filter);
    loop.set_motors(&rig.src, &rig.motors, &rig.schedule);
    FdiWatch fdi(fdi_1khz());
    if (state.range(0) != 0) loop.set_fdi(&fdi);
    std::atomic<bool> stop{false};
    const LiveStats st = loop.run(rig.src, nullptr, stop);
    writer.finish(st.complete);
    samples += st.samples;
  }
  std::filesystem::remove(temp_log());
  state.SetItemsProcessed(static_cast<std::int64_t>(samples));
  state.counters["us_per_sample"] =
      benchmark::Counter(static_cast<double>(samples), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(LiveLoopEmulatedI2cAfap)->ArgName("fdi")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace driftless::hil

BENCHMARK_MAIN();
