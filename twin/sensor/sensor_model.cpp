// The sensor model: run-to-run draws, the deterministic chain and its inverse, and step().
#include "twin/sensor/sensor_model.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "estimator/sample.hpp"

namespace driftless::twin {
namespace {

// fixed sub-stream numbers per effect: init (run-to-run) draws use 2*k, per-step draws 2*k+1,
// so switching one effect on or off never moves another effect's numbers
enum Stream : std::uint64_t {
  kConstantBias = 1, kBiasInstability, kRateRandomWalk, kWhiteNoise, kScaleFactor, kMisalignment,
  kGSensitivity, kTemperature, kQuantization, kSaturation, kAdcMissingCodes, kAdcNonlinearity,
  kLowpassLatency, kSampleJitter, kMountingMisalignment, kAccelBias, kAccelWhiteNoise,
  kAccelScaleFactor, kAccelQuantization, kSampleDelay
};
std::uint64_t init_stream(Stream s) { return 2 * static_cast<std::uint64_t>(s); }
std::uint64_t step_stream(Stream s) { return 2 * static_cast<std::uint64_t>(s) + 1; }

constexpr double kG = kStandardGravityMps2;
constexpr int kCodeMin = -32768;
constexpr int kCodeMax = 32767;

Eigen::Vector3d normal3(NormalStream& n) {
  const double a = n();
  const double b = n();
  const double c = n();
  return {a, b, c};
}

// moves a missing code to the nearest present one on the side the continuous value lies
template <class IsMissing>
int avoid_missing(int c, double x, IsMissing missing) {
  if (!missing(c)) return c;
  const int dir = x < c ? -1 : 1;
  for (int d : {dir, -dir}) {
    for (int k = c + d; k >= kCodeMin && k <= kCodeMax; k += d)
      if (!missing(k)) return k;
  }
  return c;  // every code missing: validate() keeps this from happening
}

// the static ADC transfer of one gyro axis, rad/s in and out (untouched when every stage is off)
template <class IsMissing>
double gyro_adc_axis_radps(const SensorParams& p, double y, IsMissing missing) {
  const double fs = p.saturation.full_scale_dps * kRadPerDeg;
  if (p.adc_nonlinearity.enabled) {
    const double u = y / fs;
    y += fs * (p.adc_nonlinearity.quadratic_pct_fs * u * u + p.adc_nonlinearity.cubic_pct_fs * u * u * u) *
         1e-2;
  }
  if (p.saturation.enabled) y = std::clamp(y, -fs, fs);
  if (p.quantization.enabled) {
    const double sens = p.quantization.sensitivity_lsb_per_dps;
    const double x = std::clamp(y * kDegPerRad * sens, double(kCodeMin), double(kCodeMax));
    int c = static_cast<int>(std::nearbyint(x));
    if (p.adc_missing_codes.enabled) c = avoid_missing(c, x, missing);
    y = c / sens * kRadPerDeg;
  }
  return y;
}

double accel_adc_axis_mps2(const AccelQuantizationParams& q, double a) {
  if (!q.enabled) return a;
  const double fs = q.full_scale_g * kG;
  a = std::clamp(a, -fs, fs);
  const double sens = q.sensitivity_lsb_per_g / kG;  // LSB per m/s^2
  const double x = std::clamp(a * sens, double(kCodeMin), double(kCodeMax));
  return std::nearbyint(x) / sens;
}

}  // namespace

// ---- DLPF ----

double mpu6050_gyro_bandwidth_for_delay_hz(double delay_s) {
  if (!(delay_s > 0.0) || !std::isfinite(delay_s))
    throw std::invalid_argument("mpu6050_gyro_bandwidth_for_delay_hz: delay must be > 0 s");
  // the gyro columns of DLPF_CFG 0..6: bandwidth falls as the delay grows (a straight line in
  // log-log per segment); below cfg 0 and above cfg 6 the end segments are extended
  constexpr int kRows = 7;
  const double x = std::log(delay_s);
  int i = 0;
  while (i + 2 < kRows && x > std::log(mpu6050::dlpf_setting(i + 1).gyro_delay_s)) ++i;
  const DlpfSetting a = mpu6050::dlpf_setting(i), b = mpu6050::dlpf_setting(i + 1);
  const double xa = std::log(a.gyro_delay_s), xb = std::log(b.gyro_delay_s);
  const double u = (x - xa) / (xb - xa);
  return std::exp(std::log(a.gyro_bandwidth_hz) + u * (std::log(b.gyro_bandwidth_hz) - std::log(a.gyro_bandwidth_hz)));
}

DlpfSetting lowpass_setting(const LowpassLatencyParams& p) {
  if (!(p.delay_s > 0.0)) return mpu6050::dlpf_setting(p.dlpf_cfg);
  const double bw = p.bandwidth_hz > 0.0 ? p.bandwidth_hz : mpu6050_gyro_bandwidth_for_delay_hz(p.delay_s);
  return {bw, p.delay_s, bw, p.delay_s};
}

LowpassDesign pure_delay(double delay_s, double fs) {
  if (!(fs > 0.0) || !(delay_s >= 0.0))
    throw std::invalid_argument("pure_delay: need sample rate > 0, delay >= 0");
  LowpassDesign d;
  const double want = delay_s * fs;  // samples
  d.delay_whole_samples = static_cast<int>(std::floor(want));
  d.delay_frac = want - d.delay_whole_samples;
  return d;
}

double LowpassDesign::dc_group_delay_s(double fs) const {
  return (pole / (1.0 - pole) + delay_whole_samples + delay_frac) / fs;
}

LowpassDesign design_lowpass(double bandwidth_hz, double delay_s, double fs) {
  if (!(fs > 0.0) || !(bandwidth_hz > 0.0) || !(delay_s >= 0.0))
    throw std::invalid_argument("design_lowpass: need sample rate > 0, bandwidth > 0, delay >= 0");
  LowpassDesign d;
  const double want = delay_s * fs;  // samples
  // a first-order pole at the bandwidth (impulse invariance); above Nyquist it cannot be shown
  d.pole = bandwidth_hz < 0.5 * fs ? std::exp(-2.0 * kPi * bandwidth_hz / fs) : 0.0;
  double g = d.pole / (1.0 - d.pole);  // its group delay at 0 Hz, samples
  if (g > want) {  // the pole alone lags too much: place it so it carries the whole delay
    d.pole = want / (1.0 + want);
    g = want;
  }
  const double rest = std::max(0.0, want - g);
  d.delay_whole_samples = static_cast<int>(std::floor(rest));
  d.delay_frac = rest - d.delay_whole_samples;
  return d;
}

Eigen::Vector3d LowpassFilter::apply(const Eigen::Vector3d& x) {
  // the fractional delay interpolates u at k - (n + frac) with a cubic (4-point Lagrange) on the
  // nodes around it, centred when a newer sample exists (n >= 1), else the 4 newest: exact for
  // cubics (a ramp lags by exactly the delay), and flat in amplitude to O((f/fs)^4) where linear
  // interpolation would lose 0.1 % already at fs/60
  const int n = d_.delay_whole_samples;
  const int size = n + 5;
  if (!primed_) {  // start in steady state at the first input
    u_ = x;
    hist_.assign(static_cast<std::size_t>(size), x);
    head_ = 0;
    primed_ = true;
  } else {
    u_ = d_.pole * u_ + (1.0 - d_.pole) * x;
    head_ = head_ + 1 == size ? 0 : head_ + 1;
    hist_[static_cast<std::size_t>(head_)] = u_;
  }
  if (d_.delay_frac == 0.0) return hist_[static_cast<std::size_t>((head_ - n + size) % size)];
  const int first = n >= 1 ? n - 1 : 0;   // nodes k - first ... k - first - 3
  const double pos = (n + d_.delay_frac) - first;  // in [0, 3], the point between the nodes
  Eigen::Vector3d y = Eigen::Vector3d::Zero();
  for (int i = 0; i < 4; ++i) {
    double w = 1.0;
    for (int j = 0; j < 4; ++j)
      if (j != i) w *= (pos - j) / static_cast<double>(i - j);
    y += w * hist_[static_cast<std::size_t>((head_ - first - i + 2 * size) % size)];
  }
  return y;
}

// ---- temperature ----

TemperatureModel::TemperatureModel(const TemperatureParams& p) : p_(p) {
  if (!p.enabled || p.profile_file.empty()) return;
  std::ifstream in(p.profile_file);
  if (!in)
    throw std::runtime_error("temperature profile '" + p.profile_file +
                             "': cannot open (expected a CSV with columns t_s,temp_degc)");
  std::string line;
  int lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.empty() || line[0] == '#') continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream ss(line);
    double t = 0.0, c = 0.0;
    if (!(ss >> t >> c)) {
      if (t_s_.empty() && lineno == 1) continue;  // a header row
      throw std::runtime_error(p.profile_file + ":" + std::to_string(lineno) +
                               ": expected two numbers t_s,temp_degc");
    }
    if (!std::isfinite(t) || !std::isfinite(c) || (!t_s_.empty() && t <= t_s_.back()))
      throw std::runtime_error(p.profile_file + ":" + std::to_string(lineno) +
                               ": t_s must be finite and strictly increasing");
    t_s_.push_back(t);
    temp_c_.push_back(c);
  }
  if (t_s_.empty())
    throw std::runtime_error("temperature profile '" + p.profile_file + "' holds no rows");
}

double TemperatureModel::at(double t_s) const {
  if (!p_.enabled) return p_.reference_degc;
  if (!t_s_.empty()) {  // linear interpolation, held constant outside the table
    if (t_s <= t_s_.front()) return temp_c_.front();
    if (t_s >= t_s_.back()) return temp_c_.back();
    const auto it = std::upper_bound(t_s_.begin(), t_s_.end(), t_s);
    const std::size_t i = static_cast<std::size_t>(it - t_s_.begin());
    const double a = (t_s - t_s_[i - 1]) / (t_s_[i] - t_s_[i - 1]);
    return temp_c_[i - 1] + a * (temp_c_[i] - temp_c_[i - 1]);
  }
  return p_.ambient_degc + p_.warmup_rise_degc * (1.0 - std::exp(-std::max(t_s, 0.0) / p_.warmup_tau_s));
}

// ---- the run-to-run instance ----

SensorInstance draw_sensor_instance(const SensorParams& p, std::uint64_t seed) {
  SensorInstance s;
  auto stream = [seed](Stream k) { return NormalStream(derive_seed(seed, init_stream(k))); };
  if (p.mounting_misalignment.enabled) {
    auto n = stream(kMountingMisalignment);
    const auto& m = p.mounting_misalignment;
    s.mounting_rotvec_rad = (m.angles_deg + m.sigma_deg.cwiseProduct(normal3(n))) * kRadPerDeg;
    const double a = s.mounting_rotvec_rad.norm();
    const Eigen::Matrix3d R_nominal_from_sensor =
        a > 0.0 ? Eigen::AngleAxisd(a, s.mounting_rotvec_rad / a).toRotationMatrix()
                : Eigen::Matrix3d::Identity();
    s.R_sensor_from_nominal = R_nominal_from_sensor.transpose();
  }
  if (p.misalignment.enabled) {
    auto n = stream(kMisalignment);
    Eigen::Matrix3d M = p.misalignment.matrix_pct * 1e-2;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        if (r != c) M(r, c) += p.misalignment.sigma_pct * 1e-2 * n();
    s.misalignment = Eigen::Matrix3d::Identity() + M;
  }
  if (p.scale_factor.enabled) {
    auto n = stream(kScaleFactor);
    s.scale = Eigen::Vector3d::Ones() +
              (p.scale_factor.value_pct + p.scale_factor.sigma_pct.cwiseProduct(normal3(n))) * 1e-2;
  }
  if (p.g_sensitivity.enabled) {
    auto n = stream(kGSensitivity);
    Eigen::Matrix3d G = p.g_sensitivity.matrix_dps_per_g;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) G(r, c) += p.g_sensitivity.sigma_dps_per_g * n();
    s.G_radps_per_mps2 = G * (kRadPerDeg / kG);
  }
  if (p.temperature.enabled) {
    auto n = stream(kTemperature);
    const auto& t = p.temperature;
    s.bias_tc_radps_per_degc =
        (t.bias_tc_dps_per_degc + t.bias_tc_sigma_dps_per_degc.cwiseProduct(normal3(n))) * kRadPerDeg;
    s.scale_tc_per_degc =
        (t.scale_tc_pct_per_degc + t.scale_tc_sigma_pct_per_degc.cwiseProduct(normal3(n))) * 1e-2;
  }
  if (p.constant_bias.enabled) {
    auto n = stream(kConstantBias);
    s.bias_radps =
        (p.constant_bias.value_dps + p.constant_bias.sigma_dps.cwiseProduct(normal3(n))) * kRadPerDeg;
  }
  if (p.accel_bias.enabled) {
    auto n = stream(kAccelBias);
    s.accel_bias_mps2 = p.accel_bias.value_mps2 + p.accel_bias.sigma_mps2.cwiseProduct(normal3(n));
  }
  if (p.accel_scale_factor.enabled) {
    auto n = stream(kAccelScaleFactor);
    const auto& a = p.accel_scale_factor;
    s.accel_scale = Eigen::Vector3d::Ones() + (a.value_pct + a.sigma_pct.cwiseProduct(normal3(n))) * 1e-2;
  }
  if (p.adc_missing_codes.enabled) {
    s.missing_codes = p.adc_missing_codes.codes;
    if (p.adc_missing_codes.fraction > 0.0) {
      auto n = stream(kAdcMissingCodes);
      for (int c = kCodeMin; c <= kCodeMax; ++c)
        if (n.uniform() < p.adc_missing_codes.fraction) s.missing_codes.push_back(c);
    }
    std::sort(s.missing_codes.begin(), s.missing_codes.end());
    s.missing_codes.erase(std::unique(s.missing_codes.begin(), s.missing_codes.end()),
                          s.missing_codes.end());
  }
  return s;
}

SensorParams realised_params(const SensorParams& p, const SensorInstance& s) {
  SensorParams r = p;
  if (p.mounting_misalignment.enabled) {
    r.mounting_misalignment.angles_deg = s.mounting_rotvec_rad * kDegPerRad;
    r.mounting_misalignment.sigma_deg.setZero();
  }
  if (p.misalignment.enabled) {
    r.misalignment.matrix_pct = (s.misalignment - Eigen::Matrix3d::Identity()) * 100.0;
    r.misalignment.matrix_pct.diagonal().setZero();
    r.misalignment.sigma_pct = 0.0;
  }
  if (p.scale_factor.enabled) {
    r.scale_factor.value_pct = (s.scale - Eigen::Vector3d::Ones()) * 100.0;
    r.scale_factor.sigma_pct.setZero();
  }
  if (p.g_sensitivity.enabled) {
    r.g_sensitivity.matrix_dps_per_g = s.G_radps_per_mps2 * (kG * kDegPerRad);
    r.g_sensitivity.sigma_dps_per_g = 0.0;
  }
  if (p.temperature.enabled) {
    r.temperature.bias_tc_dps_per_degc = s.bias_tc_radps_per_degc * kDegPerRad;
    r.temperature.bias_tc_sigma_dps_per_degc.setZero();
    r.temperature.scale_tc_pct_per_degc = s.scale_tc_per_degc * 100.0;
    r.temperature.scale_tc_sigma_pct_per_degc.setZero();
  }
  if (p.constant_bias.enabled) {
    r.constant_bias.value_dps = s.bias_radps * kDegPerRad;
    r.constant_bias.sigma_dps.setZero();
  }
  if (p.accel_bias.enabled) {
    r.accel_bias.value_mps2 = s.accel_bias_mps2;
    r.accel_bias.sigma_mps2.setZero();
  }
  if (p.accel_scale_factor.enabled) {
    r.accel_scale_factor.value_pct = (s.accel_scale - Eigen::Vector3d::Ones()) * 100.0;
    r.accel_scale_factor.sigma_pct.setZero();
  }
  if (p.adc_missing_codes.enabled) {
    r.adc_missing_codes.codes = s.missing_codes;
    r.adc_missing_codes.fraction = 0.0;
  }
  return r;
}

// ---- deterministic chain and inverse ----

Eigen::Vector3d gyro_deterministic_radps(const SensorParams& p, const SensorInstance& s,
                                         const Eigen::Vector3d& w_radps,
                                         const Eigen::Vector3d& f_mps2, double temp_c) {
  const double dT = temp_c - p.temperature.reference_degc;
  const Eigen::Vector3d w_s = s.R_sensor_from_nominal * w_radps;
  const Eigen::Vector3d f_s = s.R_sensor_from_nominal * f_mps2;
  const Eigen::Vector3d k = s.scale + s.scale_tc_per_degc * dT;  // per-axis gain at temperature
  return s.misalignment * k.cwiseProduct(w_s) + s.G_radps_per_mps2 * f_s + s.bias_radps +
         s.bias_tc_radps_per_degc * dT;
}

Eigen::Vector3d gyro_invert_radps(const SensorParams& p, const SensorInstance& s,
                                  const Eigen::Vector3d& y_radps, const Eigen::Vector3d& f_mps2,
                                  double temp_c) {
  const double dT = temp_c - p.temperature.reference_degc;
  const Eigen::Vector3d f_s = s.R_sensor_from_nominal * f_mps2;
  const Eigen::Vector3d k = s.scale + s.scale_tc_per_degc * dT;
  const Eigen::Vector3d m =
      y_radps - s.G_radps_per_mps2 * f_s - s.bias_radps - s.bias_tc_radps_per_degc * dT;
  const Eigen::Vector3d w_s = s.misalignment.partialPivLu().solve(m).cwiseQuotient(k);
  return s.R_sensor_from_nominal.transpose() * w_s;
}

Eigen::Vector3d gyro_adc_radps(const SensorParams& p, const SensorInstance& s,
                               const Eigen::Vector3d& y_radps) {
  auto missing = [&s](int c) {
    return std::binary_search(s.missing_codes.begin(), s.missing_codes.end(), c);
  };
  Eigen::Vector3d out;
  for (int i = 0; i < 3; ++i) out[i] = gyro_adc_axis_radps(p, y_radps[i], missing);
  return out;
}

Eigen::Vector3d predict_gyro_radps(const SensorParams& p, const SensorInstance& s,
                                   const SensorTruth& truth, double temp_c) {
  return gyro_adc_radps(p, s, gyro_deterministic_radps(p, s, truth.w_radps, truth.f_mps2, temp_c));
}

Eigen::Vector3d accel_deterministic_mps2(const SensorParams&, const SensorInstance& s,
                                         const Eigen::Vector3d& f_mps2) {
  return s.accel_scale.cwiseProduct(s.R_sensor_from_nominal * f_mps2) + s.accel_bias_mps2;
}

Eigen::Vector3d accel_invert_mps2(const SensorParams&, const SensorInstance& s,
                                  const Eigen::Vector3d& a_mps2) {
  return s.R_sensor_from_nominal.transpose() * (a_mps2 - s.accel_bias_mps2).cwiseQuotient(s.accel_scale);
}

// ---- the model ----

SensorModel::SensorModel(const SensorParams& params, double sample_rate_hz, std::uint64_t seed)
    : params_((params.validate(), params)),
      fs_hz_(sample_rate_hz),
      dt_s_(1.0 / sample_rate_hz),
      inst_(draw_sensor_instance(params, seed)),
      temp_(params.temperature) {
  if (!(sample_rate_hz > 0.0) || !std::isfinite(sample_rate_hz))
    throw std::invalid_argument("SensorModel: sample_rate_hz must be > 0");
  const auto& p = params_;
  if (p.lowpass_latency.enabled) {
    const DlpfSetting d = lowpass_setting(p.lowpass_latency);
    gyro_filter_ = LowpassFilter(design_lowpass(d.gyro_bandwidth_hz, d.gyro_delay_s, fs_hz_));
    accel_filter_ = LowpassFilter(design_lowpass(d.accel_bandwidth_hz, d.accel_delay_s, fs_hz_));
    LowpassDesign pole_only;
    pole_only.pole = gyro_filter_.design().pole;
    gyro_noise_filter_ = LowpassFilter(pole_only);
    pole_only.pole = accel_filter_.design().pole;
    accel_noise_filter_ = LowpassFilter(pole_only);
  }
  if (p.sample_delay.enabled) {
    delay_w_ = LowpassFilter(pure_delay(p.sample_delay.delay_s, fs_hz_));
    delay_f_ = LowpassFilter(pure_delay(p.sample_delay.delay_s, fs_hz_));
  }
  if (p.adc_missing_codes.enabled) {
    missing_lut_.assign(65536, 0);
    for (int c : inst_.missing_codes) missing_lut_[static_cast<std::size_t>(c - kCodeMin)] = 1;
  }
  auto step_rng = [seed](Stream k) { return NormalStream(derive_seed(seed, step_stream(k))); };
  rng_gm_ = step_rng(kBiasInstability);
  rng_rrw_ = step_rng(kRateRandomWalk);
  rng_white_ = step_rng(kWhiteNoise);
  rng_jitter_ = step_rng(kSampleJitter);
  rng_accel_white_ = step_rng(kAccelWhiteNoise);

  const Eigen::Vector3d sigma_gm = p.bias_instability.sigma_dps * kRadPerDeg;
  for (int i = 0; i < 3; ++i) {
    // exact discretisation of db = -b/tau dt + q dW: phi = e^{-dt/tau}, drive = sigma sqrt(1-phi^2)
    gm_phi_[i] = std::exp(-dt_s_ / p.bias_instability.tau_s[i]);
    gm_drive_[i] = sigma_gm[i] * std::sqrt(1.0 - gm_phi_[i] * gm_phi_[i]);
  }
  rrw_step_ = p.rate_random_walk.k_dps_rts * (kRadPerDeg * std::sqrt(dt_s_));
  // white noise: without the DLPF, band-limited to fs/2 (sigma = N sqrt(fs)). With it, the chip's
  // noise reaches the DLPF bandwidth B and the register is sampled without further filtering: when
  // 2B >= fs the noise aliases into a white sequence of sigma = N sqrt(2B) added after the filter;
  // otherwise it is added before the filter, which colours it (long-tau density stays N)
  double gyro_noise_bw_hz = 0.5 * fs_hz_, accel_noise_bw_hz = 0.5 * fs_hz_;
  if (p.lowpass_latency.enabled) {
    const DlpfSetting d = lowpass_setting(p.lowpass_latency);
    gyro_white_after_filter_ = 2.0 * d.gyro_bandwidth_hz >= fs_hz_;
    accel_white_after_filter_ = 2.0 * d.accel_bandwidth_hz >= fs_hz_;
    if (gyro_white_after_filter_) gyro_noise_bw_hz = d.gyro_bandwidth_hz;
    if (accel_white_after_filter_) accel_noise_bw_hz = d.accel_bandwidth_hz;
  }
  white_sigma_ = p.white_noise.density_dps_rthz * (kRadPerDeg * std::sqrt(2.0 * gyro_noise_bw_hz));
  accel_white_sigma_ = p.accel_white_noise.density_mps2_rthz * std::sqrt(2.0 * accel_noise_bw_hz);
  if (p.bias_instability.enabled && p.bias_instability.stationary_start)
    b_gm_ = sigma_gm.cwiseProduct(normal3(rng_gm_));
}

SensorReading SensorModel::step(const SensorTruth& truth) {
  const auto& p = params_;
  SensorReading r;
  const double temp_c = temp_.at(truth.t_s);
  const double dT = temp_c - p.temperature.reference_degc;

  // 13: sampled late, the sensor reads the truth of delay_s ago
  const Eigen::Vector3d w_in = p.sample_delay.enabled ? delay_w_.apply(truth.w_radps) : truth.w_radps;
  const Eigen::Vector3d f_in = p.sample_delay.enabled ? delay_f_.apply(truth.f_mps2) : truth.f_mps2;
  // 11b: the sample is taken at t + dt_j; first-order in the truth's backward difference
  Eigen::Vector3d w = w_in;
  Eigen::Vector3d f = f_in;
  if (p.sample_jitter.enabled) {
    const double dtj = p.sample_jitter.sigma_s * rng_jitter_();
    const double span = truth.t_s - t_prev_;
    if (have_prev_ && span > 0.0) {
      w += (w_in - w_prev_) * (dtj / span);
      f += (f_in - f_prev_) * (dtj / span);
    }
    w_prev_ = w_in;
    f_prev_ = f_in;
    t_prev_ = truth.t_s;
    have_prev_ = true;
  }

  // 12, 5, 6, 7, 1, 8: the deterministic chain
  Eigen::Vector3d y = gyro_deterministic_radps(p, inst_, w, f, temp_c);
  // 2, 3: the slowly moving bias; 4: white noise (drawn here, added around the DLPF below)
  const Eigen::Vector3d b_moving = b_gm_ + b_rrw_;
  y += b_moving;
  Eigen::Vector3d n_white = Eigen::Vector3d::Zero();
  if (p.white_noise.enabled) n_white = white_sigma_.cwiseProduct(normal3(rng_white_));
  r.bias_radps = inst_.bias_radps + inst_.bias_tc_radps_per_degc * dT + b_moving;

  // 11a: DLPF (white noise before or after it, see the constructor), then 10, 9: the ADC
  if (p.lowpass_latency.enabled) {
    y = gyro_filter_.apply(y) + (gyro_white_after_filter_ ? n_white : gyro_noise_filter_.apply(n_white));
  } else {
    y += n_white;
  }
  if (p.adc_missing_codes.enabled) {
    auto missing = [this](int c) { return missing_lut_[static_cast<std::size_t>(c - kCodeMin)] != 0; };
    for (int i = 0; i < 3; ++i) r.gyro_radps[i] = gyro_adc_axis_radps(p, y[i], missing);
  } else {
    auto none = [](int) { return false; };
    for (int i = 0; i < 3; ++i) r.gyro_radps[i] = gyro_adc_axis_radps(p, y[i], none);
  }

  // accelerometer: mounting, scale, bias, noise, DLPF, ADC
  Eigen::Vector3d a = accel_deterministic_mps2(p, inst_, f);
  Eigen::Vector3d n_accel = Eigen::Vector3d::Zero();
  if (p.accel_white_noise.enabled) n_accel = accel_white_sigma_.cwiseProduct(normal3(rng_accel_white_));
  if (p.lowpass_latency.enabled) {
    a = accel_filter_.apply(a) + (accel_white_after_filter_ ? n_accel : accel_noise_filter_.apply(n_accel));
  } else {
    a += n_accel;
  }
  for (int i = 0; i < 3; ++i) r.accel_mps2[i] = accel_adc_axis_mps2(p.accel_quantization, a[i]);

  // temperature register: T = code / 340 + 36.53
  if (p.temperature.enabled) {
    const auto& t = p.temperature;
    r.temp_c = std::nearbyint((temp_c - t.output_offset_degc) * t.output_sensitivity_lsb_per_degc) /
                   t.output_sensitivity_lsb_per_degc +
               t.output_offset_degc;
  } else {
    r.temp_c = temp_c;
  }

  // advance the bias processes to the next sample
  if (p.bias_instability.enabled)
    b_gm_ = gm_phi_.cwiseProduct(b_gm_) + gm_drive_.cwiseProduct(normal3(rng_gm_));
  if (p.rate_random_walk.enabled) b_rrw_ += rrw_step_.cwiseProduct(normal3(rng_rrw_));
  return r;
}

}  // namespace driftless::twin
