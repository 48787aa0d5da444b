#include "diagnose/effects.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/core.h>

#include "diagnose/signal_chain.hpp"
#include "estimator/sample.hpp"

namespace driftless::diagnose {
namespace {

// the effect table, in Effect order
const std::array<EffectInfo, kEffectCount> kEffects = {{
    {Effect::kScaleFactor, "scale_factor", Family::kPhysical, true, ""},
    {Effect::kMisalignment, "misalignment", Family::kPhysical, true, ""},
    {Effect::kGSensitivity, "g_sensitivity", Family::kPhysical, true, ""},
    {Effect::kTemperature, "temperature", Family::kPhysical, true, ""},
    {Effect::kAdcNonlinearity, "adc_nonlinearity", Family::kPhysical, true, ""},
    {Effect::kMountingMisalignment, "mounting_misalignment", Family::kPhysical, true, ""},
    {Effect::kEndStopError, "end_stop_error", Family::kBox, true, ""},
    {Effect::kEarthRate, "earth_rate", Family::kBox, true, ""},
    {Effect::kFlipTransient, "flip_transient", Family::kBox, false,
     "it is the platform servo's dynamics (box motor block): lengthen the settle margin or tune the motor instead"},
    {Effect::kLowpass, "lowpass_latency", Family::kSignalChain, true, ""},
    {Effect::kSampleDelay, "sample_delay", Family::kSignalChain, true, ""},
    {Effect::kTimeOffset, "time_offset", Family::kSignalChain, true, ""},
    {Effect::kQuantization, "quantization", Family::kAdc, true, ""},
    {Effect::kSaturation, "saturation", Family::kAdc, true, ""},
    {Effect::kAdcMissingCodes, "adc_missing_codes", Family::kAdc, true, ""},
    {Effect::kConstantBias, "constant_bias", Family::kNoiseModel, true, ""},
    {Effect::kWhiteNoise, "white_noise", Family::kNoiseModel, true, ""},
    {Effect::kBiasInstability, "bias_instability", Family::kNoiseModel, true, ""},
    {Effect::kRateRandomWalk, "rate_random_walk", Family::kNoiseModel, true, ""},
    {Effect::kSampleJitter, "sample_jitter", Family::kNoiseModel, true, ""},
}};

// the parameter table: stem of the name, unit, effect, plausibility limit (file units)
struct ParamInfo {
  Param param;
  const char* stem;
  const char* unit;
  Effect effect;
  double limit;
};
constexpr double kNoLimit = std::numeric_limits<double>::infinity();
const ParamInfo kParams[] = {
    {Param::kScalePct, "value_pct", "%", Effect::kScaleFactor, 20.0},
    {Param::kMisalignmentPct, "matrix_pct", "%", Effect::kMisalignment, 10.0},
    {Param::kGSensDpsPerG, "matrix_dps_per_g", "deg/s/g", Effect::kGSensitivity, 2.0},
    {Param::kBiasTcDpsPerDegc, "bias_tc_dps_per_degc", "deg/s/degC", Effect::kTemperature, 2.0},
    {Param::kScaleTcPctPerDegc, "scale_tc_pct_per_degc", "%/degC", Effect::kTemperature, 2.0},
    {Param::kNonlinQuadPctFs, "quadratic_pct_fs", "% FS", Effect::kAdcNonlinearity, 5.0},
    {Param::kNonlinCubicPctFs, "cubic_pct_fs", "% FS", Effect::kAdcNonlinearity, 5.0},
    {Param::kMountingDeg, "angles_deg", "deg", Effect::kMountingMisalignment, 10.0},
    {Param::kStopErrorDeg, "stop_deg", "deg", Effect::kEndStopError, 5.0},
    {Param::kLatitudeDeg, "latitude_deg", "deg", Effect::kEarthRate, 10.0},  // limit: on the change
    {Param::kFlipTransientDps, "dps", "deg/s", Effect::kFlipTransient, 5.0},
    {Param::kLowpassDelayS, "delay_s", "s", Effect::kLowpass, 0.1},
    {Param::kSampleDelayS, "delay_s", "s", Effect::kSampleDelay, 0.2},
    {Param::kTimeOffsetS, "offset_s", "s", Effect::kTimeOffset, 0.5},
    {Param::kQuantLsbPerDps, "sensitivity_lsb_per_dps", "LSB/(deg/s)", Effect::kQuantization, kNoLimit},
    {Param::kFullScaleDps, "full_scale_dps", "deg/s", Effect::kSaturation, kNoLimit},
    {Param::kMissingCodes, "missing_codes_count", "codes", Effect::kAdcMissingCodes, kNoLimit},
    {Param::kConstantBiasDps, "value_dps", "deg/s", Effect::kConstantBias, 100.0},
    {Param::kWhiteDensity, "density_dps_rthz", "deg/s/rtHz", Effect::kWhiteNoise, kNoLimit},
    {Param::kGmSigmaDps, "sigma_dps", "deg/s", Effect::kBiasInstability, kNoLimit},
    {Param::kGmTauS, "tau_s", "s", Effect::kBiasInstability, kNoLimit},
    {Param::kRrwDpsRts, "k_dps_rts", "deg/s/rts", Effect::kRateRandomWalk, kNoLimit},
    {Param::kJitterSigmaS, "sigma_s", "s", Effect::kSampleJitter, kNoLimit},
    {Param::kDelaySecondOrderS2, "delay_second_order_s2", "s^2", Effect::kLowpass, kNoLimit},
    {Param::kDelayThirdOrderS3, "delay_third_order_s3", "s^3", Effect::kLowpass, kNoLimit},
    {Param::kNoiseLag1, "noise_second_difference_lag1", "-", Effect::kLowpass, kNoLimit},
    {Param::kModelLag1, "model_second_difference_lag1", "-", Effect::kLowpass, kNoLimit},
};

const ParamInfo& param_info(Param p) {
  for (const auto& i : kParams)
    if (i.param == p) return i;
  throw std::logic_error("diagnose: parameter without a table row");
}

constexpr std::array<const char*, 4> kFlipBinNames = {"0-0.25s", "0.25-0.5s", "0.5-1s", "1-2s"};

// the two other axes of axis j, in increasing order (the misalignment columns kMisA, kMisB)
std::array<int, 2> other_axes(int j) {
  const int a = (j + 1) % 3, b = (j + 2) % 3;
  return {std::min(a, b), std::max(a, b)};
}

std::vector<ColumnUse> on_sensor(int s, int col) {
  return {{s * 3, col}, {s * 3 + 1, col}, {s * 3 + 2, col}};
}

std::vector<ColumnUse> on_both(int col) {
  std::vector<ColumnUse> v;
  for (int c = 0; c < 6; ++c) v.push_back({c, col});
  return v;
}

}  // namespace

const EffectInfo& effect_info(Effect e) { return kEffects[static_cast<std::size_t>(e)]; }

namespace {
// each family's machine-readable id (diagnosis.json) and its name in text and HTML
struct FamilyText {
  const char* id;
  const char* name;
};
constexpr std::array<FamilyText, 5> kFamilyText = {{{"physical", "physical"},
                                                    {"box", "box"},
                                                    {"signal_chain", "signal chain"},
                                                    {"adc", "ADC"},
                                                    {"noise_model", "noise model"}}};
}  // namespace

const char* family_name(Family f) { return kFamilyText[static_cast<std::size_t>(f)].name; }
const char* family_id(Family f) { return kFamilyText[static_cast<std::size_t>(f)].id; }

const char* param_unit(Param p) { return param_info(p).unit; }
Effect effect_of(Param p) { return param_info(p).effect; }
double plausible_limit(Param p) { return param_info(p).limit; }

char axis_letter(int axis) { return "xyz"[axis]; }

std::string channel_name(int c) { return fmt::format("gyro{}_{}", c / 3 + 1, axis_letter(c % 3)); }

std::string param_name(const ParamRef& p) {
  const ParamInfo& i = param_info(p.param);
  const std::string s = p.sensor >= 0 ? fmt::format("s{}.", p.sensor + 1) : std::string();
  switch (p.param) {
    case Param::kMisalignmentPct:
    case Param::kGSensDpsPerG:
      return fmt::format("{}{}[{}][{}]", s, i.stem, axis_letter(p.row), axis_letter(p.col));
    case Param::kMountingDeg: return fmt::format("{}{}[{}]", s, i.stem, axis_letter(p.row));
    case Param::kStopErrorDeg: return fmt::format("{}{}_{}", s, p.col == 1 ? "plus" : "minus", i.stem);
    case Param::kFlipTransientDps:
      return fmt::format("{}{}.{}_{}", s, axis_letter(p.row), kFlipBinNames[static_cast<std::size_t>(p.col)], i.stem);
    default: break;
  }
  if (p.row >= 0) return fmt::format("{}{}.{}", s, axis_letter(p.row), i.stem);
  return s + i.stem;
}

std::vector<ColumnUse> columns_of(const ParamRef& p) {
  const int s = p.sensor, j = p.row;
  switch (p.param) {
    case Param::kScalePct: return {{s * 3 + j, kScale}};
    case Param::kMisalignmentPct: return {{s * 3 + j, p.col == other_axes(j)[0] ? kMisA : kMisB}};
    case Param::kGSensDpsPerG: return {{s * 3 + j, kG0 + p.col}};
    case Param::kBiasTcDpsPerDegc: return {{s * 3 + j, kTempBias}};
    case Param::kScaleTcPctPerDegc: return {{s * 3 + j, kTempScale}};
    case Param::kNonlinQuadPctFs: return {{s * 3 + j, kNonlin2}};
    case Param::kNonlinCubicPctFs: return {{s * 3 + j, kNonlin3}};
    case Param::kMountingDeg: return on_sensor(s, kMount0 + j);
    case Param::kStopErrorDeg: return on_sensor(s, p.col == 1 ? kEndPlus : kEndMinus);
    case Param::kLatitudeDeg: return on_both(kLat);
    case Param::kFlipTransientDps: return {{s * 3 + j, kFlip0 + p.col}};
    case Param::kLowpassDelayS: return s < 0 ? on_both(kDelay) : on_sensor(s, kDelay);  // -1: both sensors' filter
    case Param::kSampleDelayS: return on_sensor(s, kDelay);
    case Param::kTimeOffsetS: return on_both(kDelay);
    case Param::kDelaySecondOrderS2: return on_sensor(s, kDelay2);
    case Param::kDelayThirdOrderS3: return on_sensor(s, kDelay3);
    default: return {};
  }
}

namespace {
// the Earth-rate columns of axis j from the box-axes series turned into the sensor's axes
// (Rt = R_i^T at sample k): its latitude sensitivity (per deg) and its part of y_j
double earth_column(const Replay& r, const Eigen::Matrix3d& Rt, int j, int col, std::size_t k) {
  if (col == kLat) return Rt.row(j).dot(r.dw_dlat_box_radps[k].cast<double>()) * kDegPerRad * kRadPerDeg;
  return r.earth_box_radps.empty() ? 0.0 : Rt.row(j).dot(r.earth_box_radps[k].cast<double>()) * kDegPerRad;
}
}  // namespace

double column_value(const ColumnInputs& in, int s, int j, int col, std::size_t k) {
  const Replay& r = in.r;
  const Eigen::Vector3d& w = r.w_radps[s][k];
  switch (col) {
    case kScale: return w[j] * kDegPerRad / 100.0;
    case kMisA: return w[other_axes(j)[0]] * kDegPerRad / 100.0;
    case kMisB: return w[other_axes(j)[1]] * kDegPerRad / 100.0;
    case kG0: case kG1: case kG2: return static_cast<double>(r.f_mps2[s][k][col - kG0]) / kStandardGravityMps2;
    case kMount0: case kMount1: case kMount2:
      return w.cross(Eigen::Vector3d::Unit(col - kMount0))[j] * kDegPerRad * kRadPerDeg;
    case kTempBias: return in.res.temp_c(s, k) - in.params[s].temperature.reference_degc;
    case kTempScale:
      return (in.res.temp_c(s, k) - in.params[s].temperature.reference_degc) * w[j] * kDegPerRad / 100.0;
    case kNonlin2: case kNonlin3: {
      const double fs = in.params[s].saturation.full_scale_dps;
      const double u = in.res.pred_dps(s, j, k) / fs;
      return fs * (col == kNonlin2 ? u * u : u * u * u) / 100.0;
    }
    case kDelay: return -r.dw_axis_radps2(s, k, j) * kDegPerRad;
    case kDelay2: {
      const std::size_t a = k == 0 ? 0 : k - 1, b = k + 1 < r.size() ? k + 1 : k;
      if (b == a) return 0.0;
      return (r.dw_axis_radps2(s, b, j) - r.dw_axis_radps2(s, a, j)) / (r.t_s[b] - r.t_s[a]) * kDegPerRad;
    }
    case kDelay3: {  // the second difference of dw/dt
      if (k == 0 || k + 1 >= r.size()) return 0.0;
      const double h = 0.5 * (r.t_s[k + 1] - r.t_s[k - 1]);
      const double d = r.dw_axis_radps2(s, k + 1, j) - 2.0 * r.dw_axis_radps2(s, k, j) + r.dw_axis_radps2(s, k - 1, j);
      return -d / (h * h) * kDegPerRad;
    }
    case kEndPlus: case kEndMinus: {
      if (r.rest_side[s][k] != (col == kEndPlus ? 1 : -1)) return 0.0;
      return -r.hinge_axis[s].cross(w)[j] * kDegPerRad * kRadPerDeg;
    }
    case kLat: case kEarth: return earth_column(r, r.sensor_from_box(s, k), j, col, k);
    default: {  // flip bins
      const auto b = static_cast<std::size_t>(col - kFlip0);
      const double since = r.since_flip_s[s][k];
      if (!(since >= kFlipBinsS[b] && since < kFlipBinsS[b + 1])) return 0.0;
      return static_cast<double>(r.last_flip_dir[s][k]);
    }
  }
}

void ColumnSweep::move_to(std::size_t k) {
  if (k == k_) return;
  const Replay& r = in_.r;
  if (k == k_ + 1) {
    dw_[0] = dw_[1], dw_[1] = dw_[2];
  } else {
    dw_[0] = r.dw_axis_radps2(s_, k - 1, j_), dw_[1] = r.dw_axis_radps2(s_, k, j_);
  }
  dw_[2] = r.dw_axis_radps2(s_, k + 1, j_);
  k_ = k;
}

bool column_before_chain(int col) {
  return !(col == kDelay || col == kDelay2 || col == kDelay3 || col == kNonlin2 || col == kNonlin3 || col >= kFlip0);
}

ColumnSweep::ColumnSweep(const ColumnInputs& in, int s, int j) : in_(in), s_(s), j_(j) {
  const double lag = std::max(0.0, in.chain_delay_s[static_cast<std::size_t>(s)]) * in.res.fs_hz;  // samples
  lag_whole_ = static_cast<std::size_t>(std::floor(lag));
  lag_frac_ = lag - static_cast<double>(lag_whole_);
  for (auto& a : at_) a = {static_cast<std::size_t>(-1), static_cast<std::size_t>(-1)};
}

// a column before the chain at sample k: its undelayed values at the samples the chain delay
// falls between (before the first sample: the first), each evaluated once as k moves forward
double ColumnSweep::value(int col, std::size_t k) {
  if (!column_before_chain(col) || (lag_whole_ == 0 && lag_frac_ == 0.0)) return undelayed(col, k);
  const std::size_t i1 = k > lag_whole_ ? k - lag_whole_ : 0, i0 = i1 > 0 ? i1 - 1 : 0;
  auto& at = at_[static_cast<std::size_t>(col)];
  auto& val = val_[static_cast<std::size_t>(col)];
  auto get = [&](std::size_t i) {
    if (at[0] == i) return val[0];
    if (at[1] == i) return val[1];
    const double v = undelayed(col, i);
    // the slot of the earlier sample (or an empty one) takes it
    auto rank = [](std::size_t a) { return a == static_cast<std::size_t>(-1) ? -1.0 : static_cast<double>(a); };
    const int slot = rank(at[0]) <= rank(at[1]) ? 0 : 1;
    at[static_cast<std::size_t>(slot)] = i, val[static_cast<std::size_t>(slot)] = v;
    return v;
  };
  const double v0 = get(i0), v1 = get(i1);
  return v1 + lag_frac_ * (v0 - v1);
}

// the delay columns as column_value forms them, from the kept stencil values (the ends, where
// column_value's one-sided forms apply, and every other column go to column_value)
double ColumnSweep::undelayed(int col, std::size_t k) {
  const Replay& r = in_.r;
  if (col == kLat || col == kEarth) {  // the platform's rotation, turned again only when its angle changes
    const double ang = r.plat_deg[s_][k];
    if (!(ang == rt_angle_deg_)) Rt_ = r.sensor_from_box(s_, k), rt_angle_deg_ = ang;
    return earth_column(r, Rt_, j_, col, k);
  }
  if ((col != kDelay && col != kDelay2 && col != kDelay3) || k == 0 || k + 1 >= r.size()) {
    return column_value(in_, s_, j_, col, k);
  }
  move_to(k);
  switch (col) {
    case kDelay: return -dw_[1] * kDegPerRad;
    case kDelay2: return (dw_[2] - dw_[0]) / (r.t_s[k + 1] - r.t_s[k - 1]) * kDegPerRad;
    default: {
      const double h = 0.5 * (r.t_s[k + 1] - r.t_s[k - 1]);
      const double d = dw_[2] - 2.0 * dw_[1] + dw_[0];
      return -d / (h * h) * kDegPerRad;
    }
  }
}

double prior_sigma(const twin::SensorParams& p, int j, int col, double fs_hz) {
  switch (col) {
    case kScale: return p.scale_factor.enabled ? p.scale_factor.sigma_pct[j] : 0.0;
    case kMisA: case kMisB: return p.misalignment.enabled ? p.misalignment.sigma_pct : 0.0;
    case kG0: case kG1: case kG2: return p.g_sensitivity.enabled ? p.g_sensitivity.sigma_dps_per_g : 0.0;
    case kMount0: case kMount1: case kMount2:
      return p.mounting_misalignment.enabled ? p.mounting_misalignment.sigma_deg[col - kMount0] : 0.0;
    case kTempBias: return p.temperature.enabled ? p.temperature.bias_tc_sigma_dps_per_degc[j] : 0.0;
    case kTempScale: return p.temperature.enabled ? p.temperature.scale_tc_sigma_pct_per_degc[j] : 0.0;
    // a platform's rest angle on a stop is known to about this: how hard the servo presses it
    // into the stop (the twin's MuJoCo press, ~0.006 deg, is the model's mean) differs between
    // boxes and simulators
    case kEndPlus: case kEndMinus: return kRestAngleSigmaDeg;
    // the signal chain's second-order term c2 = (D^2 + V)/2 (D the group delay, V the variance of
    // the impulse response): the model knows its delays, not the filter's shape. V lies between 0
    // (a pure delay) and about D^2 (a first-order pole), and a sample that averages its interval
    // adds dt^2/12: the spread is half of that range. Without it the shape's amplitude response
    // (c2 times the rate's second derivative) reads as a scale of ~0.02 % on fast motion
    case kDelay2: {
      const double D = lowpass_delay_s(p), dt = 1.0 / fs_hz;
      return 0.25 * (D * D + dt * dt / 12.0);
    }
    default: return 0.0;
  }
}

}  // namespace driftless::diagnose
