// End-to-end render speed: log replay -> OSMesa drawing with overlay -> ffmpeg (libx264) MP4.
// The figure that matters is frames_per_s (whole pipeline, encoding included) on this machine;
// 640x480 at 30 frames/s must reach at least 30 to render in real time. BM_RenderTwin* is what
// `driftless demo` renders: the twin's model and carrier, the auto camera with its close-ups,
// the full overlay (filter, three charts).
#include <filesystem>

#include <benchmark/benchmark.h>

#include "renders/render_job.hpp"
#include "renders/twin_source.hpp"

#define DRIFTLESS_BINARY_DIR "/tmp"
#include "tests/renders/render_fixture.hpp"

namespace {

using namespace driftless;
using namespace driftless::render;

const std::filesystem::path& bench_log() {
  static const std::filesystem::path path = [] {
    const auto dir = std::filesystem::temp_directory_path() / "driftless_bench_render";
    std::filesystem::create_directories(dir);
    testing::FlipSchedule sched;  // a flip every 3 s: the scene changes as in real runs
    testing::write_flip_log(dir / "run.csv", 10.0, 100.0, sched);
    return dir / "run.csv";
  }();
  return path;
}

// 20 s of the default scenario with a flip every 3 s (the demo's run flips every 20 s)
const std::filesystem::path& twin_log() {
  static const std::filesystem::path path = [] {
    const auto dir = std::filesystem::temp_directory_path() / "driftless_bench_render";
    std::filesystem::create_directories(dir);
    twin::Scenario sc = twin::default_scenario();
    sc.duration_s = 20.0;
    sc.flip_schedule.standstill_s = 2.0;
    twin::simulate_to_log(sc, dir / "twin.csv");
    return dir / "twin.csv";
  }();
  return path;
}

void report(benchmark::State& state, std::uint64_t frames, double wall, double draw) {
  state.counters["frames_per_s"] = static_cast<double>(frames) / wall;
  state.counters["draw_ms_per_frame"] = 1e3 * draw / static_cast<double>(frames);
  state.counters["x_real_time"] = static_cast<double>(frames) / 30.0 / wall;
}

void run_twin(benchmark::State& state, int w, int h) {
  log::LogReader head(twin_log());
  TwinPoser poser(twin::default_scenario().model.box, carrier_from_metadata(head.metadata()));
  RenderParams p;
  p.scene.width_px = w;
  p.scene.height_px = h;
  p.timeline.fps = 30;
  p.out = twin_log().parent_path() / fmt::format("bench_twin_{}x{}.mp4", w, h);
  std::uint64_t frames = 0;
  double wall = 0, draw = 0;
  for (auto _ : state) {
    LogFrameSource src(twin_log(), poser);
    const auto stats = render_video(src, p);
    frames += stats.frames;
    wall += stats.wall_s;
    draw += stats.draw_s;
  }
  report(state, frames, wall, draw);
}

void run(benchmark::State& state, int w, int h, const char* preset, bool overlay) {
  auto model = testing::load_model();
  BoxPoser poser(model.get());
  const auto out = bench_log().parent_path() / fmt::format("bench_{}x{}.mp4", w, h);
  RenderParams p;
  p.scene.width_px = w;
  p.scene.height_px = h;
  p.timeline.fps = 30;
  p.encoder.preset = preset;
  p.overlay = overlay;
  p.out = out;
  std::uint64_t frames = 0;
  double wall = 0, draw = 0;
  for (auto _ : state) {
    LogFrameSource src(bench_log(), poser);
    const auto stats = render_video(src, p);
    frames += stats.frames;
    wall += stats.wall_s;
    draw += stats.draw_s;
  }
  report(state, frames, wall, draw);
}

void BM_RenderTwin640x480(benchmark::State& s) { run_twin(s, 640, 480); }
void BM_Render640x480Ultrafast(benchmark::State& s) { run(s, 640, 480, "ultrafast", true); }
void BM_Render640x480Veryfast(benchmark::State& s) { run(s, 640, 480, "veryfast", true); }
void BM_Render640x480NoOverlay(benchmark::State& s) { run(s, 640, 480, "ultrafast", false); }
void BM_Render1280x720Ultrafast(benchmark::State& s) { run(s, 1280, 720, "ultrafast", true); }

// each iteration renders 10 s of video (300 frames); the twin run 20 s (600 frames)
BENCHMARK(BM_RenderTwin640x480)->Unit(benchmark::kSecond)->Iterations(2);
BENCHMARK(BM_Render640x480Ultrafast)->Unit(benchmark::kSecond)->Iterations(2);
BENCHMARK(BM_Render640x480Veryfast)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(BM_Render640x480NoOverlay)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(BM_Render1280x720Ultrafast)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
