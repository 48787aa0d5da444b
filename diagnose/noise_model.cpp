#include "diagnose/noise_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Dense>
#include <fmt/core.h>

#include "diagnose/apply.hpp"
#include "diagnose/parallel.hpp"
#include "estimator/sample.hpp"
#include "estimator/stats.hpp"

namespace driftless::diagnose {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// one channel's evidence for one noise effect and its parameters
struct PerChannel {
  double ev = -kInf, gain = 0.0;
  std::vector<FittedParam> params;
  std::string note;  // said beside the parameters (the assumption a value rests on)
};

FittedParam noise_param(const CompareModel& m, Param p, int c, double new_value, double sigma) {
  FittedParam fp;
  fp.ref = ParamRef{p, static_cast<std::int8_t>(c / 3), static_cast<std::int8_t>(c % 3)};
  fp.model_value = model_value(m, fp.ref);
  fp.value = new_value - fp.model_value;
  fp.sigma = sigma;
  return fp;
}

std::vector<double> finite_or_zero(std::vector<double> z) {
  for (double& v : z) v = std::isfinite(v) ? v : 0.0;
  return z;
}

// which bandwidth sets the white noise per sample (docs/compare.md 3, white_noise). The twin's
// sensor model: without a low-pass the noise is band-limited to fs/2 (sigma = N sqrt(fs)); with
// one whose bandwidth B reaches fs/2 the register is sampled without averaging (an MPU6050's
// sample-rate divider), so the noise up to B aliases (sigma = N sqrt(2B)). A sensor whose filter
// follows the output rate has sigma = N sqrt(fs) whatever its B: the data (white either way)
// cannot tell the two apart, so the density is given under both and the assumption said
std::string aliasing_note(const twin::SensorParams& p, double fs_hz, double n_out) {
  if (!p.lowpass_latency.enabled) return {};
  const double bw = twin::lowpass_setting(p.lowpass_latency).gyro_bandwidth_hz;
  if (!(2.0 * bw > fs_hz)) return {};
  return fmt::format(
      "per-sample sigma {:.3g} deg/s; N = {:.3g} assumes the model's {:.3g} Hz low-pass sampled at {:.3g} Hz without "
      "averaging (an MPU6050: sigma = N sqrt(2B)); if the sensor's filter follows the output rate (sigma = N sqrt(fs), "
      "most IMUs) N = {:.3g}, and the change is the model's low-pass instead (a bandwidth of {:.3g} Hz or less)",
      n_out * std::sqrt(fs_hz), n_out * std::sqrt(fs_hz / (2.0 * bw)), bw, fs_hz, n_out, 0.5 * fs_hz);
}

// the sensor's parameters the noise is referred to: a low-pass whose delay is at the chain's
// "no low-pass" boundary is none (a fitted 8.5 us filter, 1.6 sigma from zero, would take its
// bandwidth from the datasheet relation, tens of kHz, and the density read 10x low)
twin::SensorParams noise_reference(twin::SensorParams p) {
  if (p.lowpass_latency.enabled && p.lowpass_latency.delay_s > 0.0 && p.lowpass_latency.delay_s <= kNoLowpassDelayS)
    p.lowpass_latency.enabled = false;
  return p;
}

// the model's quantisation noise per sample, q^2/12 for an LSB q, (deg/s)^2: white where the
// noise spans several LSB, added at the output after the white noise (as the twin quantises)
double quantization_variance_dps2(const twin::SensorParams& p) {
  if (!p.quantization.enabled || !(p.quantization.sensitivity_lsb_per_dps > 0.0)) return 0.0;
  const double q = 1.0 / p.quantization.sensitivity_lsb_per_dps;
  return q * q / 12.0;
}

// white noise: the fitted density (long-tau, DLPF's block variance taken out) against the model's
// with the selected effects (compare.cpp): a selected "no low-pass" refers it to fs/2 (F13: read
// against the model's DLPF, a 20 Hz log without one showed 0.49x its density, 50 Hz 0.77x). The
// quantisation's own white part (q^2/12 per sample) is taken out of the fit and added to the
// model's: 65.5 LSB/(deg/s) at 10 Hz made a density 4 % high, 16.4 LSB/(deg/s) 8 %
PerChannel white_noise(const Residual& res, const ChannelData& C, int c, const CompareModel& m,
                       const std::vector<double>& z, double log_m) {
  const twin::SensorParams p = noise_reference(m.sensor[C.s]);
  const double ratio = block_mean_variance_ratio(deterministic_part(p), res.fs_hz, res.block_len);
  const double q2_hz = quantization_variance_dps2(p) / res.fs_hz;  // as a density^2 at the output rate
  ChannelNoise fit = C.noise, mod = C.noise;
  fit.white_dps_rthz = fit_white_density(C, res.block_series, z);
  const double n_model = p.white_noise.enabled ? p.white_noise.density_dps_rthz[C.j] : 0.0;
  mod.white_dps_rthz = std::max(std::sqrt(n_model * n_model * ratio + q2_hz), 1e-7);
  const double gain = BiasWhitener::neg2_loglik(res.block_series, mod, z) - BiasWhitener::neg2_loglik(res.block_series, fit, z);
  // the sensor's own white part at the output rate (at least a tenth of the total: a fit below
  // the LSB's share is the lattice, not a quieter sensor)
  const double n_out = std::sqrt(std::max(fit.white_dps_rthz * fit.white_dps_rthz - q2_hz,
                                          0.01 * fit.white_dps_rthz * fit.white_dps_rthz));
  const double n_est = n_out / std::sqrt(ratio);
  PerChannel out{gain - log_m, gain, {}, {}};
  if (const std::string why = aliasing_note(p, res.fs_hz, n_out); !why.empty()) out.note = channel_name(c) + ": " + why;
  out.params.push_back(noise_param(m, Param::kWhiteDensity, c, n_est,
                                   n_est / std::sqrt(2.0 * std::max<double>(1.0, static_cast<double>(C.m)))));
  return out;
}

// the residual on 1 s blocks (count-weighted means of the 0.1 s blocks)
struct SlowBlocks {
  BlockSeries series;
  std::size_t per = 1;
};
SlowBlocks slow_blocks(const Residual& res) {
  SlowBlocks sb;
  const double block_s = static_cast<double>(res.block_len) / res.fs_hz;
  sb.per = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(1.0 / block_s)));
  const std::size_t mb = res.blocks, m1 = (mb + sb.per - 1) / sb.per;
  sb.series.sample_rate_hz = res.fs_hz;
  sb.series.t_s.resize(m1);
  sb.series.count.resize(m1);
  for (std::size_t b = 0; b < m1; ++b) {
    std::size_t cnt = 0;
    for (std::size_t q = b * sb.per; q < std::min(mb, (b + 1) * sb.per); ++q) cnt += res.block_series.count[q];
    sb.series.count[b] = static_cast<std::uint16_t>(std::min<std::size_t>(cnt, 65535));
    sb.series.t_s[b] = res.block_series.t_s[std::min(mb - 1, b * sb.per + sb.per / 2)];
  }
  return sb;
}
std::vector<double> slow_means(const Residual& res, const SlowBlocks& sb, const std::vector<double>& z) {
  std::vector<double> z1(sb.series.t_s.size(), 0.0);
  for (std::size_t b = 0; b < z1.size(); ++b) {
    double acc = 0;
    std::size_t cnt = 0;
    for (std::size_t q = b * sb.per; q < std::min(res.blocks, (b + 1) * sb.per); ++q) {
      acc += z[q] * res.block_series.count[q];
      cnt += res.block_series.count[q];
    }
    z1[b] = cnt ? acc / static_cast<double>(cnt) : 0.0;
  }
  return z1;
}

// bias instability (sigma and tau free) and rate random walk (K free) on 1 s blocks
std::array<PerChannel, 2> slow_processes(const ChannelData& C, int c, const CompareModel& m, const SlowBlocks& sb,
                                         const std::vector<double>& z1, double duration_s) {
  const double l_model = BiasWhitener(sb.series, C.noise).neg2_loglik(z1);
  const double log_m1 = std::log(std::max(2.0, static_cast<double>(z1.size())));
  std::array<PerChannel, 2> out;
  double best = l_model, bs = C.noise.gm_sigma_dps, bt = C.noise.gm_tau_s;
  const double dur = std::max(10.0, duration_s);
  for (double tau : {dur / 30, dur / 10, dur / 3, dur, 3 * dur, 10 * dur}) {
    auto f = [&](double ls) {
      ChannelNoise nz = C.noise;
      nz.gm_sigma_dps = std::exp(ls);
      nz.gm_tau_s = tau;
      return BiasWhitener::neg2_loglik(sb.series, nz, z1);
    };
    const double ls = golden_min(f, std::log(1e-5), std::log(50.0), 30);
    if (const double v = f(ls); v < best) best = v, bs = std::exp(ls), bt = tau;
  }
  out[0] = {l_model - best - 2 * log_m1, l_model - best,
            {noise_param(m, Param::kGmSigmaDps, c, bs, 0.0), noise_param(m, Param::kGmTauS, c, bt, 0.0)}, {}};
  auto f = [&](double lk) {
    ChannelNoise nz = C.noise;
    nz.rrw_dps_rts = std::exp(lk);
    return BiasWhitener::neg2_loglik(sb.series, nz, z1);
  };
  const double lk = golden_min(f, std::log(1e-7), std::log(1.0), 30);
  const double g = l_model - std::min(f(lk), l_model);
  out[1] = {g - log_m1, g, {noise_param(m, Param::kRrwDpsRts, c, std::exp(lk), 0.0)}, {}};
  return out;
}

// the turn-on bias against the model's run-to-run spread (sigma^2 + sigma_GM^2 + K^2 T)
PerChannel constant_bias(const ChannelData& C, int c, const CompareModel& m, const AfterFit& a, const Residual& res,
                         double duration_s, double log_m) {
  const twin::SensorParams& p = m.sensor[C.s];
  const int j = C.j;
  double var0 = 0.0;
  if (p.constant_bias.enabled) var0 += std::pow(p.constant_bias.sigma_dps[j], 2);
  if (p.bias_instability.enabled) var0 += std::pow(p.bias_instability.sigma_dps[j], 2);
  if (p.rate_random_walk.enabled) var0 += std::pow(p.rate_random_walk.k_dps_rts[j], 2) * duration_s;
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t b = 0; b < res.blocks; ++b)
    if (res.block_series.count[b]) sum += a.bias[c][b], ++n;
  const double bias = n ? sum / static_cast<double>(n) : 0.0;
  const double sig = BiasWhitener(res.block_series, C.noise).final_bias_sigma_dps();
  const double chi2 = bias * bias / (var0 + sig * sig);
  FittedParam fp = noise_param(m, Param::kConstantBiasDps, c, 0.0, sig);
  fp.value = bias;  // the change: the residual's turn-on bias
  return {chi2 - log_m, chi2, {fp}, {}};
}

// the residual's per-sample variance and the variance of its square, per channel, over the fit
// samples: the jitter test's null. The model's floor is no null: a noisier sensor than the
// model's (a BMI088 against the MPU6050 default, 2.8x) made var(e^2) 61x too small, and a
// 3 s "jitter" was fitted on a log with exact stamps (P10)
struct SquareMoments {
  double var = 0.0, var_of_square = 0.0;
};
SquareMoments square_moments(const Residual& res, const AfterFit& a, int c) {
  double m2 = 0.0, m4 = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < res.n; ++k) {
    const double e = a.e(c, k);
    if (!res.mask[k] || !std::isfinite(e)) continue;
    m2 += e * e, m4 += e * e * e * e, ++n;
  }
  if (n < 2) return {};
  m2 /= static_cast<double>(n), m4 /= static_cast<double>(n);
  return {m2, std::max(m4 - m2 * m2, 1e-30)};
}

// sample jitter: the residual variance growing with the squared angular acceleration
PerChannel jitter(const Replay& r, const Residual& res, const CompareModel& m, const AfterFit& a, int s, double log_m) {
  const twin::SensorParams& p = m.sensor[s];
  const double sj2 = p.sample_jitter.enabled ? p.sample_jitter.sigma_s * p.sample_jitter.sigma_s : 0.0;
  Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
  Eigen::Vector2d bvec = Eigen::Vector2d::Zero();
  for (int j = 0; j < 3; ++j) {
    const SquareMoments sm = square_moments(res, a, s * 3 + j);
    if (!(sm.var > 0)) continue;
    for (std::size_t k = 0; k < res.n; ++k) {
      const double e = a.e(s * 3 + j, k);
      if (!res.mask[k] || !std::isfinite(e)) continue;
      const double g2 = std::pow(r.dw_axis_radps2(s, k, j) * kDegPerRad, 2);
      // var(e^2) as measured, grown with the model's own jitter as (v0 + sj2 g2)^2 / v0^2
      const double var = sm.var_of_square * std::pow(1.0 + sj2 * g2 / sm.var, 2) + 1e-30;
      const Eigen::Vector2d x(1.0, g2);
      A += x * x.transpose() / var;
      bvec += x * (e * e - sj2 * g2) / var;
    }
  }
  PerChannel out;
  if (A(1, 1) <= 0) return out;
  const Eigen::Vector2d beta = A.ldlt().solve(bvec);
  const double sd = std::sqrt(std::max(0.0, A.inverse()(1, 1)));
  if (!(sd > 0)) return out;
  const double t = beta[1] / sd;
  const double sig = std::sqrt(std::max(0.0, beta[1] + sj2));
  out.gain = t > 0 ? t * t : 0.0;
  out.ev = out.gain - log_m;
  out.params.push_back(noise_param(m, Param::kJitterSigmaS, s * 3, sig, sig > 0 ? 0.5 * sd / sig : 0.0));
  out.params.back().ref.row = -1;
  // a clock that wanders by more than a sample period is no jitter (the stamps would reorder)
  const double period_s = 1.0 / res.fs_hz;
  if (sig > period_s) {
    out.params.back().absurd = true;
    out.note = fmt::format("sensor {}: sigma {:.3g} s is more than one sample period ({:.3g} s): not a plausible "
                           "jitter (the stamps would reorder); where its evidence is high, the residual grows with the "
                           "angular acceleration for another reason (a timing or signal-chain mismatch)",
                           s + 1, sig, period_s);
  }
  return out;
}

// one candidate from per-channel results: the channels whose own evidence passes the threshold
// (a noise-model change must stand on its own channel), else the best one for the report
Candidate gather(Effect e, const std::vector<PerChannel>& per, int dof_per, double threshold) {
  Candidate c;
  c.effect = e;
  std::size_t best = 0;
  for (std::size_t i = 0; i < per.size(); ++i) if (per[i].ev > per[best].ev) best = i;
  double ev = 0.0, gain = 0.0;
  for (std::size_t i = 0; i < per.size(); ++i) {
    if (!(per[i].ev > threshold) && !(i == best && !(per[best].ev > threshold))) continue;
    ev += per[i].ev;
    gain += per[i].gain;
    c.params.insert(c.params.end(), per[i].params.begin(), per[i].params.end());
    c.dof += dof_per;
    if (c.note.empty() && !per[i].note.empty()) c.note = per[i].note;
  }
  for (const auto& fp : c.params) c.absurd = c.absurd || fp.absurd;
  c.evidence = ev;
  c.chi2 = std::max(0.0, gain);
  c.p_value = 1.0 - est::chi2_cdf(c.chi2, std::max(1, c.dof));
  c.testable = !c.params.empty();
  if (!c.testable) c.note = "not testable on this log";
  return c;
}

}  // namespace

NoiseModelFindings noise_model_candidates(const Replay& r, const Residual& res, const Channels& ch,
                                          const CompareModel& model, const AfterFit& after, double threshold) {
  const double log_m = log_blocks(ch);
  const double duration = r.t_s.back() - r.t_s.front();
  const SlowBlocks sb = slow_blocks(res);
  const int nc = res.channels();  // a single-sensor log: sensor 1's three channels
  const auto ncs = static_cast<std::size_t>(nc);
  std::vector<PerChannel> white(ncs), gm(ncs), rrw(ncs), bias(ncs), jit;
  for_each_index(nc, [&](int c) {
    const auto i = static_cast<std::size_t>(c);
    const ChannelData& C = ch[i];
    const std::vector<double> z = finite_or_zero(after.z[i]);
    white[i] = white_noise(res, C, c, model, z, log_m);
    const auto slow = slow_processes(C, c, model, sb, slow_means(res, sb, z), duration);
    gm[i] = slow[0];
    rrw[i] = slow[1];
    bias[i] = constant_bias(C, c, model, after, res, duration, log_m);
  });
  for (int s = 0; s < res.sensors; ++s) jit.push_back(jitter(r, res, model, after, s, log_m));
  NoiseModelFindings out;
  for (Candidate c : {gather(Effect::kWhiteNoise, white, 1, threshold), gather(Effect::kBiasInstability, gm, 2, threshold),
                      gather(Effect::kRateRandomWalk, rrw, 1, threshold), gather(Effect::kConstantBias, bias, 1, threshold),
                      gather(Effect::kSampleJitter, jit, 1, threshold)}) {
    // an implausible value is reported, not proposed (--apply writes the supported ones)
    (c.testable && c.evidence > threshold && !c.absurd ? out.supported : out.not_supported).push_back(c);
  }
  std::stable_sort(out.supported.begin(), out.supported.end(),
                   [](const Candidate& a, const Candidate& b) { return a.evidence > b.evidence; });
  return out;
}

}  // namespace driftless::diagnose
