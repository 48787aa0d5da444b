#include "diagnose/summary.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>

#include <fmt/core.h>

#include "diagnose/parallel.hpp"
#include "estimator/sample.hpp"
#include "estimator/stats.hpp"

namespace driftless::diagnose {
namespace {

// Ljung-Box portmanteau of a whitened series: Q, its p-value on lags - fitted degrees of
// freedom, and the effect size sum rho_h^2 - lags/m (about the fraction of the residual's
// variance its own past predicts, debiased: white noise gives ~0 on average)
struct Portmanteau {
  double q = 0.0, p = 1.0, excess = 0.0;
};
Portmanteau ljung_box(const std::vector<double>& x, int lags, int fitted) {
  const std::size_t m = x.size();
  if (m < static_cast<std::size_t>(lags) * 4) return {};
  const double mean = std::accumulate(x.begin(), x.end(), 0.0) / static_cast<double>(m);
  double c0 = 0.0;
  for (double v : x) c0 += (v - mean) * (v - mean);
  double q = 0.0, r2 = 0.0;
  for (int h = 1; h <= lags; ++h) {
    double ch = 0.0;
    for (std::size_t k = static_cast<std::size_t>(h); k < m; ++k) ch += (x[k] - mean) * (x[k - h] - mean);
    const double rho = ch / c0;
    q += rho * rho / static_cast<double>(m - static_cast<std::size_t>(h));
    r2 += rho * rho;
  }
  q *= static_cast<double>(m) * static_cast<double>(m + 2);
  return {q, 1.0 - est::chi2_cdf(q, std::max(1, lags - fitted)), r2 - static_cast<double>(lags) / static_cast<double>(m)};
}

// Allan variance of a first-order Gauss-Markov process (sigma^2, correlation time T)
double gm_avar(double sigma, double T, double tau) {
  if (sigma <= 0) return 0.0;
  const double x = tau / T;
  return sigma * sigma * 2.0 / (x * x) * (x - 1.5 + 2.0 * std::exp(-x) - 0.5 * std::exp(-2.0 * x));
}

// mean and rms of a per-sample float series over the fit samples (NaN left out)
struct RunningMeanRms {
  double s1 = 0, s2 = 0;
  std::size_t n = 0;
  void add(float e) {
    if (std::isfinite(e)) s1 += e, s2 += static_cast<double>(e) * e, ++n;
  }
  std::pair<double, double> mean_rms() const {
    const double d = std::max<double>(1.0, static_cast<double>(n));
    return {s1 / d, std::sqrt(s2 / d)};
  }
};

// the residual's Allan deviation (bias drift kept) against the model's N^2/tau + K^2 tau/3 + GM,
// with the model's band at the data's confidence. Samples left out (flips, kinks) are filled
// with the smoothed bias there, the residual's expected value: a held noisy sample would put a
// false bump into the curve at the flip period
void allan_against_model(const Residual& res, const twin::SensorParams& p, int j, double floor_dps, const AfterFit& a,
                         int c, ChannelSummary& cs) {
  std::vector<double> series(res.n);
  const auto& e_drift = a.e_drift[static_cast<std::size_t>(c)];
  const auto& bias = a.bias[static_cast<std::size_t>(c)];
  for (std::size_t k = 0; k < res.n; ++k) {
    const double fill = bias[k / res.block_len];
    series[k] = res.mask[k] && std::isfinite(e_drift[k]) ? e_drift[k] : (std::isfinite(fill) ? fill : 0.0);
  }
  if (series.size() < 16) return;
  est::AllanOptions ao;
  ao.sample_rate_hz = res.fs_hz;
  ao.confidence = 0.95;
  cs.adev = est::allan_deviation(series, ao);
  const double N = p.white_noise.enabled ? p.white_noise.density_dps_rthz[j] : 0.0;
  const double K = p.rate_random_walk.enabled ? p.rate_random_walk.k_dps_rts[j] : 0.0;
  int outside = 0, considered = 0;
  for (const auto& pt : cs.adev.points) {
    const double gm = p.bias_instability.enabled ? gm_avar(p.bias_instability.sigma_dps[j], p.bias_instability.tau_s[j], pt.tau_s) : 0.0;
    double avar = N * N / pt.tau_s + K * K * pt.tau_s / 3.0 + gm;
    // white noise seen through the DLPF at the shortest tau: the per-sample floor there
    if (pt.m == 1) avar = std::min(avar, floor_dps * floor_dps + K * K * pt.tau_s / 3.0 + gm);
    const double a = std::sqrt(avar);
    cs.adev_model.push_back(a);
    const double lo = pt.adev > 0 ? a * pt.adev_lo / pt.adev : a, hi = pt.adev > 0 ? a * pt.adev_hi / pt.adev : a;
    cs.adev_model_lo.push_back(lo);
    cs.adev_model_hi.push_back(hi);
    if (pt.tau_s < 0.1) continue;
    ++considered;
    if (pt.adev_hi < lo || pt.adev_lo > hi) ++outside;
  }
  cs.adev_outside_fraction = considered ? static_cast<double>(outside) / considered : 0.0;
}

// whiteness of the whitened block residual after the selection (the forward filter's
// innovations are white under the model whatever the nuisance; N takes one degree of freedom)
void whiteness(const ChannelData& c, const Residual& res, const std::vector<double>& z, const CompareOptions& opt,
               ChannelSummary& cs) {
  const BiasWhitener W(res.block_series, c.noise);
  std::vector<double> wz(z.size()), sel;
  W.whiten(z, wz);
  for (std::size_t b = 0; b < z.size(); ++b)
    if (W.used()[b]) sel.push_back(wz[b]);
  const Portmanteau lb = ljung_box(sel, opt.ljung_box_lags, 1);
  cs.ljung_box_q = lb.q;
  cs.ljung_box_p = lb.p;
  cs.autocorrelation_excess = lb.excess;
  cs.white = !(lb.p < opt.whiteness_alpha / 6.0 && lb.excess > opt.min_effect_fraction);
  cs.turn_on_sigma_dps = W.final_bias_sigma_dps();
}

}  // namespace

double AfterFit::bias_at(int c, std::size_t k) const {
  const std::vector<double>& bias = this->bias[static_cast<std::size_t>(c)];
  const std::size_t L = block_len, b = k / L;
  const double u = (static_cast<double>(k % L) + 0.5) / static_cast<double>(L) - 0.5;
  double bv = bias[b];
  if (u > 0 && b + 1 < bias.size()) bv += (bias[b + 1] - bias[b]) * u;
  if (u < 0 && b > 0) bv += (bias[b] - bias[b - 1]) * u;
  return bv;
}

AfterFit residual_after(const Channels& ch, const ColumnInputs& in, const Residual& res, const FitSpec& spec,
                        const FitResult& fit, AfterDetail detail) {
  AfterFit a;
  a.block_len = res.block_len;
  const bool keep = detail == AfterDetail::kSamples;
  // the channels are independent: on the machine's cores, each into its own slots
  for_each_index(6, [&](int c) {
    const ChannelData& C = ch[c];
    if (!C.present) {  // sensor 2 of a single-sensor log: NaN throughout
      a.z[c].assign(res.blocks, kNaN);
      a.bias[c].assign(res.blocks, kNaN);
      if (keep) a.e_drift[c].assign(res.n, std::numeric_limits<float>::quiet_NaN());
      return;
    }
    const Eigen::VectorXd coef = channel_coefficients(C, c, spec, fit);
    a.z[c] = block_residual(C, coef);
    a.bias[c] = BiasWhitener(res.block_series, C.noise).smooth(a.z[c]);
    for (std::size_t b = 0; b < res.blocks; ++b)
      if (!res.block_series.count[b]) a.z[c][b] = kNaN;
    if (detail == AfterDetail::kBlocks) return;
    if (keep) a.e_drift[c].resize(res.n);
    RunningMeanRms stats;
    ColumnSweep sweep(in, C.s, C.j);
    for (std::size_t k = 0; k < res.n; ++k) {
      double v = res.e_dps(c, k);
      if (std::isfinite(v)) {
        for (int i = 0; i < static_cast<int>(C.cols.size()); ++i)
          if (coef[i] != 0.0) v -= sweep.value(C.cols[i], k) * coef[i];
      }
      if (res.mask[k]) stats.add(static_cast<float>(v - a.bias_at(c, k)));
      if (keep) a.e_drift[c][k] = static_cast<float>(v);
    }
    std::tie(a.mean_dps[c], a.rms_dps[c]) = stats.mean_rms();
  });
  return a;
}

void summarise_channels(const Channels& ch, const Residual& res, const CompareModel& model,
                        const CompareModel& selected_model, const AfterFit& before, const AfterFit& after,
                        const CompareOptions& opt, CompareResult& out) {
  for (int c = 0; c < res.channels(); ++c) {
    const ChannelData& C = ch[c];
    ChannelSummary& cs = out.channels[c];
    const twin::SensorParams& p = model.sensor[C.s];
    const twin::SensorParams& p_sel = selected_model.sensor[C.s];
    RunningMeanRms raw;
    for (std::size_t k = 0; k < res.n; ++k)
      if (res.mask[k]) raw.add(static_cast<float>(res.e_dps(c, k)));
    std::tie(cs.raw_mean_dps, cs.raw_rms_dps) = raw.mean_rms();
    cs.mean_dps = before.mean_dps[c], cs.rms_dps = before.rms_dps[c];
    cs.rms_after_dps = after.rms_dps[c];
    cs.noise_floor_dps = white_noise_floor_dps(p, C.j, res.fs_hz);
    const double f2 = cs.noise_floor_dps * cs.noise_floor_dps;
    cs.systematic_rms_dps = std::sqrt(std::max(0.0, cs.rms_dps * cs.rms_dps - f2));
    const double floor_sel = white_noise_floor_dps(p_sel, C.j, res.fs_hz);
    cs.systematic_after_dps = std::sqrt(std::max(0.0, cs.rms_after_dps * cs.rms_after_dps - floor_sel * floor_sel));
    cs.white_fit_dps_rthz = C.noise.white_dps_rthz;
    whiteness(C, res, after.z[c], opt, cs);
    double bsum = 0;
    std::size_t bn = 0;
    for (std::size_t b = 0; b < res.blocks; ++b)
      if (res.block_series.count[b]) bsum += after.bias[c][b], ++bn;
    cs.turn_on_bias_dps = bn ? bsum / static_cast<double>(bn) : 0.0;
    allan_against_model(res, p_sel, C.j, white_noise_floor_dps(p_sel, C.j, res.fs_hz), after, c, cs);
  }
  for (int c = res.channels(); c < 6; ++c) {  // sensor 2 of a single-sensor log: null in the report
    ChannelSummary& cs = out.channels[c];
    for (double* v : {&cs.raw_mean_dps, &cs.raw_rms_dps, &cs.mean_dps, &cs.rms_dps, &cs.rms_after_dps, &cs.noise_floor_dps,
                      &cs.systematic_rms_dps, &cs.systematic_after_dps, &cs.white_fit_dps_rthz, &cs.ljung_box_q,
                      &cs.ljung_box_p, &cs.autocorrelation_excess, &cs.turn_on_bias_dps, &cs.turn_on_sigma_dps})
      *v = kNaN;
  }
}

}  // namespace driftless::diagnose
