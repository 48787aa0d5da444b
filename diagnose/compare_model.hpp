// The model side of a comparison: the two sensors' parameters from a model/scenario YAML file
// (or the embedded MPU6050 defaults), their noise-free prediction along a replayed log, and
// writing a model back with a fitted effect added (diagnose --apply).
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "diagnose/replay.hpp"
#include "twin/scenario.hpp"
#include "twin/sensor/sensor_model.hpp"

namespace driftless::diagnose {

/// The model side of a comparison: twin-core's model config (box + sensors, every key of a
/// scenario's `model:` block) plus the scenario keys a comparison uses.
struct CompareModel {
  std::array<twin::SensorParams, 2> sensor;  // sensor1, sensor2 (the working copy of config.sensor1/2)
  twin::BoxParams box;                       // hinge axes, end stops and their errors, motors
  double time_offset_s = 0.0;          // s; the sensors sample this long before the log's stamp
  double sample_rate_hz = kNaN;        // Hz, the scenario's rate when the file is a scenario (the
                                       // model runs at the log's rate; --resample uses this one)
  double latitude_deg = kNaN;          // deg, the scenario's latitude when the file is a scenario
  std::string source;                  // file name, or "embedded MPU6050 defaults"
  bool is_scenario = false;            // the file is a whole scenario (else a `model:`-only file)
  twin::Scenario scenario;                   // the parsed scenario (its other keys are kept by --apply)
  /// The model config as twin-core holds it.
  twin::ModelConfig config() const;
};

/// The nominal MPU6050: mpu6050_defaults()'s random parts (white noise, bias instability, rate
/// random walk, turn-on bias spread), DLPF and ADC, with no run-to-run spread of the
/// calibration-type effects (scale, cross-axis, g-sensitivity, temperature coefficients,
/// mounting): they sit at their nominal zero, so a unit's own values are findings, not nuisance.
twin::SensorParams nominal_mpu6050();
/// The embedded default: both sensors nominal_mpu6050(), the default box, no time offset, no
/// stated rate (it runs at the log's rate, like a model file).
CompareModel default_compare_model();
/// Reads a scenario file or a file with only `model:` through twin-core's parser
/// (parse_scenario / load_model_config): every key of the model block is honoured.
/// Throws std::runtime_error naming the file, line and key on bad input.
CompareModel load_compare_model(const std::filesystem::path& path);
/// Writes the model to `path` in the form it was read: a whole scenario (emit_scenario) or a
/// `model:`-only file; both `simulate --scenario` (scenarios) and `compare --model` read it back.
void save_compare_model(const CompareModel& m, const std::filesystem::path& path);

/// The model's noise-free prediction of one sensor along a replay, deg/s, plus the temperature
/// used (the log's when it has one, else the model's temperature curve), degC.
struct SensorPrediction {
  std::vector<Eigen::Vector3d> gyro_dps;
  std::vector<double> temp_c;
  bool temp_from_log = false;
};

/// Expected-value parameters: run-to-run sigmas dropped, random processes, noise, jitter,
/// quantisation and missing codes off (they cannot be predicted sample by sample).
twin::SensorParams deterministic_part(const twin::SensorParams& p);

/// Predicts sensor `s` (0 or 1): deterministic chain, DLPF, nonlinearity and saturation, with
/// the model's end-stop errors (a platform logged at rest on a stop sits at the stop's true
/// angle, unless the log's platform_readback is an encoder) and its sensor time offset.
/// `settled_offset_deg` (platform x [-stop, +stop]) adds how far the servo presses each platform
/// into its stop (settled_stop_offsets_deg).
SensorPrediction predict_sensor(const Replay& r, int s, const twin::SensorParams& p, const twin::BoxParams& box = {},
                                double time_offset_s = 0.0,
                                const Eigen::Matrix2d& settled_offset_deg = Eigen::Matrix2d::Zero());

/// How far past (nominal + error) each platform rests when its servo presses it onto a stop,
/// deg, [platform][0: - stop, 1: + stop]: the MuJoCo box settled on its stops (level, still).
Eigen::Matrix2d settled_stop_offsets_deg(const twin::BoxParams& box);

/// True when platform s (0 or 1) rests on one of its end stops at sample k and the log reports
/// the nominal stop angle there (end-stop switches), so the box's stop errors apply.
int on_stop_side(const Replay& r, int s, std::size_t k, const twin::BoxParams& box);

/// The model's white noise at the output, per unit density: its per-sample variance (Hz, i.e.
/// (deg/s)^2 per (deg/s/rtHz)^2) and normalised autocorrelation at lags 0..lags. Without a DLPF,
/// or when its bandwidth reaches fs/2, the noise is white (variance fs, or 2B when it aliases);
/// otherwise it passes the DLPF, which colours it (docs/effects.md, 4 white_noise).
struct WhiteNoiseShape {
  double variance_hz = 0.0;
  std::vector<double> rho;  // rho[0] = 1
};
WhiteNoiseShape white_noise_shape(const twin::SensorParams& p, double sample_rate_hz, int lags);

/// Per-sample standard deviation of the model's white noise after its DLPF, deg/s.
double white_noise_floor_dps(const twin::SensorParams& p, int axis, double sample_rate_hz);
/// Variance of a block mean (block_len samples) of the model's DLPF-filtered white noise,
/// relative to that of unfiltered white noise of the same density (1 without a DLPF).
double block_mean_variance_ratio(const twin::SensorParams& p, double sample_rate_hz, std::size_t block_len);
/// Lag-1 autocorrelation the model's DLPF gives white noise (0 without a DLPF).
double dlpf_lag1_autocorrelation(const twin::SensorParams& p, double sample_rate_hz);

}  // namespace driftless::diagnose
