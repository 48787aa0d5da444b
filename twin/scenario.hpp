// A scenario: everything one simulation run needs (model, motion, flip schedule, duration,
// seed, latitude). A plain struct: load it from YAML, or build and edit it in code.
// Format reference: docs/scenario.md. Units: files deg, deg/s, s, m, m/s^2; code rad, rad/s.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "estimator/fields.hpp"
#include "estimator/input_error.hpp"
#include "twin/flip_schedule.hpp"
#include "twin/motion.hpp"
#include "twin/sensor/sensor_model.hpp"
#include "twin/world.hpp"

namespace driftless::twin {

/// How the system knows its platform angles (the log's plat1_deg/plat2_deg).
enum class PlatformReadback {
  end_stops,  // hardware with end-stop switches only: commanded +/- flip angle at rest, empty while moving
  encoder,    // an ideal encoder: the joint angle at every sample
};
const char* readback_name(PlatformReadback r);

/// The model config (`model:` block): the box and its two sensors.
struct ModelConfig {
  BoxParams box;
  SensorParams sensor1 = mpu6050_defaults();  // `model.sensor1`: effect catalogue, docs/effects.md
  SensorParams sensor2 = mpu6050_defaults();  // `model.sensor2`
  double time_offset_s = 0.0;  // `model.time_offset_s`, s: the sensors sample this long before
                               // the log's time stamp (0 <= offset <= 1 s in simulate)
  void validate() const;
};

/// One simulation run.
struct Scenario {
  std::string name = "default";
  std::string description;
  double duration_s = 600.0;        // s
  std::uint64_t seed = 1;           // seeds motion patterns and sensor effects
  double latitude_deg = 52.0;       // deg, north positive (Earth rate Omega (0, cos, sin) in ENU)
  double sample_rate_hz = 100.0;    // output (log) rate, Hz
  double physics_dt_s = 0.001;      // MuJoCo time step, s; 1/(sample_rate_hz physics_dt_s) must be an integer
  PlatformReadback platform_readback = PlatformReadback::end_stops;
  ModelConfig model;
  MotionConfig motion;
  FlipScheduleParams flip_schedule;
  std::filesystem::path base_dir;   // resolves relative paths (the scenario file's folder)

  /// Throws std::invalid_argument naming the field on a bad or inconsistent value.
  void validate() const;
  /// Physics steps per output sample.
  long steps_per_sample() const;
  /// Output samples in the run (t = 0, 1/rate, ... < duration).
  std::uint64_t total_samples() const;
};

/// Loads a scenario file (or a built-in scenario by name: "default", "static", ...). Keys not
/// given keep their defaults. Errors name the file, line and key (driftless::InputError).
Scenario load_scenario(const std::string& path_or_builtin);
/// Parses scenario YAML text; `file` names it in error messages; `base_dir` resolves relative paths.
Scenario parse_scenario(const std::string& yaml_text, const std::string& file,
                        const std::filesystem::path& base_dir = {});
/// The built-in default scenario (models/scenarios/default.yaml, embedded in the binary).
Scenario default_scenario();
/// Names of the built-in scenarios.
std::vector<std::string> builtin_scenarios();

/// Loads a model-config file (a YAML file holding `model:`) over `base`.
ModelConfig load_model_config(const std::filesystem::path& path, const ModelConfig& base);

/// The resolved scenario as YAML: every default explicit; parse_scenario() reads it back.
std::string emit_scenario(const Scenario& s);
/// The resolved scenario as a document tree (emit_scenario writes it).
fields::Node scenario_node(const Scenario& s);
/// A model config as the `model:` block's tree.
fields::Node model_node(const ModelConfig& m);

}  // namespace driftless::twin
