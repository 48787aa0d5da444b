// Logs this project did not make: tests/diagnose/independent_log.py (numpy, its own kinematics,
// sensor errors, DLPF at 1 kHz, sampling and ADC) writes them in the documented log format; the
// tests replay them from the file like any user's log and diagnose them with the embedded model.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <gtest/gtest.h>

#include "diagnose/apply.hpp"
#include "diagnose/compare.hpp"
#include "tests/temp_path.hpp"

namespace driftless::diagnose::indep {

/// What the generator varies besides the planted effects.
struct Source {
  int seed = 1;
  double rate_hz = 100.0;
  double duration_s = 150.0;
  std::string motion = "pan_tilt";
  double noise_scale = 1.0;
  std::string dlpf = "none";         // none, cfg:N, custom:BW:DELAY
  int lag_sensor = 0;                // 1 or 2: that sensor samples late
  double lag_s = 0.0;
  double time_offset_s = 0.0;
  bool temperature = false;
  bool single = false;               // the single-sensor form: one IMU fixed to the body, ref_q
  bool accel = false;                // (single) its accelerometer columns accel1_*
  std::vector<std::string> plants;   // scale:1:x:3, ...
};

/// Writes the log of `src` into the temp folder (GTest fails on a generator error).
inline std::filesystem::path generate(const Source& src, const std::string& tag) {
  const auto path = test::temp_path(fmt::format("driftless_indep_{}_{}.csv", tag, src.seed));
  std::string cmd = fmt::format("/usr/bin/python3 '{}/tests/diagnose/independent_log.py' --out '{}' --seed {} --rate {} "
                                "--duration {} --motion {} --noise-scale {} --dlpf {}",
                                DRIFTLESS_SOURCE_DIR, path.string(), src.seed, src.rate_hz, src.duration_s, src.motion,
                                src.noise_scale, src.dlpf);
  if (src.lag_sensor > 0) cmd += fmt::format(" --lag {}:{}", src.lag_sensor, src.lag_s);
  if (src.time_offset_s != 0.0) cmd += fmt::format(" --time-offset {}", src.time_offset_s);
  if (src.temperature) cmd += " --temperature";
  if (src.single) cmd += " --single";
  if (src.accel) cmd += " --accel";
  for (const auto& p : src.plants) cmd += " --plant " + p;
  if (std::getenv("DRIFTLESS_INDEP_SHOW")) std::printf("generate: %s\n", cmd.c_str());  // to rerun one case by hand
  const int rc = std::system(cmd.c_str());
  EXPECT_EQ(rc, 0) << "generator failed: " << cmd;
  return path;
}

/// The embedded default model, as `driftless diagnose` without --model uses it.
inline CompareResult diagnose_log(const std::filesystem::path& log, CompareModel* model_out = nullptr) {
  const CompareModel m = default_compare_model();
  const Replay r = replay_log(log, ReplayOptions{});
  if (model_out) *model_out = m;
  return compare(r, m, CompareOptions{});
}

/// --apply then compare again (written to YAML and read back, as the command does). `model_io`:
/// the model `r` was compared with (the embedded default when null), replaced by the written one
/// (a second apply starts from it).
inline CompareResult apply_and_compare(const std::filesystem::path& log, const CompareResult& r, const std::string& tag,
                                       CompareModel* model_io = nullptr) {
  CompareModel m = model_io ? *model_io : default_compare_model();
  apply_result(m, r);
  const auto yaml = test::temp_path(fmt::format("driftless_indep_{}.yaml", tag));
  save_compare_model(m, yaml);
  const CompareModel back = load_compare_model(yaml);
  std::filesystem::remove(yaml);
  if (model_io) *model_io = back;
  return compare(replay_log(log, ReplayOptions{}), back, CompareOptions{});
}

/// The selected candidate of effect `e`, or nullptr.
inline const Candidate* selected(const CompareResult& r, Effect e) {
  for (const auto& c : r.selected)
    if (c.effect == e) return &c;
  return nullptr;
}

/// A random background: rate, noise, motion, DLPF, maybe a lagging sensor (what real sources vary).
inline Source random_source(int seed, bool allow_lag) {
  std::mt19937 g(static_cast<unsigned>(seed) * 7919u + 11u);
  auto pick = [&](auto&& v) { return v[std::uniform_int_distribution<std::size_t>(0, v.size() - 1)(g)]; };
  Source s;
  s.seed = seed;
  s.rate_hz = pick(std::vector<double>{50.0, 100.0, 200.0});
  s.noise_scale = std::uniform_real_distribution<double>(0.5, 3.0)(g);
  s.motion = pick(std::vector<std::string>{"pan_tilt", "pan_tilt", "sweep", "wobble"});
  s.dlpf = pick(std::vector<std::string>{"none", "cfg:1", "cfg:3", "cfg:4"});
  if (allow_lag && std::uniform_real_distribution<double>(0, 1)(g) < 0.35) {
    s.lag_sensor = pick(std::vector<int>{1, 2});
    s.lag_s = std::uniform_real_distribution<double>(0.012, 0.025)(g);
  }
  return s;
}

/// A one-line description of a source for failure messages and rate tables.
inline std::string describe(const Source& s) {
  std::string p;
  for (const auto& x : s.plants) p += " " + x;
  return fmt::format("seed {} {:g} Hz {} noise x{:.2f} dlpf {}{}{}", s.seed, s.rate_hz, s.motion, s.noise_scale, s.dlpf,
                     s.lag_sensor ? fmt::format(" lag s{} {:.0f} ms", s.lag_sensor, 1e3 * s.lag_s) : std::string(), p);
}

}  // namespace driftless::diagnose::indep
