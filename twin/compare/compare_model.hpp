// The model side of a comparison: the two sensors' parameters from a model/scenario YAML file
// (or the embedded MPU6050 defaults), their noise-free prediction along a replayed log, and
// writing a model back with a fitted effect added (diagnose --apply).
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <yaml-cpp/yaml.h>

#include "twin/compare/replay.hpp"
#include "twin/sensor/sensor_model.hpp"

namespace driftless::twin {

/// The parts of a model config a comparison uses.
struct CompareModel {
  std::array<SensorParams, 2> sensor;  // sensor1, sensor2
  double sample_rate_hz = kNaN;        // Hz, the scenario's rate when the file states one
  double latitude_deg = kNaN;          // deg, the scenario's latitude when stated
  std::string source;                  // file name, or "embedded MPU6050 defaults"
  YAML::Node root;                     // the whole file, kept for --apply
};

/// The embedded default: both sensors mpu6050_defaults().
CompareModel default_compare_model();
/// Reads `model: {sensor1: {...}, sensor2: {...}}` (a scenario file or a file with only `model:`).
/// Throws std::runtime_error naming the file and key on bad input.
CompareModel load_compare_model(const std::filesystem::path& path);
/// Writes the model (with `root`'s other keys kept) to `path`.
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
SensorParams deterministic_part(const SensorParams& p);

/// Predicts sensor `s` (0 or 1): deterministic chain, DLPF, nonlinearity and saturation.
SensorPrediction predict_sensor(const Replay& r, int s, const SensorParams& p);

/// Per-sample standard deviation of the model's white noise after its DLPF, deg/s.
double white_noise_floor_dps(const SensorParams& p, int axis, double sample_rate_hz);
/// Variance of a block mean (block_len samples) of the model's DLPF-filtered white noise,
/// relative to that of unfiltered white noise of the same density (1 without a DLPF).
double block_mean_variance_ratio(const SensorParams& p, double sample_rate_hz, std::size_t block_len);
/// Lag-1 autocorrelation the model's DLPF gives white noise (0 without a DLPF).
double dlpf_lag1_autocorrelation(const SensorParams& p, double sample_rate_hz);

}  // namespace driftless::twin
