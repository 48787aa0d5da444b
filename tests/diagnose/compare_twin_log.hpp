// "Measured" logs from the MuJoCo twin itself for compare/diagnose tests: a built-in scenario
// (pan_tilt or vehicle) shortened and re-seeded, its sensors replaced by the test's, simulated
// by the twin's Simulator and written through the LogWriter (the documented log format), then
// replayed from the file like any user's log.
#pragma once

#include <filesystem>
#include <string>

#include <fmt/core.h>

#include "diagnose/compare.hpp"
#include "tests/temp_path.hpp"
#include "twin/scenario.hpp"
#include "twin/simulator.hpp"

namespace driftless::diagnose::twinlog {

using namespace driftless::twin;  // the sensor model, scenario and simulator

/// The log's sensor: MPU6050 defaults with the run-to-run draws fixed at their means (so the
/// planted effect is the only difference from the model), noise processes and ADC kept, and a
/// turn-on bias the comparison must estimate as a nuisance.
inline SensorParams base_sensor() {
  SensorParams p = deterministic_part(mpu6050_defaults());
  p.white_noise.enabled = true;
  p.bias_instability.enabled = true;
  p.rate_random_walk.enabled = true;
  p.quantization.enabled = true;
  p.constant_bias.value_dps = Eigen::Vector3d(1.5, -2.0, 0.7);
  return p;
}

/// A built-in scenario ("pan_tilt", "vehicle", ...) shortened to `duration_s` with `seed`, both
/// sensors base_sensor(), flips every `standstill_s`.
inline Scenario scenario(const std::string& name, double duration_s, std::uint64_t seed, double standstill_s = 10.0) {
  Scenario sc = load_scenario(std::string(DRIFTLESS_SOURCE_DIR) + "/models/scenarios/" + name + ".yaml");
  sc.duration_s = duration_s;
  sc.seed = seed;
  sc.flip_schedule.standstill_s = standstill_s;
  sc.model.sensor1 = base_sensor();
  sc.model.sensor2 = base_sensor();
  return sc;
}

/// Simulates `sc` into a log file named after `tag` in the temp folder; returns its path.
inline std::filesystem::path simulate(const Scenario& sc, const std::string& tag) {
  const auto path = test::temp_path(fmt::format("driftless_twinlog_{}_{}_{}.csv", tag, sc.seed, static_cast<long>(sc.duration_s)));
  simulate_to_log(sc, path);
  return path;
}

/// The comparison model of a scenario: its box, sensors and rate (what a user's model file says).
inline CompareModel model_of(const Scenario& sc) {
  CompareModel m = default_compare_model();
  m.sensor = {sc.model.sensor1, sc.model.sensor2};
  m.box = sc.model.box;
  m.time_offset_s = sc.model.time_offset_s;
  m.sample_rate_hz = sc.sample_rate_hz;
  m.latitude_deg = sc.latitude_deg;
  m.is_scenario = true;
  m.scenario = sc;
  m.source = "scenario " + sc.name;
  return m;
}

/// Replays a log file (the model runs at the log's rate, as the commands do).
inline Replay replay(const std::filesystem::path& log, const CompareModel&) { return replay_log(log, ReplayOptions{}); }

}  // namespace driftless::diagnose::twinlog
