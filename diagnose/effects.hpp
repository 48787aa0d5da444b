// The candidate effects of a comparison as types: which effect, which model value a fitted
// parameter is, and the residual each linear effect leaves (its regressor column). Text is made
// from these at the edge (report, JSON), never parsed back. Catalogue: docs/compare.md section 3.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "diagnose/compare_model.hpp"
#include "diagnose/replay.hpp"
#include "diagnose/residual.hpp"
#include "twin/sensor/sensor_model.hpp"

namespace driftless::diagnose {

/// The candidate effects, in catalogue order.
enum class Effect : std::uint8_t {
  kScaleFactor, kMisalignment, kGSensitivity, kTemperature, kAdcNonlinearity, kMountingMisalignment,
  kEndStopError, kEarthRate, kFlipTransient,
  kLowpass, kSampleDelay, kTimeOffset,
  kQuantization, kSaturation, kAdcMissingCodes,
  kConstantBias, kWhiteNoise, kBiasInstability, kRateRandomWalk, kSampleJitter,
  kCount
};
constexpr int kEffectCount = static_cast<int>(Effect::kCount);

/// What an effect changes: physical (sensor), box, signal chain (filter and timing), ADC, or the
/// noise model. The forward selection takes the first four before any noise-model change.
enum class Family : std::uint8_t { kPhysical, kBox, kSignalChain, kAdc, kNoiseModel };

/// One row of the effect table.
struct EffectInfo {
  Effect effect;
  const char* id;        // catalogue id (docs/effects.md, docs/compare.md)
  Family family;
  bool writable;         // diagnose --apply can write it into a model file
  const char* not_writable_because;  // when !writable: what to do instead
};
const EffectInfo& effect_info(Effect e);
inline const char* effect_id(Effect e) { return effect_info(e).id; }
/// The family in text and HTML: "physical", "box", "signal chain", "ADC", "noise model".
const char* family_name(Family f);
/// The family in diagnosis.json: physical|box|signal_chain|adc|noise_model.
const char* family_id(Family f);

/// Which model value a fitted parameter is (the field --apply writes).
enum class Param : std::uint8_t {
  kScalePct,           // sensor.scale_factor.value_pct[row], %
  kMisalignmentPct,    // sensor.misalignment.matrix_pct(row, col), %
  kGSensDpsPerG,       // sensor.g_sensitivity.matrix_dps_per_g(row, col), deg/s/g
  kBiasTcDpsPerDegc,   // sensor.temperature.bias_tc_dps_per_degc[row]
  kScaleTcPctPerDegc,  // sensor.temperature.scale_tc_pct_per_degc[row]
  kNonlinQuadPctFs,    // sensor.adc_nonlinearity.quadratic_pct_fs (fitted on axis row)
  kNonlinCubicPctFs,   // sensor.adc_nonlinearity.cubic_pct_fs (fitted on axis row)
  kMountingDeg,        // sensor.mounting_misalignment.angles_deg[row], deg
  kStopErrorDeg,       // box.stop<s>_error_deg[col: 0 at -stop, 1 at +stop], deg
  kLatitudeDeg,        // scenario latitude_deg, deg (fitted as a change; plausibility on the change)
  kFlipTransientDps,   // deg/s on axis row in bin col after a flip (not writable)
  kLowpassDelayS,      // sensor.lowpass_latency.delay_s (0 = no filter), s; sensor -1: both sensors
  kSampleDelayS,       // sensor.sample_delay.delay_s, s
  kTimeOffsetS,        // model.time_offset_s, s
  kQuantLsbPerDps,     // sensor.quantization.sensitivity_lsb_per_dps
  kFullScaleDps,       // sensor.saturation.full_scale_dps
  kMissingCodes,       // number of missing codes on axis row (the codes are in the candidate)
  kConstantBiasDps,    // sensor.constant_bias.value_dps[row]
  kWhiteDensity,       // sensor.white_noise.density_dps_rthz[row]
  kGmSigmaDps,         // sensor.bias_instability.sigma_dps[row]
  kGmTauS,             // sensor.bias_instability.tau_s[row]
  kRrwDpsRts,          // sensor.rate_random_walk.k_dps_rts[row]
  kJitterSigmaS,       // sensor.sample_jitter.sigma_s
  kDelaySecondOrderS2, // the signal chain's second-order term change (held, not fitted), s^2
  kDelayThirdOrderS3,  // its third-order term change (held, not fitted), s^3
  kNoiseLag1,          // lag-1 correlation of the residual noise (data), diagnostic
  kModelLag1,          // the same as the model predicts, diagnostic
};

/// A parameter: which value, of which sensor (0, 1; -1 for the box), which axis / element.
struct ParamRef {
  Param param = Param::kScalePct;
  std::int8_t sensor = -1;
  std::int8_t row = -1;
  std::int8_t col = -1;
  bool operator==(const ParamRef&) const = default;
};
/// Its name in reports, e.g. "s1.x.value_pct", "s2.matrix_dps_per_g[y][z]", "offset_s".
std::string param_name(const ParamRef& p);
/// Its unit, e.g. "%", "deg/s/g", "s".
const char* param_unit(Param p);

// ---- regressors: the residual each linear effect leaves, linear in its parameter ----

/// Regressor columns of one channel, deg/s per unit of the parameter (file units).
enum Col : int {
  kScale,                     // scale_factor, %:            w_j / 100
  kMisA, kMisB,               // misalignment, %:            w_a / 100, w_b / 100 (a < b the other axes)
  kG0, kG1, kG2,              // g_sensitivity, deg/s/g:     f_k / g
  kMount0, kMount1, kMount2,  // mounting_misalignment, deg: (w x e_k)_j
  kTempBias,                  // bias tempco, deg/s/degC:    T - T_ref
  kTempScale,                 // scale tempco, %/degC:       (T - T_ref) w_j / 100
  kNonlin2, kNonlin3,         // adc_nonlinearity, % FS:     FS u^2 / 100, FS u^3 / 100
  kDelay,                     // any delay, s:               -dw_j/dt
  kDelay2,                    // its second order, s^2:      d2w_j/dt2 (a delay d: d^2/2; a pole T: T^2)
  kDelay3,                    // its third order, s^3:       -d3w_j/dt3 (a delay d: d^3/6; a pole T: T^3)
  kEndPlus, kEndMinus,        // end_stop_error, deg:        -(a x w)_j at rest on that side
  kLat,                       // latitude error, deg:        dy_j/dlat
  kEarth,                     // the Earth rate's scale, 1:  its part of y_j (a nuisance where the latitude is assumed)
  kFlip0, kFlip1, kFlip2, kFlip3,  // flip transient, deg/s: dir * 1[bin after the stop]
  kNumCols
};
/// Seconds after a platform stops that bound the flip-transient bins.
inline constexpr std::array<double, 5> kFlipBinsS = {0.0, 0.25, 0.5, 1.0, 2.0};
/// Prior 1-sigma of a platform's rest angle on a stop, deg (servo press differs between boxes).
inline constexpr double kRestAngleSigmaDeg = 0.01;
/// Where a log states no latitude: prior 1-sigma of the Earth rate's latitude, deg, and of its
/// scale (1 = as at the assumed latitude, 0 = a reference frame that does not turn with the
/// Earth); together they span every Earth rate in the north-up plane, none included.
inline constexpr double kAssumedLatitudeSigmaDeg = 45.0;
inline constexpr double kAssumedEarthScaleSigma = 1.0;

/// What a column needs besides the replay: the model's prediction (output and temperature, from
/// the residual), and each sensor's signal-chain delay under the model (low-pass group delay +
/// sample delay + time offset, s), which an effect acting before the chain reaches the output
/// through (ColumnSweep).
struct ColumnInputs {
  const Replay& r;
  const Residual& res;
  const std::array<twin::SensorParams, 2>& params;
  std::array<double, 2> chain_delay_s{};
};
/// True for a column of an effect that acts on the sensor's input, before its low-pass and
/// sampling (scale, cross-axis, g-sensitivity, mounting, temperature, end stops, Earth rate): the
/// output sees it through the model's signal chain. Not the chain's own Taylor terms (kDelay*,
/// about the undelayed rate with the whole chain's moments), the ADC nonlinearity (of the
/// prediction, already through the chain) and the flip bins.
bool column_before_chain(int col);
/// Value of column `col` for channel (sensor s, axis j) at sample k.
double column_value(const ColumnInputs& in, int s, int j, int col, std::size_t k);
/// Every column of channel (sensor s, axis j), sample by sample: the angular acceleration's
/// stencil is evaluated once per sample and kept for its neighbours (a column at a time needed it
/// six times: kDelay once, kDelay2 twice, kDelay3 three times). The same numbers as column_value,
/// except that a column before the chain (column_before_chain) is read the sensor's chain delay
/// earlier (linear interpolation between samples): the model's chain delays what such an effect
/// adds, and read undelayed a 3 % scale behind an 18 ms chain was a 0.1 ms delay error (5 sigma).
class ColumnSweep {
 public:
  ColumnSweep(const ColumnInputs& in, int s, int j);
  /// Value of column `col` at sample k. Fastest when k moves forward one sample at a time.
  double value(int col, std::size_t k);

 private:
  void move_to(std::size_t k);
  double undelayed(int col, std::size_t k);
  const ColumnInputs& in_;
  int s_, j_;
  std::size_t lag_whole_ = 0;  // the chain delay in samples: whole part
  double lag_frac_ = 0.0;      // ... and fraction
  // per column the undelayed values at the two samples last interpolated between
  std::array<std::array<std::size_t, 2>, kNumCols> at_{};
  std::array<std::array<double, 2>, kNumCols> val_{};
  std::size_t k_ = static_cast<std::size_t>(-1);
  std::array<double, 3> dw_{};  // d(w_j)/dt at k - 1, k, k + 1, rad/s^2
  double rt_angle_deg_ = kNaN;  // the platform angle Rt_ was made for
  Eigen::Matrix3d Rt_ = Eigen::Matrix3d::Identity();  // box to sensor axes there
};
/// Prior 1-sigma (file units) of a column's coefficient under the model: the run-to-run spread
/// of an effect the model switches on; 0 = not a nuisance (the model says "exactly"). The signal
/// chain's second-order term (kDelay2) spreads with the filter's unknown shape at rate fs_hz.
double prior_sigma(const twin::SensorParams& p, int j, int col, double fs_hz);

/// One regressor a linear parameter drives: channel 0..5 (sensor*3 + axis) and column.
struct ColumnUse {
  int channel;
  int col;
};
/// The columns a linear parameter drives (empty for a parameter that is not linear).
std::vector<ColumnUse> columns_of(const ParamRef& p);
/// The effect a parameter belongs to.
Effect effect_of(Param p);

/// Largest magnitude of a parameter that is physically plausible for a MEMS gyro box (file
/// units); a fit beyond it is flagged as absurd (wrong units, axes or frame in the log).
double plausible_limit(Param p);

/// Axis letter 'x', 'y', 'z'.
char axis_letter(int axis);
/// Channel name "gyro1_x" ... "gyro2_z".
std::string channel_name(int channel);

}  // namespace driftless::diagnose
