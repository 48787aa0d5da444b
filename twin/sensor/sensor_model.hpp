// The gyro/accelerometer sensor model: a catalogue of physical effects applied to MuJoCo truth.
// Parameters are in file units (deg/s, deg, s, degC, %); the model runs in rad, rad/s, m/s^2.
// Equations, units, YAML keys and defaults of every effect: docs/effects.md.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "estimator/fields.hpp"
#include "estimator/mpu6050.hpp"
#include "estimator/random.hpp"


namespace driftless::twin {

/// Truth at one output sample, in the (nominal) sensor frame.
/// (Pass Eigen::Vector3d::Zero(), not `{}`: an Eigen vector built from `{}` is uninitialised.)
struct SensorTruth {
  double t_s = 0.0;
  Eigen::Vector3d w_radps = Eigen::Vector3d::Zero();  // inertial rate of the sensor frame, sensor axes
  Eigen::Vector3d f_mps2 = Eigen::Vector3d::Zero();   // specific force, sensor axes
};

/// One output sample of a sensor.
struct SensorReading {
  Eigen::Vector3d gyro_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_mps2 = Eigen::Vector3d::Zero();
  // total additive gyro bias at this sample (constant + temperature + Gauss-Markov + random walk),
  // sensor output axes; excludes g-sensitivity, scale and misalignment (they depend on the input)
  Eigen::Vector3d bias_radps = Eigen::Vector3d::Zero();
  double temp_c = 25.0;  // the chip's temperature output, degC
};

// ---- the effect catalogue: one plain struct per effect id, file units on every field ----

/// 1 constant_bias: b0 = value + sigma * N(0,1), drawn once per run (turn-on / run-to-run).
struct ConstantBiasParams {
  bool enabled = true;
  Eigen::Vector3d value_dps = Eigen::Vector3d::Zero();  // fixed part, deg/s
  Eigen::Vector3d sigma_dps = Eigen::Vector3d::Zero();  // 1-sigma run-to-run draw, deg/s
  bool operator==(const ConstantBiasParams&) const = default;
};

/// 2 bias_instability: first-order Gauss-Markov, exact discretisation.
struct BiasInstabilityParams {
  bool enabled = true;
  Eigen::Vector3d sigma_dps = Eigen::Vector3d::Zero();          // stationary 1-sigma, deg/s
  Eigen::Vector3d tau_s = Eigen::Vector3d::Constant(3600.0);    // correlation time, s
  bool stationary_start = true;  // b(0) ~ N(0, sigma^2); false: b(0) = 0
  bool operator==(const BiasInstabilityParams&) const = default;
};

/// 3 rate_random_walk: b_{k+1} = b_k + K sqrt(dt) N(0,1).
struct RateRandomWalkParams {
  bool enabled = true;
  Eigen::Vector3d k_dps_rts = Eigen::Vector3d::Zero();  // K, deg/s/sqrt(s)
  bool operator==(const RateRandomWalkParams&) const = default;
};

/// 4 white_noise: angle random walk N; per-sample sigma = N sqrt(fs), or N sqrt(2 B) when the DLPF
/// bandwidth B is above fs/2 (the chip samples its registers without anti-aliasing: docs/effects.md).
struct WhiteNoiseParams {
  bool enabled = true;
  Eigen::Vector3d density_dps_rthz = Eigen::Vector3d::Zero();  // N, deg/s/sqrt(Hz)
  bool operator==(const WhiteNoiseParams&) const = default;
};

/// 5 scale_factor: y_i = (1 + s_i) w_i, s = value + sigma * N(0,1) per run.
struct ScaleFactorParams {
  bool enabled = true;
  Eigen::Vector3d value_pct = Eigen::Vector3d::Zero();  // %
  Eigen::Vector3d sigma_pct = Eigen::Vector3d::Zero();  // 1-sigma run-to-run draw, %
  bool operator==(const ScaleFactorParams&) const = default;
};

/// 6 misalignment: y = (I + M) w, M with zero diagonal (axis misalignment / cross-coupling).
struct MisalignmentParams {
  bool enabled = true;
  Eigen::Matrix3d matrix_pct = Eigen::Matrix3d::Zero();  // off-diagonal coupling, % (diag must be 0)
  double sigma_pct = 0.0;  // 1-sigma draw of each off-diagonal element, %
  bool operator==(const MisalignmentParams&) const = default;
};

/// 7 g_sensitivity: y += G f, driven by the specific-force truth.
struct GSensitivityParams {
  bool enabled = true;
  Eigen::Matrix3d matrix_dps_per_g = Eigen::Matrix3d::Zero();  // deg/s per g
  double sigma_dps_per_g = 0.0;  // 1-sigma draw of each element, deg/s per g
  bool operator==(const GSensitivityParams&) const = default;
};

/// 8 temperature: T(t) = ambient + rise (1 - exp(-t/tau)) or a CSV profile; bias and scale tempcos.
struct TemperatureParams {
  bool enabled = true;
  double ambient_degc = 25.0;
  double warmup_rise_degc = 0.0;   // self-heating after power-on, degC
  double warmup_tau_s = 600.0;     // self-heating time constant, s
  std::string profile_file;        // CSV "t_s,temp_degc" replacing ambient + warm-up when set
  double reference_degc = 25.0;    // temperature at which the tempco terms vanish
  Eigen::Vector3d bias_tc_dps_per_degc = Eigen::Vector3d::Zero();
  Eigen::Vector3d bias_tc_sigma_dps_per_degc = Eigen::Vector3d::Zero();
  Eigen::Vector3d scale_tc_pct_per_degc = Eigen::Vector3d::Zero();
  Eigen::Vector3d scale_tc_sigma_pct_per_degc = Eigen::Vector3d::Zero();
  // temp register: T = code / 340 + 36.53 (datasheet)
  double output_sensitivity_lsb_per_degc = mpu6050::kTempLsbPerDegC;
  double output_offset_degc = mpu6050::kTempOffsetDegC;
  bool operator==(const TemperatureParams&) const = default;
};

/// 9a quantization: code = round(y * sensitivity), output = code / sensitivity.
struct QuantizationParams {
  bool enabled = true;
  double sensitivity_lsb_per_dps = mpu6050::gyro_lsb_per_dps(0);  // FS_SEL 0
  bool operator==(const QuantizationParams&) const = default;
};

/// 9b saturation: clip at +-full scale.
struct SaturationParams {
  bool enabled = true;
  double full_scale_dps = 250.0;
  bool operator==(const SaturationParams&) const = default;
};

/// 10a adc_missing_codes: codes the ADC never outputs (random fraction and/or a list).
struct AdcMissingCodesParams {
  bool enabled = false;
  double fraction = 0.0;          // probability that a code is missing, drawn once per run
  std::vector<int> codes;         // codes (LSB) that are always missing
  bool operator==(const AdcMissingCodesParams&) const = default;
};

/// 10b adc_nonlinearity: y += FS (c2 u^2 + c3 u^3), u = y / FS.
struct AdcNonlinearityParams {
  bool enabled = false;
  double quadratic_pct_fs = 0.0;  // bow term, % of full scale
  double cubic_pct_fs = 0.0;      // S-curve term, % of full scale
  bool operator==(const AdcNonlinearityParams&) const = default;
};

/// 11a lowpass_latency: the DLPF as a discrete filter at the output rate: the MPU6050 DLPF_CFG
/// row (0..6), or a continuous group delay (`delay_s` > 0) with its bandwidth. Off = no filter.
struct LowpassLatencyParams {
  bool enabled = true;
  int dlpf_cfg = 3;
  double delay_s = 0.0;       // s, group delay at 0 Hz; > 0 replaces the dlpf_cfg row
  double bandwidth_hz = 0.0;  // Hz, with delay_s > 0: the bandwidth (0 = the datasheet's for that delay)
  bool operator==(const LowpassLatencyParams&) const = default;
};

/// 11b sample_jitter: the sample instant moves by dt ~ N(0, sigma^2); y += dw/dt * dt.
struct SampleJitterParams {
  bool enabled = false;
  double sigma_s = 0.0;
  bool operator==(const SampleJitterParams&) const = default;
};

/// 13 sample_delay: the sensor samples `delay_s` after the log's time stamp: it reads the truth of
/// that long ago (linear interpolation between output samples), gyro and accelerometer alike.
struct SampleDelayParams {
  bool enabled = false;
  double delay_s = 0.0;  // s, >= 0
  bool operator==(const SampleDelayParams&) const = default;
};

/// 12 mounting_misalignment: small rotation of the chip on its platform, rotation vector.
struct MountingMisalignmentParams {
  bool enabled = true;
  Eigen::Vector3d angles_deg = Eigen::Vector3d::Zero();  // fixed rotation vector, deg
  Eigen::Vector3d sigma_deg = Eigen::Vector3d::Zero();   // 1-sigma draw per component, deg
  bool operator==(const MountingMisalignmentParams&) const = default;
};

/// accel_bias: zero-g offset, value + sigma * N(0,1) per run.
struct AccelBiasParams {
  bool enabled = true;
  Eigen::Vector3d value_mps2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_mps2 = Eigen::Vector3d::Zero();
  bool operator==(const AccelBiasParams&) const = default;
};

/// accel_white_noise: per-sample sigma = density sqrt(fs).
struct AccelWhiteNoiseParams {
  bool enabled = true;
  Eigen::Vector3d density_mps2_rthz = Eigen::Vector3d::Zero();
  bool operator==(const AccelWhiteNoiseParams&) const = default;
};

/// accel_scale_factor: a_i = (1 + s_i) f_i.
struct AccelScaleFactorParams {
  bool enabled = true;
  Eigen::Vector3d value_pct = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_pct = Eigen::Vector3d::Zero();
  bool operator==(const AccelScaleFactorParams&) const = default;
};

/// accel_quantization: LSB grid and clip at +-full scale.
struct AccelQuantizationParams {
  bool enabled = true;
  double sensitivity_lsb_per_g = mpu6050::accel_lsb_per_g(0);  // AFS_SEL 0
  double full_scale_g = 2.0;
  bool operator==(const AccelQuantizationParams&) const = default;
};

/// Every effect of one sensor (gyro triad + accelerometer triad + temperature sensor).
struct SensorParams {
  std::string preset = "mpu6050";  // the preset the file started from (informational)
  ConstantBiasParams constant_bias;
  BiasInstabilityParams bias_instability;
  RateRandomWalkParams rate_random_walk;
  WhiteNoiseParams white_noise;
  ScaleFactorParams scale_factor;
  MisalignmentParams misalignment;
  GSensitivityParams g_sensitivity;
  TemperatureParams temperature;
  QuantizationParams quantization;
  SaturationParams saturation;
  AdcMissingCodesParams adc_missing_codes;
  AdcNonlinearityParams adc_nonlinearity;
  LowpassLatencyParams lowpass_latency;
  SampleJitterParams sample_jitter;
  MountingMisalignmentParams mounting_misalignment;
  AccelBiasParams accel_bias;
  AccelWhiteNoiseParams accel_white_noise;
  AccelScaleFactorParams accel_scale_factor;
  AccelQuantizationParams accel_quantization;
  SampleDelayParams sample_delay;

  /// Throws std::invalid_argument naming the effect and key of the first bad value.
  void validate() const;
  bool operator==(const SensorParams&) const = default;
};

/// The effect ids in catalogue order (the YAML keys under `effects:`).
const std::vector<std::string>& effect_ids();
/// Whether effect `id` is switched on; throws std::invalid_argument on an unknown id.
bool effect_enabled(const SensorParams& p, std::string_view id);
/// Switches effect `id` on or off; throws std::invalid_argument on an unknown id.
void set_effect_enabled(SensorParams& p, std::string_view id, bool enabled);

/// The paper's MPU6050 with datasheet magnitudes (docs/effects.md lists the sources).
SensorParams mpu6050_defaults();
/// A perfect sensor: every effect off, so the output equals the truth.
SensorParams ideal_sensor();
/// A preset by name ("mpu6050", "ideal"); throws std::invalid_argument listing the valid names.
SensorParams sensor_preset(std::string_view name);

/// Reads a `{preset: NAME, effects: {<id>: {enabled: bool, <key_unit>: ...}}}` block over `base`
/// (a key in another unit of the same quantity is converted: `sigma_dph`). `ctx` names the file
/// and the block's dotted path in errors (InputError).
SensorParams read_sensor_params(const fields::Node& node, const SensorParams& base, const fields::Context& ctx);
/// Every parameter explicitly, as a map (read_sensor_params of the result gives back `p`).
fields::Node write_sensor_params(const SensorParams& p);

// ---- building blocks the model uses, public for tests, compare and diagnosis ----

/// The one random-number module (estimator/random.hpp), under the names the sensor model uses.
using rnd::derive_seed;
using rnd::NormalStream;

/// The MPU6050 DLPF_CFG table row (estimator/mpu6050.hpp, the one copy of the datasheet).
using mpu6050::DlpfSetting;

/// Gyro bandwidth, Hz, that the MPU6050 datasheet pairs with a DLPF group delay `delay_s` (> 0):
/// log-log interpolation between the DLPF_CFG rows, their end segments extended beyond them.
double mpu6050_gyro_bandwidth_for_delay_hz(double delay_s);
/// The filter the model runs for `p` (bandwidths and delays of gyro and accelerometer): the
/// DLPF_CFG row, or with `delay_s` > 0 that delay and bandwidth for both (docs/effects.md, 11a).
DlpfSetting lowpass_setting(const LowpassLatencyParams& p);

/// A discrete low-pass at the output rate: first-order IIR then a (fractional) sample delay.
struct LowpassDesign {
  double pole = 0.0;            // u_k = pole u_{k-1} + (1 - pole) x_k
  int delay_whole_samples = 0;  // y_k = u at k - n - frac, cubic interpolation (docs/effects.md 11)
  double delay_frac = 0.0;
  /// Group delay at 0 Hz, s: pole/(1-pole)/fs + (n + frac)/fs (equals the requested delay).
  double dc_group_delay_s(double sample_rate_hz) const;
};
/// Designs the filter: pole from the bandwidth (impulse invariance), delay topped up to delay_s.
LowpassDesign design_lowpass(double bandwidth_hz, double delay_s, double sample_rate_hz);
/// A pure (fractional) delay of `delay_s` at the output rate: no pole (13 sample_delay).
LowpassDesign pure_delay(double delay_s, double sample_rate_hz);

/// Runs a LowpassDesign on a 3-vector, one call per sample; starts in steady state at its first input.
class LowpassFilter {
 public:
  explicit LowpassFilter(const LowpassDesign& d = {}) : d_(d) {}
  /// Filters one sample.
  Eigen::Vector3d apply(const Eigen::Vector3d& x);
  const LowpassDesign& design() const { return d_; }

 private:
  LowpassDesign d_;
  Eigen::Vector3d u_ = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> hist_;  // ring of past u, size n + 5
  int head_ = 0;
  bool primed_ = false;
};

/// The run-to-run part of a sensor, drawn once from the seed, in internal units (rad, rad/s, m/s^2).
struct SensorInstance {
  Eigen::Vector3d mounting_rotvec_rad = Eigen::Vector3d::Zero();        // rotation vector, nominal<-sensor
  Eigen::Matrix3d R_sensor_from_nominal = Eigen::Matrix3d::Identity();  // mounting rotation
  Eigen::Matrix3d misalignment = Eigen::Matrix3d::Identity();           // I + M
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();                      // 1 + s
  Eigen::Vector3d scale_tc_per_degc = Eigen::Vector3d::Zero();          // fraction per degC
  Eigen::Matrix3d G_radps_per_mps2 = Eigen::Matrix3d::Zero();
  Eigen::Vector3d bias_radps = Eigen::Vector3d::Zero();                 // constant bias
  Eigen::Vector3d bias_tc_radps_per_degc = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_bias_mps2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_scale = Eigen::Vector3d::Ones();
  std::vector<int> missing_codes;  // sorted, unique
};

/// Draws the run-to-run parameters (sub-streams of `seed`); with all sigmas 0 it is deterministic.
SensorInstance draw_sensor_instance(const SensorParams& p, std::uint64_t seed);
/// `p` with the draws of `inst` folded into the fixed values and every run-to-run sigma set to 0.
SensorParams realised_params(const SensorParams& p, const SensorInstance& inst);

/// The chip temperature over time (ambient + warm-up, or an interpolated CSV profile), degC.
class TemperatureModel {
 public:
  /// Loads the profile file if one is set; throws std::runtime_error naming file and line.
  explicit TemperatureModel(const TemperatureParams& p);
  /// True temperature at time t_s, degC (the reference temperature when the effect is off).
  double at(double t_s) const;

 private:
  TemperatureParams p_;
  std::vector<double> t_s_, temp_c_;
};

/// Deterministic gyro output before noise, filter and ADC: C_T R w + G R f + b0 + b_T (rad/s).
Eigen::Vector3d gyro_deterministic_radps(const SensorParams& p, const SensorInstance& inst,
                                         const Eigen::Vector3d& w_radps,
                                         const Eigen::Vector3d& f_mps2, double temp_c);
/// Inverse of gyro_deterministic_radps: the truth rate that gives y_radps (basalt invertCalibration).
Eigen::Vector3d gyro_invert_radps(const SensorParams& p, const SensorInstance& inst,
                                  const Eigen::Vector3d& y_radps, const Eigen::Vector3d& f_mps2,
                                  double temp_c);
/// The static ADC transfer (nonlinearity, saturation, quantisation, missing codes) of the gyro.
Eigen::Vector3d gyro_adc_radps(const SensorParams& p, const SensorInstance& inst,
                               const Eigen::Vector3d& y_radps);
/// Noise-free steady-state prediction of the gyro output: ADC(deterministic) (DLPF has DC gain 1).
Eigen::Vector3d predict_gyro_radps(const SensorParams& p, const SensorInstance& inst,
                                   const SensorTruth& truth, double temp_c);
/// Deterministic accel output before noise, filter and ADC: (1 + s) R f + b (m/s^2).
Eigen::Vector3d accel_deterministic_mps2(const SensorParams& p, const SensorInstance& inst,
                                         const Eigen::Vector3d& f_mps2);
/// Inverse of accel_deterministic_mps2.
Eigen::Vector3d accel_invert_mps2(const SensorParams& p, const SensorInstance& inst,
                                  const Eigen::Vector3d& a_mps2);

/// A sensor: pure function of truth, parameters and a seeded random stream, stepped per sample.
class SensorModel {
 public:
  /// Validates `params`, draws the run-to-run instance from `seed`, designs the DLPF for the rate.
  SensorModel(const SensorParams& params, double sample_rate_hz, std::uint64_t seed);
  /// One output sample (call once per sample, in time order).
  SensorReading step(const SensorTruth& truth);

  const SensorParams& params() const { return params_; }
  const SensorInstance& instance() const { return inst_; }
  /// The parameters with this run's draws fixed (for compare / diagnose --apply).
  SensorParams realised() const { return realised_params(params_, inst_); }
  double sample_rate_hz() const { return fs_hz_; }
  const LowpassDesign& gyro_lowpass() const { return gyro_filter_.design(); }
  const LowpassDesign& accel_lowpass() const { return accel_filter_.design(); }

 private:
  SensorParams params_;
  double fs_hz_, dt_s_;
  SensorInstance inst_;
  TemperatureModel temp_;
  LowpassFilter gyro_filter_, accel_filter_;
  // the chip's noise passes the DLPF's pole only: its delay is a whole number of the chip's
  // internal samples, which does not correlate noise (interpolating it at the output rate would)
  LowpassFilter gyro_noise_filter_, accel_noise_filter_;
  LowpassFilter delay_w_, delay_f_;  // 13: the truth delayed by sample_delay.delay_s
  std::vector<std::uint8_t> missing_lut_;  // 65536 flags, code + 32768

  // per-step noise streams, one per effect
  NormalStream rng_gm_, rng_rrw_, rng_white_, rng_jitter_, rng_accel_white_;
  // precomputed constants (rad/s)
  Eigen::Vector3d gm_phi_, gm_drive_, rrw_step_, white_sigma_, accel_white_sigma_;
  bool gyro_white_after_filter_ = false, accel_white_after_filter_ = false;  // aliased noise
  // changing state
  Eigen::Vector3d b_gm_ = Eigen::Vector3d::Zero(), b_rrw_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d w_prev_ = Eigen::Vector3d::Zero(), f_prev_ = Eigen::Vector3d::Zero();
  double t_prev_ = 0.0;
  bool have_prev_ = false;
};

}  // namespace driftless::twin
