#include "diagnose/compare.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <numeric>
#include <stdexcept>

#include <Eigen/Dense>
#include <fmt/core.h>

#include "estimator/stats.hpp"
#include "diagnose/bias_filter.hpp"

namespace driftless::diagnose {

using namespace driftless::twin;  // the sensor model, box and scenario types
namespace {

// the per-channel (or per-set) fits with positive evidence `ev`; if none has, the best one alone
template <class Fit>
std::vector<Fit> supported_or_best(const std::vector<Fit>& fits) {
  std::vector<Fit> chosen;
  for (const auto& f : fits)
    if (f.ev > 0) chosen.push_back(f);
  if (chosen.empty() && !fits.empty())
    chosen.push_back(*std::max_element(fits.begin(), fits.end(), [](const Fit& a, const Fit& b) { return a.ev < b.ev; }));
  return chosen;
}

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr const char* kAxis[3] = {"x", "y", "z"};

// ---- regressors: the residual each effect leaves, linear in its parameters (file units) ----
enum Col : int {
  kScale,      // scale_factor, %:              w_j / 100
  kMisA,       // misalignment, %:              w_a / 100 (a, b the other axes, a < b)
  kMisB,
  kG0, kG1, kG2,            // g_sensitivity, deg/s/g:   f_k / g
  kMount0, kMount1, kMount2,  // mounting_misalignment, deg: (w x e_k)_j
  kTempBias,   // temperature bias tc, deg/s/degC:  T - T_ref
  kTempScale,  // temperature scale tc, %/degC:     (T - T_ref) w_j / 100
  kNonlin2, kNonlin3,  // adc_nonlinearity, % FS:   FS u^2 / 100, FS u^3 / 100, u = y / FS
  kDelay,      // latency / time offset, s:      -dw_j/dt
  kEndPlus, kEndMinus,  // end_stop_error, deg:   -(a x w)_j at rest on that side
  kLat,        // latitude error, deg:           dy_j/dlat
  kFlip0, kFlip1, kFlip2, kFlip3,  // flip transients, deg/s: dir * 1[bin after the stop]
  kNumCols
};
constexpr double kRestAngleSigmaDeg = 0.01;  // deg, prior spread of a rest angle on a stop
constexpr double kFlipBins[5] = {0.0, 0.25, 0.5, 1.0, 2.0};  // s after a platform stops

struct Inputs {
  const Replay& r;
  const std::array<SensorPrediction, 2>& pred;
  const std::array<SensorParams, 2>& params;
};

// value of regressor `col` for channel (s, j) at sample k, in deg/s per unit parameter
double column_value(const Inputs& in, int s, int j, int col, std::size_t k) {
  const Replay& r = in.r;
  const Eigen::Vector3d& w = r.w_radps[s][k];
  switch (col) {
    case kScale: return w[j] * kDegPerRad / 100.0;
    case kMisA: return w[(j + 1) % 3 < (j + 2) % 3 ? (j + 1) % 3 : (j + 2) % 3] * kDegPerRad / 100.0;
    case kMisB: return w[(j + 1) % 3 < (j + 2) % 3 ? (j + 2) % 3 : (j + 1) % 3] * kDegPerRad / 100.0;
    case kG0: case kG1: case kG2: return r.f_mps2[s][k][col - kG0] / kStandardGravityMps2;
    case kMount0: case kMount1: case kMount2: {
      const Eigen::Vector3d e = Eigen::Vector3d::Unit(col - kMount0);
      return w.cross(e)[j] * kDegPerRad * kRadPerDeg;
    }
    case kTempBias: return in.pred[s].temp_c[k] - in.params[s].temperature.reference_degc;
    case kTempScale:
      return (in.pred[s].temp_c[k] - in.params[s].temperature.reference_degc) * w[j] * kDegPerRad / 100.0;
    case kNonlin2: case kNonlin3: {
      const double fs = in.params[s].saturation.full_scale_dps;
      const double u = in.pred[s].gyro_dps[k][j] / fs;
      return fs * (col == kNonlin2 ? u * u : u * u * u) / 100.0;
    }
    case kDelay: return -r.dw_radps2[s][k][j] * kDegPerRad;
    case kEndPlus: case kEndMinus: {
      const int side = col == kEndPlus ? 1 : -1;
      if (r.rest_side[s][k] != side) return 0.0;
      return -r.hinge_axis[s].cross(w)[j] * kDegPerRad * kRadPerDeg;
    }
    case kLat: return r.dw_dlat_radps[s][k][j] * kDegPerRad * kRadPerDeg;
    default: {  // flip bins
      const int b = col - kFlip0;
      const double since = r.since_flip_s[s][k];
      if (!(since >= kFlipBins[b] && since < kFlipBins[b + 1])) return 0.0;
      return static_cast<double>(r.last_flip_dir[s][k]);
    }
  }
}

// prior 1-sigma (file units) of a regressor's coefficient under the model: the run-to-run
// spread of effects the model has switched on; 0 = not a nuisance (the model says "exactly")
double prior_sigma(const SensorParams& p, int j, int col) {
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
    default: return 0.0;
  }
}

// one gyro channel's regression data (whitened block means)
struct Chan {
  int s = 0, j = 0;
  std::vector<int> cols;       // regressor ids present (non-degenerate)
  std::vector<double> prior;   // prior sigma per entry of cols (0 = free / not nuisance)
  Eigen::MatrixXd G;           // Gram of whitened [cols..., y]
  double sigma2 = 1.0;         // whitened residual variance of the null fit
  double J0 = 0.0;             // null objective (whitened RSS + prior penalty) / sigma2
  std::size_t m = 0;           // blocks used
  Eigen::VectorXd beta_null;   // MAP nuisance coefficients (per entry of cols; 0 if not nuisance)
  Eigen::MatrixXd raw_cols;    // block means of the columns (unwhitened), m_all x cols
  std::vector<double> z;       // block means of the residual
  ChannelNoise noise;          // model noise with the fitted white density
  int index(int col) const {
    auto it = std::find(cols.begin(), cols.end(), col);
    return it == cols.end() ? -1 : static_cast<int>(it - cols.begin());
  }
};

// solves the nuisance-only MAP fit of a channel with some columns excluded from the nuisance
struct Partial {
  Eigen::MatrixXd S;  // p x p
  Eigen::VectorXd s;  // p
  double J = 0.0;     // objective with the reduced nuisance
};

Partial partial_out(const Chan& c, const std::vector<int>& xcols /* col ids, -1 = absent */) {
  const int P = static_cast<int>(c.cols.size());
  const int yi = P;
  std::vector<int> N, X;
  for (int i = 0; i < P; ++i) {
    const bool in_x = std::find(xcols.begin(), xcols.end(), c.cols[i]) != xcols.end();
    if (!in_x && c.prior[i] > 0) N.push_back(i);
  }
  for (int col : xcols) X.push_back(col < 0 ? -1 : c.index(col));
  const int n = static_cast<int>(N.size()), p = static_cast<int>(X.size());
  Eigen::MatrixXd A(n, n);
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(n, p + 1);
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) A(a, b) = c.G(N[a], N[b]);
    const double pr = c.prior[N[a]];
    A(a, a) += c.sigma2 / (pr * pr);  // prior precision in whitened units
    for (int q = 0; q < p; ++q) B(a, q) = X[q] >= 0 ? c.G(N[a], X[q]) : 0.0;
    B(a, p) = c.G(N[a], yi);
  }
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(p + 1, p + 1);
  for (int q = 0; q < p; ++q) {
    for (int r = 0; r < p; ++r) C(q, r) = (X[q] >= 0 && X[r] >= 0) ? c.G(X[q], X[r]) : 0.0;
    C(q, p) = C(p, q) = X[q] >= 0 ? c.G(X[q], yi) : 0.0;
  }
  C(p, p) = c.G(yi, yi);
  if (n > 0) C -= B.transpose() * A.ldlt().solve(B);
  Partial out;
  out.S = C.topLeftCorner(p, p) / c.sigma2;
  out.s = C.col(p).head(p) / c.sigma2;
  out.J = C(p, p) / c.sigma2;
  return out;
}

// least squares on summed normal equations: beta, covariance, objective drop, rank
struct Solve {
  Eigen::VectorXd beta, sd;
  double drop = 0.0;
  int rank = 0;
};
Solve solve_normal(const Eigen::MatrixXd& S, const Eigen::VectorXd& s) {
  Solve out;
  const int p = static_cast<int>(S.rows());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(S);
  const double top = std::max(es.eigenvalues().maxCoeff(), 1e-300);
  Eigen::VectorXd inv = Eigen::VectorXd::Zero(p);
  for (int i = 0; i < p; ++i) {
    if (es.eigenvalues()[i] > 1e-9 * top && es.eigenvalues()[i] > 1e-12) {
      inv[i] = 1.0 / es.eigenvalues()[i];
      ++out.rank;
    }
  }
  const Eigen::MatrixXd Sinv = es.eigenvectors() * inv.asDiagonal() * es.eigenvectors().transpose();
  out.beta = Sinv * s;
  out.drop = s.dot(out.beta);
  out.sd = Sinv.diagonal().cwiseMax(0.0).cwiseSqrt();
  for (int i = 0; i < p; ++i) {
    if (Sinv(i, i) <= 0) out.sd[i] = kInf;
  }
  return out;
}

// golden-section minimum of f on [lo, hi] (log-space search by the caller)
double golden_min(const std::function<double(double)>& f, double lo, double hi, int iters = 40) {
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double a = lo, b = hi;
  double x1 = b - g * (b - a), x2 = a + g * (b - a);
  double f1 = f(x1), f2 = f(x2);
  for (int i = 0; i < iters; ++i) {
    if (f1 < f2) {
      b = x2; x2 = x1; f2 = f1; x1 = b - g * (b - a); f1 = f(x1);
    } else {
      a = x1; x1 = x2; f1 = f2; x2 = a + g * (b - a); f2 = f(x2);
    }
  }
  return 0.5 * (a + b);
}

double median_abs(std::vector<double> v) {
  if (v.empty()) return 0.0;
  auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end(), [](double a, double b) { return std::abs(a) < std::abs(b); });
  return std::abs(*mid);
}

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
  Portmanteau out;
  out.q = q;
  out.p = 1.0 - est::chi2_cdf(q, std::max(1, lags - fitted));
  out.excess = r2 - static_cast<double>(lags) / static_cast<double>(m);
  return out;
}

std::string axes_text(const std::vector<int>& axes) {
  std::string out;
  for (int a : axes) out += (out.empty() ? "" : ",") + std::string(kAxis[a]);
  return out.empty() ? "-" : out;
}

// Allan variance of a first-order Gauss-Markov process (sigma^2, correlation time T)
double gm_avar(double sigma, double T, double tau) {
  if (sigma <= 0) return 0.0;
  const double x = tau / T;
  return sigma * sigma * 2.0 / (x * x) * (x - 1.5 + 2.0 * std::exp(-x) - 0.5 * std::exp(-2.0 * x));
}

}  // namespace

void CompareOptions::validate() const {
  auto pos = [](double v, const char* n) {
    if (!(v > 0) || !std::isfinite(v)) throw std::invalid_argument(fmt::format("CompareOptions.{} must be > 0", n));
  };
  pos(block_s, "block_s");
  if (!(window_s >= 0)) throw std::invalid_argument("CompareOptions.window_s must be >= 0 s");
  if (worst_windows < 0) throw std::invalid_argument("CompareOptions.worst_windows must be >= 0");
  pos(whiteness_alpha, "whiteness_alpha");
  if (ljung_box_lags < 2) throw std::invalid_argument("CompareOptions.ljung_box_lags must be >= 2");
  if (!(min_effect_fraction >= 0 && min_effect_fraction < 1)) {
    throw std::invalid_argument("CompareOptions.min_effect_fraction must be in [0, 1)");
  }
  pos(correlation_z, "correlation_z");
  replay.validate();
}

std::string channel_name(int c) { return fmt::format("gyro{}_{}", c / 3 + 1, kAxis[c % 3]); }

CompareResult compare(const Replay& r, const CompareModel& model, const CompareOptions& opt) {
  opt.validate();
  CompareResult out;
  out.model_source = model.source;
  out.log_path = r.log_path;
  out.notes = r.notes;
  out.resampled = r.resampled;
  const std::size_t n = r.size();
  const double fs = r.sample_rate_hz;
  out.samples = n;
  out.sample_rate_hz = fs;
  out.duration_s = r.t_s.back() - r.t_s.front();

  // ---- predict, residual ----
  // platforms resting on stops: the model's stop errors plus the servo's press into the stop
  // (the MuJoCo box settled on them); logs with an encoder read the true angle instead
  const Eigen::Matrix2d settled = r.encoder_readback ? Eigen::Matrix2d::Zero() : settled_stop_offsets_deg(model.box);
  std::array<SensorPrediction, 2> pred{predict_sensor(r, 0, model.sensor[0], model.box, model.time_offset_s, settled),
                                       predict_sensor(r, 1, model.sensor[1], model.box, model.time_offset_s, settled)};
  if (!r.has_temp) {
    out.notes.push_back("the log has no temperature columns: the model's temperature curve is used");
  }
  const Inputs in{r, pred, model.sensor};
  std::vector<std::uint8_t> mask(n);
  for (std::size_t k = 0; k < n; ++k) mask[k] = r.usable[k] && !r.flipping[k] && !r.rough[k];
  std::array<std::vector<double>, 6> resid;
  for (int c = 0; c < 6; ++c) {
    resid[c].resize(n);
    const int s = c / 3, j = c % 3;
    for (std::size_t k = 0; k < n; ++k) {
      resid[c][k] = r.usable[k] ? r.gyro_dps[s][k][j] - pred[s].gyro_dps[k][j] : kNaN;
    }
  }
  // a platform that leaves its stop while the log says it rests (lifted by a box acceleration
  // the servo cannot hold, or bouncing after a flip) turns the sensor about the hinge axis only:
  // the residual along the hinge jumps between samples far beyond the noise while the other
  // axes do not. Those bursts are left out (no model here predicts them) and counted.
  for (int s = 0; s < 2; ++s) {
    const Eigen::Vector3d a = r.hinge_axis[s];
    std::vector<double> dh(n, 0.0), doff(n, 0.0);
    std::vector<double> sample;
    for (std::size_t k = 1; k < n; ++k) {
      if (!mask[k] || !mask[k - 1]) continue;
      Eigen::Vector3d d;
      for (int j = 0; j < 3; ++j) d[j] = resid[s * 3 + j][k] - resid[s * 3 + j][k - 1];
      dh[k] = std::abs(a.dot(d));
      doff[k] = (d - a * a.dot(d)).norm();
      if (k % 3 == 0) sample.push_back(dh[k]);
    }
    if (sample.size() < 20) continue;
    // robust spread of the hinge differences (floored: a noise-free log has none)
    const double sd = std::max(1.4826 * median_abs(sample), 1e-3);
    const auto guard = static_cast<std::size_t>(std::ceil(0.1 * fs));
    std::vector<std::uint8_t> bad(n, 0);
    for (std::size_t k = 1; k < n; ++k) {
      if (!(dh[k] > 12.0 * sd && dh[k] > 3.0 * doff[k])) continue;
      const std::size_t lo = k >= guard ? k - guard : 0, hi = std::min(n - 1, k + guard);
      for (std::size_t i = lo; i <= hi; ++i) bad[i] = 1;
    }
    std::size_t cnt = 0;
    for (std::size_t k = 0; k < n; ++k) {
      if (bad[k] && mask[k]) {
        mask[k] = 0;
        ++cnt;
      }
    }
    if (cnt > 0) {
      out.notes.push_back(fmt::format(
          "{} samples where platform {} turned about its hinge while the log says it rests (gyro {} jumps "
          "along the hinge axis beyond 12x its noise, the other axes do not: the platform left its stop) are "
          "left out of the fits",
          cnt, s + 1, s + 1));
    }
  }
  out.samples_used = static_cast<std::size_t>(std::count(mask.begin(), mask.end(), 1));
  if (out.samples_used < 50) {
    throw std::runtime_error(fmt::format("{}: only {} samples with both platforms at rest and known "
                                         "truth; compare needs at least 50", r.log_path, out.samples_used));
  }

  // ---- blocks ----
  const std::size_t L = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(opt.block_s * fs)));
  const std::size_t mb = (n + L - 1) / L;
  out.block_s = static_cast<double>(L) / fs;
  BlockSeries blocks;
  blocks.sample_rate_hz = fs;
  blocks.t_s.resize(mb);
  blocks.count.resize(mb);
  for (std::size_t b = 0; b < mb; ++b) {
    const std::size_t a = b * L, e = std::min(n, a + L);
    int cnt = 0;
    for (std::size_t k = a; k < e; ++k) cnt += mask[k];
    blocks.count[b] = static_cast<std::uint16_t>(2 * static_cast<std::size_t>(cnt) >= L ? cnt : 0);
    blocks.t_s[b] = 0.5 * (r.t_s[a] + r.t_s[e - 1]);
  }
  std::vector<std::uint8_t> bmask(n);
  for (std::size_t k = 0; k < n; ++k) bmask[k] = mask[k] && blocks.count[k / L] > 0;
  out.block_t_s = blocks.t_s;

  const double temp_span = [&] {
    double lo = kInf, hi = -kInf;
    for (int s = 0; s < 2; ++s)
      for (std::size_t k = 0; k < n; k += 10) {
        lo = std::min(lo, pred[s].temp_c[k]);
        hi = std::max(hi, pred[s].temp_c[k]);
      }
    return hi - lo;
  }();

  // ---- per channel: columns, whitening, Gram, nuisance fit ----
  std::array<Chan, 6> ch;
  std::vector<double> tmp(n), wtmp(mb);
  for (int c = 0; c < 6; ++c) {
    Chan& C = ch[c];
    C.s = c / 3;
    C.j = c % 3;
    const SensorParams& p = model.sensor[C.s];
    C.z.assign(mb, 0.0);
    block_means(resid[c], bmask, L, C.z);
    std::vector<std::vector<double>> colv;
    for (int col = 0; col < kNumCols; ++col) {
      if ((col == kTempBias || col == kTempScale) && temp_span < 0.2) continue;
      for (std::size_t k = 0; k < n; ++k) tmp[k] = bmask[k] ? column_value(in, C.s, C.j, col, k) : 0.0;
      std::vector<double> bm(mb);
      block_means(tmp, bmask, L, bm);
      double ss = 0.0;
      for (std::size_t b = 0; b < mb; ++b) ss += blocks.count[b] ? bm[b] * bm[b] : 0.0;
      if (ss < 1e-20) continue;  // not excited by this log
      C.cols.push_back(col);
      C.prior.push_back(prior_sigma(p, C.j, col));
      colv.push_back(std::move(bm));
    }
    const int P = static_cast<int>(C.cols.size());
    C.raw_cols.resize(static_cast<Eigen::Index>(mb), P);
    for (int i = 0; i < P; ++i)
      for (std::size_t b = 0; b < mb; ++b) C.raw_cols(static_cast<Eigen::Index>(b), i) = colv[i][b];

    // noise model: the model's bias processes, white density fitted (a nuisance)
    C.noise.white_dps_rthz = p.white_noise.enabled ? std::max(1e-6, p.white_noise.density_dps_rthz[C.j]) : 1e-6;
    C.noise.gm_sigma_dps = p.bias_instability.enabled ? p.bias_instability.sigma_dps[C.j] : 0.0;
    C.noise.gm_tau_s = p.bias_instability.tau_s[C.j];
    C.noise.rrw_dps_rts = p.rate_random_walk.enabled ? p.rate_random_walk.k_dps_rts[C.j] : 0.0;
    C.noise.turn_on_sigma_dps = 1e3;
  }

  // fit N on a residual, then whiten columns and build the Gram and the MAP nuisance fit
  auto fit_white = [&](Chan& C, const std::vector<double>& zres) {
    std::vector<double> d;
    for (std::size_t b = 1; b < mb; ++b)
      if (blocks.count[b] && blocks.count[b - 1]) d.push_back(zres[b] - zres[b - 1]);
    const double n0 = std::max(1e-7, 1.4826 * median_abs(d) / std::sqrt(2.0) * std::sqrt(static_cast<double>(L) / fs));
    auto f = [&](double logN) {
      ChannelNoise nz = C.noise;
      nz.white_dps_rthz = std::exp(logN);
      return BiasWhitener(blocks, nz).neg2_loglik(zres);
    };
    C.noise.white_dps_rthz = std::exp(golden_min(f, std::log(n0) - 2.0, std::log(n0) + 2.0, 30));
  };
  auto build_gram = [&](Chan& C) {
    const int P = static_cast<int>(C.cols.size());
    BiasWhitener W(blocks, C.noise);
    C.m = W.used_count();
    Eigen::MatrixXd A(static_cast<Eigen::Index>(mb), P + 1);
    std::vector<double> col(mb);
    for (int i = 0; i <= P; ++i) {
      for (std::size_t b = 0; b < mb; ++b) col[b] = i < P ? C.raw_cols(static_cast<Eigen::Index>(b), i) : C.z[b];
      W.whiten(col, wtmp);
      for (std::size_t b = 0; b < mb; ++b) A(static_cast<Eigen::Index>(b), i) = wtmp[b];
    }
    C.G = A.transpose() * A;
    C.sigma2 = 1.0;
    // null fit (MAP nuisance) and its objective
    Partial p0 = partial_out(C, {});
    C.sigma2 = std::max(1e-6, p0.J / static_cast<double>(std::max<std::size_t>(C.m, 1)));
    p0 = partial_out(C, {});
    C.J0 = p0.J;
    // nuisance coefficients
    std::vector<int> N;
    for (int i = 0; i < P; ++i) if (C.prior[i] > 0) N.push_back(i);
    C.beta_null = Eigen::VectorXd::Zero(P);
    if (!N.empty()) {
      const int k = static_cast<int>(N.size());
      Eigen::MatrixXd Am(k, k);
      Eigen::VectorXd bv(k);
      for (int a = 0; a < k; ++a) {
        for (int b = 0; b < k; ++b) Am(a, b) = C.G(N[a], N[b]);
        Am(a, a) += C.sigma2 / (C.prior[N[a]] * C.prior[N[a]]);
        bv[a] = C.G(N[a], P);
      }
      const Eigen::VectorXd x = Am.ldlt().solve(bv);
      for (int a = 0; a < k; ++a) C.beta_null[N[a]] = x[a];
    }
  };
  auto nuisance_residual = [&](const Chan& C) {
    std::vector<double> zr = C.z;
    for (std::size_t b = 0; b < mb; ++b)
      for (int i = 0; i < static_cast<int>(C.cols.size()); ++i)
        zr[b] -= C.raw_cols(static_cast<Eigen::Index>(b), i) * C.beta_null[i];
    return zr;
  };
  // all coefficients of channel C given a candidate's fitted columns: the candidate's values,
  // and the nuisance re-fitted (MAP) with those columns held, from the whitened Gram:
  // beta_N = (G_NN + sigma^2/prior^2)^-1 (G_Ny - G_NX beta_X)
  auto coefficients_given = [&](const Chan& C, int c, const Candidate& cd) {
    const int P = static_cast<int>(C.cols.size());
    Eigen::VectorXd coef = Eigen::VectorXd::Zero(P);
    std::vector<int> held;
    for (const auto& f : cd.fit) {
      if (f.channel != c) continue;
      const int i = C.index(f.column);
      if (i < 0) continue;
      coef[i] = f.beta;
      held.push_back(i);
    }
    std::vector<int> N;
    for (int i = 0; i < P; ++i)
      if (C.prior[i] > 0 && std::find(held.begin(), held.end(), i) == held.end()) N.push_back(i);
    if (!N.empty()) {
      const int k = static_cast<int>(N.size());
      Eigen::MatrixXd Am(k, k);
      Eigen::VectorXd bv(k);
      for (int a = 0; a < k; ++a) {
        for (int b = 0; b < k; ++b) Am(a, b) = C.G(N[a], N[b]);
        Am(a, a) += C.sigma2 / (C.prior[N[a]] * C.prior[N[a]]);
        bv[a] = C.G(N[a], P);
        for (int h : held) bv[a] -= C.G(N[a], h) * coef[h];
      }
      const Eigen::VectorXd x = Am.ldlt().solve(bv);
      for (int a = 0; a < k; ++a) coef[N[a]] = x[a];
    }
    return coef;
  };
  auto block_residual_given = [&](const Chan& C, const Eigen::VectorXd& coef) {
    std::vector<double> zr = C.z;
    for (int i = 0; i < static_cast<int>(C.cols.size()); ++i) {
      if (coef[i] == 0.0) continue;
      for (std::size_t b = 0; b < mb; ++b) zr[b] -= C.raw_cols(static_cast<Eigen::Index>(b), i) * coef[i];
    }
    return zr;
  };
  for (auto& C : ch) {
    fit_white(C, C.z);
    build_gram(C);
    fit_white(C, nuisance_residual(C));  // refit N without the nuisance structure
    build_gram(C);
  }
  out.blocks_used = ch[0].m;
  double m_total = 0.0;
  for (auto& C : ch) m_total += static_cast<double>(C.m);
  const double log_m = std::log(std::max(2.0, m_total / 6.0));

  // ---- candidates ----
  std::vector<Candidate> cands;
  // evaluates shared parameters over a set of channels: params -> column per channel
  auto eval_regression = [&](const std::vector<int>& chans, const std::vector<int>& xcols) {
    const int p = static_cast<int>(xcols.size());
    Eigen::MatrixXd S = Eigen::MatrixXd::Zero(p, p);
    Eigen::VectorXd s = Eigen::VectorXd::Zero(p);
    double Jnull = 0.0, Jred = 0.0;
    for (int c : chans) {
      std::vector<int> present;
      for (int col : xcols) present.push_back(ch[c].index(col) >= 0 ? col : -1);
      const Partial pt = partial_out(ch[c], present);
      S += pt.S;
      s += pt.s;
      Jnull += ch[c].J0;
      Jred += pt.J;
    }
    Solve sv = solve_normal(S, s);
    struct R { Solve sv; double gain, Jnull; } res{sv, Jnull - (Jred - sv.drop), Jnull};
    return res;
  };
  auto make_fit = [&](Candidate& cd, const std::vector<int>& chans, const std::vector<int>& xcols,
                      const Solve& sv) {
    for (int c : chans)
      for (std::size_t q = 0; q < xcols.size(); ++q)
        if (ch[c].index(xcols[q]) >= 0 && std::isfinite(sv.sd[static_cast<Eigen::Index>(q)]))
          cd.fit.push_back({c, xcols[q], sv.beta[static_cast<Eigen::Index>(q)], sv.sd[static_cast<Eigen::Index>(q)]});
  };

  // systematic candidates; evaluated again once the white level is refitted without the
  // strongest supported one (a large missing effect would otherwise inflate the fitted noise
  // density and hide itself and others)
  auto evaluate_systematic = [&]() {
  // per-channel regression effects, aggregated over channels with positive evidence
  struct PerChannelDef {
    const char* effect;
    std::vector<int> cols;
    std::vector<std::string> names;
    std::vector<std::string> units;
  };
  const std::vector<PerChannelDef> per_channel = {
      {"scale_factor", {kScale}, {"value_pct"}, {"%"}},
      {"misalignment", {kMisA, kMisB}, {"matrix_pct[a]", "matrix_pct[b]"}, {"%", "%"}},
      {"g_sensitivity", {kG0, kG1, kG2}, {"matrix_dps_per_g[x]", "matrix_dps_per_g[y]", "matrix_dps_per_g[z]"},
       {"deg/s/g", "deg/s/g", "deg/s/g"}},
      {"temperature", {kTempBias, kTempScale}, {"bias_tc_dps_per_degc", "scale_tc_pct_per_degc"},
       {"deg/s/degC", "%/degC"}},
      {"adc_nonlinearity", {kNonlin2, kNonlin3}, {"quadratic_pct_fs", "cubic_pct_fs"}, {"% FS", "% FS"}},
      {"flip_transient", {kFlip0, kFlip1, kFlip2, kFlip3},
       {"0-0.25s_dps", "0.25-0.5s_dps", "0.5-1s_dps", "1-2s_dps"}, {"deg/s", "deg/s", "deg/s", "deg/s"}},
  };
  for (const auto& def : per_channel) {
    Candidate cd;
    cd.effect = def.effect;
    cd.kind = std::string(def.effect) == "flip_transient" ? "box" : "regression";
    cd.applicable = cd.kind == "regression";
    std::vector<std::pair<int, double>> per;  // channel, evidence
    double gain_sum = 0.0, jn_sum = 0.0, chi2 = 0.0;
    int dof = 0;
    struct Best { int c; std::vector<int> cols; Solve sv; double ev, gain, jn; };
    std::vector<Best> bests;
    for (int c = 0; c < 6; ++c) {
      std::vector<int> cols;
      for (int col : def.cols) if (ch[c].index(col) >= 0) cols.push_back(col);
      if (cols.empty()) continue;
      // temperature: the bias term alone, the scale term alone, or both (best evidence)
      std::vector<std::vector<int>> subsets{cols};
      if (std::string(def.effect) == "temperature" && cols.size() == 2) subsets = {cols, {cols[0]}, {cols[1]}};
      Best best{c, {}, {}, -kInf, 0, 0};
      for (const auto& sub : subsets) {
        auto res = eval_regression({c}, sub);
        const double ev = res.gain - res.sv.rank * log_m;
        if (ev > best.ev) best = {c, sub, res.sv, ev, res.gain, res.Jnull};
      }
      if (best.cols.empty()) continue;
      bests.push_back(best);
    }
    if (bests.empty()) {
      cd.testable = false;
      cd.note = "not excited by this log (no variation of the driving signal)";
      cands.push_back(cd);
      continue;
    }
    const std::vector<Best> chosen = supported_or_best(bests);
    double ev_sum = 0.0;
    std::vector<int> s_set, axes1, axes2;
    for (const auto& b : chosen) {
      ev_sum += b.ev;
      gain_sum += b.gain;
      jn_sum += b.jn;
      chi2 += b.gain;
      dof += b.sv.rank;
      (b.c / 3 == 0 ? axes1 : axes2).push_back(b.c % 3);
      make_fit(cd, {b.c}, b.cols, b.sv);
      for (std::size_t q = 0; q < b.cols.size(); ++q) {
        const auto it = std::find(def.cols.begin(), def.cols.end(), b.cols[q]);
        std::string name = def.names[static_cast<std::size_t>(it - def.cols.begin())];
        const int j = b.c % 3;
        if (b.cols[q] == kMisA || b.cols[q] == kMisB) {
          const int lo = std::min((j + 1) % 3, (j + 2) % 3), hi = std::max((j + 1) % 3, (j + 2) % 3);
          name = fmt::format("matrix_pct[{}][{}]", kAxis[j], kAxis[b.cols[q] == kMisA ? lo : hi]);
        } else if (b.cols[q] >= kG0 && b.cols[q] <= kG2) {
          name = fmt::format("matrix_dps_per_g[{}][{}]", kAxis[j], kAxis[b.cols[q] - kG0]);
        } else {
          name = fmt::format("{}.{}", kAxis[j], name);
        }
        cd.params.push_back({fmt::format("s{}.{}", b.c / 3 + 1, name), b.sv.beta[static_cast<Eigen::Index>(q)],
                             b.sv.sd[static_cast<Eigen::Index>(q)],
                             def.units[static_cast<std::size_t>(it - def.cols.begin())]});
      }
    }
    cd.evidence = ev_sum;
    cd.chi2 = chi2;
    cd.dof = dof;
    cd.p_value = 1.0 - est::chi2_cdf(chi2, std::max(1, dof));
    cd.explained_fraction = jn_sum > 0 ? gain_sum / jn_sum : 0.0;
    cd.sensor = axes1.empty() ? "2" : axes2.empty() ? "1" : "both";
    cd.axis = axes1.empty() ? axes_text(axes2) : axes2.empty() ? axes_text(axes1)
                            : "s1:" + axes_text(axes1) + " s2:" + axes_text(axes2);
    cands.push_back(cd);
  }

  // shared-parameter regression effects
  struct SharedDef {
    const char* effect;
    std::vector<int> cols;
    std::vector<std::string> names;
    std::string unit;
    std::vector<std::vector<int>> channel_sets;  // evaluated separately; positive ones summed
    std::vector<std::string> sensor_names;
    std::string kind;
  };
  const std::vector<SharedDef> shared = {
      {"mounting_misalignment", {kMount0, kMount1, kMount2}, {"angles_deg[x]", "angles_deg[y]", "angles_deg[z]"}, "deg",
       {{0, 1, 2}, {3, 4, 5}}, {"1", "2"}, "regression"},
      {"end_stop_error", {kEndPlus, kEndMinus}, {"plus_stop_deg", "minus_stop_deg"}, "deg",
       {{0, 1, 2}, {3, 4, 5}}, {"1", "2"}, "box"},
      {"lowpass_latency", {kDelay}, {"delay_s"}, "s", {{0, 1, 2}, {3, 4, 5}}, {"1", "2"}, "regression"},
      {"time_offset", {kDelay}, {"offset_s"}, "s", {{0, 1, 2, 3, 4, 5}}, {"both"}, "box"},
      {"earth_rate", {kLat}, {"latitude_error_deg"}, "deg", {{0, 1, 2, 3, 4, 5}}, {"both"}, "box"},
  };
  // full-rate lag-1 autocorrelation of the residual noise per sensor, for lowpass_latency
  std::array<double, 2> rho1{0, 0}, rho1_model{0, 0};
  std::array<double, 2> rho1_n{0, 0};
  {
    for (int s = 0; s < 2; ++s) {
      rho1_model[s] = dlpf_lag1_autocorrelation(deterministic_part(model.sensor[s]), fs);
      double num = 0, den = 0;
      std::size_t cnt = 0;
      for (int j = 0; j < 3; ++j) {
        const auto& e = resid[s * 3 + j];
        // high-pass by differencing block-local means: use e_k - mean of its block
        for (std::size_t k = 1; k < n; ++k) {
          if (!bmask[k] || !bmask[k - 1] || k / L != (k - 1) / L) continue;
          const double mu = ch[s * 3 + j].z[k / L];
          num += (e[k] - mu) * (e[k - 1] - mu);
          den += (e[k] - mu) * (e[k] - mu);
          ++cnt;
        }
      }
      // block-local demeaning biases lag-1 autocorrelation by about -1/(L-1)
      rho1[s] = den > 0 ? num / den + (L > 2 ? 1.0 / static_cast<double>(L - 1) : 0.0) : 0.0;
      rho1_n[s] = static_cast<double>(cnt);
    }
  }
  for (const auto& def : shared) {
    Candidate cd;
    cd.effect = def.effect;
    cd.kind = def.kind;
    cd.applicable = def.kind == "regression" || cd.effect == "earth_rate" || cd.effect == "end_stop_error" ||
                    cd.effect == "time_offset";
    std::vector<std::string> sensors_used;
    double ev_sum = 0, gain_sum = 0, jn_sum = 0;
    int dof = 0;
    struct One { std::size_t set; Solve sv; double ev, gain, jn; };
    std::vector<One> ones;
    for (std::size_t si = 0; si < def.channel_sets.size(); ++si) {
      auto res = eval_regression(def.channel_sets[si], def.cols);
      if (res.sv.rank == 0) continue;
      double ev = res.gain - res.sv.rank * log_m;
      if (cd.effect == "lowpass_latency" && ev > 0) {
        // the DLPF also colours the noise: its lag-1 autocorrelation must move the same way
        const int s = static_cast<int>(si);
        const double dz = (rho1[s] - rho1_model[s]) * std::sqrt(std::max(1.0, rho1_n[s]));
        const double beta = res.sv.beta[0];
        const bool same_sign = (beta > 0) == (rho1[s] > rho1_model[s]);
        ev += (same_sign ? dz * dz : -dz * dz) - log_m;
      }
      ones.push_back({si, res.sv, ev, res.gain, res.Jnull});
    }
    if (ones.empty()) {
      cd.testable = false;
      cd.note = "not excited by this log";
      cands.push_back(cd);
      continue;
    }
    const std::vector<One> chosen = supported_or_best(ones);
    for (const auto& o : chosen) {
      ev_sum += o.ev;
      gain_sum += o.gain;
      jn_sum += o.jn;
      dof += o.sv.rank;
      sensors_used.push_back(def.sensor_names[o.set]);
      make_fit(cd, def.channel_sets[o.set], def.cols, o.sv);
      for (std::size_t q = 0; q < def.cols.size(); ++q) {
        const auto qi = static_cast<Eigen::Index>(q);
        if (!std::isfinite(o.sv.sd[qi])) continue;
        const std::string pre = def.sensor_names[o.set] == "both" ? "" : "s" + def.sensor_names[o.set] + ".";
        cd.params.push_back({pre + def.names[q], o.sv.beta[qi], o.sv.sd[qi], def.unit});
      }
    }
    cd.evidence = ev_sum;
    cd.chi2 = gain_sum;
    cd.dof = dof;
    cd.p_value = 1.0 - est::chi2_cdf(gain_sum, std::max(1, dof));
    cd.explained_fraction = jn_sum > 0 ? gain_sum / jn_sum : 0.0;
    cd.sensor = sensors_used.size() == 2 ? "both" : sensors_used[0];
    cd.axis = "x,y,z";
    if (cd.effect == "end_stop_error") {
      // equal errors at both stops are a rotation about the hinge axis: the same residual as a
      // mounting rotation about that axis while the platform rests (only flips tell them apart)
      for (std::size_t i = 0; i + 1 < cd.params.size(); i += 2) {
        const auto& a = cd.params[i];
        const auto& b = cd.params[i + 1];
        if (std::abs(a.value - b.value) < 2.0 * std::hypot(a.sigma, b.sigma) + 0.1 * std::abs(a.value))
          cd.note = "equal errors at both stops: indistinguishable from mounting_misalignment about the hinge axis";
      }
    }
    if (cd.effect == "mounting_misalignment") {
      cd.note = "a rotation about a platform's hinge axis is indistinguishable from equal end-stop errors";
    }
    if (cd.effect == "lowpass_latency") {
      for (const auto& o : chosen) {
        const int s = static_cast<int>(o.set);
        cd.params.push_back({fmt::format("s{}.noise_lag1_autocorrelation", s + 1), rho1[s],
                             1.0 / std::sqrt(std::max(1.0, rho1_n[s])), "-"});
        cd.params.push_back({fmt::format("s{}.model_lag1_autocorrelation", s + 1), rho1_model[s], 0.0, "-"});
      }
    }
    cands.push_back(cd);
  }

  };
  evaluate_systematic();
  for (int pass = 0; pass < 2; ++pass) {
    const Candidate* top = nullptr;
    for (const auto& cd : cands)
      if (cd.testable && !cd.fit.empty() && cd.kind != "adc" && cd.evidence > opt.evidence_threshold &&
          (!top || cd.evidence > top->evidence))
        top = &cd;
    if (!top) break;
    bool changed = false;
    for (int c = 0; c < 6; ++c) {
      Chan& C = ch[c];
      bool touched = false;
      for (const auto& f : top->fit) touched = touched || (f.channel == c && C.index(f.column) >= 0);
      const std::vector<double> zr = touched ? block_residual_given(C, coefficients_given(C, c, *top)) : std::vector<double>{};
      if (!touched) continue;
      const double before = C.noise.white_dps_rthz;
      fit_white(C, zr);
      if (std::abs(C.noise.white_dps_rthz / before - 1.0) > 0.02) changed = true;
      build_gram(C);
    }
    if (!changed) break;
    cands.clear();
    evaluate_systematic();
  }

  // ---- full-rate residual after the nuisance fit (for rms, regimes, windows, ADEV) ----
  std::array<std::vector<double>, 6> e_nuis;  // bias drift kept (for ADEV)
  std::array<std::vector<double>, 6> e;       // smoothed bias removed too
  for (int c = 0; c < 6; ++c) {
    Chan& C = ch[c];
    e_nuis[c].resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      double v = resid[c][k];
      if (!std::isfinite(v)) { e_nuis[c][k] = kNaN; continue; }
      for (int i = 0; i < static_cast<int>(C.cols.size()); ++i)
        if (C.beta_null[i] != 0.0) v -= column_value(in, C.s, C.j, C.cols[i], k) * C.beta_null[i];
      e_nuis[c][k] = v;
    }
    std::vector<double> zr = nuisance_residual(C);
    BiasWhitener W(blocks, C.noise);
    const std::vector<double> bias = W.smooth(zr);
    out.block_residual_dps[c] = zr;
    out.block_bias_dps[c] = bias;
    for (std::size_t b = 0; b < mb; ++b) if (!blocks.count[b]) out.block_residual_dps[c][b] = kNaN;
    // bias per sample: linear interpolation between block centres
    e[c].resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      const double bt = (static_cast<double>(k % L) + 0.5) / static_cast<double>(L) - 0.5;
      const std::size_t b = k / L;
      double bv = bias[b];
      if (bt > 0 && b + 1 < mb) bv += (bias[b + 1] - bias[b]) * bt;
      if (bt < 0 && b > 0) bv += (bias[b] - bias[b - 1]) * bt;
      e[c][k] = e_nuis[c][k] - bv;
    }
    ChannelSummary& cs = out.channels[c];
    const SensorParams& p = model.sensor[C.s];
    double s1 = 0, s2 = 0, r1 = 0, r2 = 0;
    std::size_t cnt = 0;
    for (std::size_t k = 0; k < n; ++k) {
      if (!mask[k] || !std::isfinite(e[c][k])) continue;
      s1 += e[c][k]; s2 += e[c][k] * e[c][k];
      r1 += resid[c][k]; r2 += resid[c][k] * resid[c][k];
      ++cnt;
    }
    const double dn = std::max<double>(1.0, static_cast<double>(cnt));
    cs.mean_dps = s1 / dn;
    cs.rms_dps = std::sqrt(s2 / dn);
    cs.raw_mean_dps = r1 / dn;
    cs.raw_rms_dps = std::sqrt(r2 / dn);
    cs.noise_floor_dps = white_noise_floor_dps(p, C.j, fs);
    cs.systematic_rms_dps = std::sqrt(std::max(0.0, cs.rms_dps * cs.rms_dps - cs.noise_floor_dps * cs.noise_floor_dps));
    cs.white_fit_dps_rthz = C.noise.white_dps_rthz;
    // whiteness of the whitened block residual
    std::vector<double> wz(mb), wsel;
    W.whiten(zr, wz);
    for (std::size_t b = 0; b < mb; ++b) if (W.used()[b]) wsel.push_back(wz[b]);
    // the forward filter's innovations are white under the model whatever the nuisance; the
    // fitted white density takes one degree of freedom
    const Portmanteau lb = ljung_box(wsel, opt.ljung_box_lags, 1);
    cs.ljung_box_q = lb.q;
    cs.ljung_box_p = lb.p;
    cs.autocorrelation_excess = lb.excess;
    cs.white = !(lb.p < opt.whiteness_alpha / 6.0 && lb.excess > opt.min_effect_fraction);
    // turn-on bias
    double bsum = 0; std::size_t bn = 0;
    for (std::size_t b = 0; b < mb; ++b) if (blocks.count[b]) { bsum += bias[b]; ++bn; }
    cs.turn_on_bias_dps = bn ? bsum / static_cast<double>(bn) : 0.0;
    cs.turn_on_sigma_dps = W.final_bias_sigma_dps();
    // ADEV of the residual with the bias drift kept, against the model's
    std::vector<double> series;
    series.reserve(n);
    double last = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      if (mask[k] && std::isfinite(e_nuis[c][k])) last = e_nuis[c][k];
      series.push_back(last);  // flips filled with the last value (short gaps)
    }
    est::AllanOptions ao;
    ao.sample_rate_hz = fs;
    if (series.size() >= 16) {
      cs.adev = est::allan_deviation(series, ao);
      int outside = 0;
      for (const auto& pt : cs.adev.points) {
        const double Nn = p.white_noise.enabled ? p.white_noise.density_dps_rthz[C.j] : 0.0;
        const double K = p.rate_random_walk.enabled ? p.rate_random_walk.k_dps_rts[C.j] : 0.0;
        const double gm = p.bias_instability.enabled ? gm_avar(p.bias_instability.sigma_dps[C.j], p.bias_instability.tau_s[C.j], pt.tau_s) : 0.0;
        // white noise seen through the DLPF at the shortest taus: use the floor there
        double avar = Nn * Nn / pt.tau_s + K * K * pt.tau_s / 3.0 + gm;
        if (pt.m == 1) avar = std::min(avar, cs.noise_floor_dps * cs.noise_floor_dps * 2.0 / 2.0 + K * K * pt.tau_s / 3.0 + gm);
        const double a = std::sqrt(avar);
        cs.adev_model.push_back(a);
        if (pt.tau_s >= 0.1 && (a < pt.adev_lo / 1.25 || a > pt.adev_hi * 1.25)) ++outside;
      }
      int considered = 0;
      for (const auto& pt : cs.adev.points) considered += pt.tau_s >= 0.1;
      cs.adev_outside_fraction = considered ? static_cast<double>(outside) / considered : 0.0;
    }
  }

  // ---- noise-type candidates: on the residual after the nuisance fit and after the best
  // supported systematic candidate (forward selection: a missing systematic effect must not
  // be mistaken for more noise) ----
  // per channel: the strongest supported systematic candidate that touches it
  std::array<const Candidate*, 6> sys_on{};
  for (const auto& cd : cands) {
    if (!cd.testable || cd.fit.empty() || cd.evidence <= opt.evidence_threshold) continue;
    for (const auto& f : cd.fit)
      if (!sys_on[f.channel] || cd.evidence > sys_on[f.channel]->evidence) sys_on[f.channel] = &cd;
  }
  auto noise_residual = [&](const Chan& C, int c) {
    if (!sys_on[c]) return nuisance_residual(C);
    return block_residual_given(C, coefficients_given(C, c, *sys_on[c]));
  };
  {
    struct NoiseRes { double ev; std::vector<FittedParam> params; double gain; };
    std::array<std::array<NoiseRes, 3>, 6> nr;
    // 1 s blocks for the slow processes
    const std::size_t L1 = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(1.0 / out.block_s)));
    BlockSeries b1;
    b1.sample_rate_hz = fs;
    const std::size_t m1 = (mb + L1 - 1) / L1;
    b1.t_s.resize(m1);
    b1.count.resize(m1);
    for (std::size_t b = 0; b < m1; ++b) {
      std::size_t cnt = 0;
      for (std::size_t q = b * L1; q < std::min(mb, (b + 1) * L1); ++q) cnt += blocks.count[q];
      b1.count[b] = static_cast<std::uint16_t>(std::min<std::size_t>(cnt, 65535));
      b1.t_s[b] = blocks.t_s[std::min(mb - 1, b * L1 + L1 / 2)];
    }
    for (int c = 0; c < 6; ++c) {
      Chan& C = ch[c];
      const SensorParams& p = model.sensor[C.s];
      std::vector<double> zr = noise_residual(C, c);
      if (sys_on[c]) fit_white(C, zr);  // the white level without the systematic part
      // white noise: fitted N (already the nuisance value) against the model's N
      ChannelNoise nm = C.noise;
      const double Nmodel = p.white_noise.enabled ? p.white_noise.density_dps_rthz[C.j] : 0.0;
      // the DLPF correlates neighbouring samples: the model's block-mean noise is a bit lower
      nm.white_dps_rthz = std::max(Nmodel * std::sqrt(block_mean_variance_ratio(deterministic_part(p), fs, L)), 1e-7);
      const double l_model = BiasWhitener(blocks, nm).neg2_loglik(zr);
      const double l_fit = BiasWhitener(blocks, C.noise).neg2_loglik(zr);
      const double gw = l_model - l_fit;
      const double mused = static_cast<double>(C.m);
      nr[c][0] = {gw - log_m, {{fmt::format("s{}.{}.density_dps_rthz", C.s + 1, kAxis[C.j]), C.noise.white_dps_rthz,
                                C.noise.white_dps_rthz / std::sqrt(2.0 * std::max(1.0, mused)), "deg/s/rtHz"}}, gw};
      // slow processes on 1 s block means (count-weighted)
      std::vector<double> z1(m1, 0.0);
      for (std::size_t b = 0; b < m1; ++b) {
        double acc = 0; std::size_t cnt = 0;
        for (std::size_t q = b * L1; q < std::min(mb, (b + 1) * L1); ++q) {
          acc += zr[q] * blocks.count[q];
          cnt += blocks.count[q];
        }
        z1[b] = cnt ? acc / static_cast<double>(cnt) : 0.0;
      }
      const double l1_model = BiasWhitener(b1, C.noise).neg2_loglik(z1);
      const double log_m1 = std::log(std::max(2.0, static_cast<double>(m1)));
      // bias_instability: sigma and tau free
      {
        double best = l1_model, bs = C.noise.gm_sigma_dps, bt = C.noise.gm_tau_s;
        const double dur = std::max(10.0, out.duration_s);
        for (double tau : {dur / 30, dur / 10, dur / 3, dur, 3 * dur, 10 * dur}) {
          auto f = [&](double ls) {
            ChannelNoise nz = C.noise;
            nz.gm_sigma_dps = std::exp(ls);
            nz.gm_tau_s = tau;
            return BiasWhitener(b1, nz).neg2_loglik(z1);
          };
          const double ls = golden_min(f, std::log(1e-5), std::log(50.0), 30);
          const double v = f(ls);
          if (v < best) { best = v; bs = std::exp(ls); bt = tau; }
        }
        const double g = l1_model - best;
        nr[c][1] = {g - 2 * log_m1, {{fmt::format("s{}.{}.sigma_dps", C.s + 1, kAxis[C.j]), bs, 0.0, "deg/s"},
                                     {fmt::format("s{}.{}.tau_s", C.s + 1, kAxis[C.j]), bt, 0.0, "s"}}, g};
      }
      // rate_random_walk: K free
      {
        auto f = [&](double lk) {
          ChannelNoise nz = C.noise;
          nz.rrw_dps_rts = std::exp(lk);
          return BiasWhitener(b1, nz).neg2_loglik(z1);
        };
        const double lk = golden_min(f, std::log(1e-7), std::log(1.0), 30);
        const double v = std::min(f(lk), l1_model);
        const double g = l1_model - v;
        nr[c][2] = {g - log_m1, {{fmt::format("s{}.{}.k_dps_rts", C.s + 1, kAxis[C.j]), std::exp(lk), 0.0, "deg/s/rts"}}, g};
      }
    }
    const char* names[3] = {"white_noise", "bias_instability", "rate_random_walk"};
    for (int t = 0; t < 3; ++t) {
      Candidate cd;
      cd.effect = names[t];
      cd.kind = "noise";
      std::vector<int> a1, a2;
      double ev = 0, g = 0;
      int best_c = 0;
      for (int c = 0; c < 6; ++c) if (nr[c][t].ev > nr[best_c][t].ev) best_c = c;
      for (int c = 0; c < 6; ++c) {
        if (nr[c][t].ev <= 0 && c != best_c) continue;
        if (nr[c][t].ev <= 0 && nr[best_c][t].ev > 0) continue;
        ev += nr[c][t].ev;
        g += nr[c][t].gain;
        (c < 3 ? a1 : a2).push_back(c % 3);
        for (const auto& fp : nr[c][t].params) cd.params.push_back(fp);
      }
      cd.evidence = ev;
      cd.chi2 = g;
      cd.dof = static_cast<int>(a1.size() + a2.size()) * (t == 1 ? 2 : 1);
      cd.p_value = 1.0 - est::chi2_cdf(std::max(0.0, g), std::max(1, cd.dof));
      cd.sensor = a1.empty() ? "2" : a2.empty() ? "1" : "both";
      cd.axis = a1.empty() ? axes_text(a2) : a2.empty() ? axes_text(a1) : "s1:" + axes_text(a1) + " s2:" + axes_text(a2);
      cands.push_back(cd);
    }
  }

  // ---- constant_bias: the fitted turn-on bias against the model's run-to-run spread ----
  {
    Candidate cd;
    cd.effect = "constant_bias";
    cd.kind = "regression";
    std::vector<int> a1, a2;
    double ev = 0, g = 0;
    struct One { int c; double ev, chi2; };
    std::vector<One> ones;
    for (int c = 0; c < 6; ++c) {
      const SensorParams& p = model.sensor[c / 3];
      const int j = c % 3;
      double var0 = 0.0;
      if (p.constant_bias.enabled) var0 += std::pow(p.constant_bias.sigma_dps[j], 2);
      if (p.bias_instability.enabled) var0 += std::pow(p.bias_instability.sigma_dps[j], 2);
      if (p.rate_random_walk.enabled) var0 += std::pow(p.rate_random_walk.k_dps_rts[j], 2) * out.duration_s;
      const auto& cs = out.channels[c];
      const double chi2 = cs.turn_on_bias_dps * cs.turn_on_bias_dps / (var0 + cs.turn_on_sigma_dps * cs.turn_on_sigma_dps);
      ones.push_back({c, chi2 - log_m, chi2});
    }
    int best_c = 0;
    for (const auto& o : ones) if (o.ev > ones[best_c].ev) best_c = o.c;
    for (const auto& o : ones) {
      if (!(o.ev > 0 || (o.c == best_c && ones[best_c].ev <= 0))) continue;
      ev += o.ev;
      g += o.chi2;
      (o.c < 3 ? a1 : a2).push_back(o.c % 3);
      cd.params.push_back({fmt::format("s{}.{}.value_dps", o.c / 3 + 1, kAxis[o.c % 3]), out.channels[o.c].turn_on_bias_dps,
                           out.channels[o.c].turn_on_sigma_dps, "deg/s"});
    }
    cd.evidence = ev;
    cd.chi2 = g;
    cd.dof = static_cast<int>(a1.size() + a2.size());
    cd.p_value = 1.0 - est::chi2_cdf(g, std::max(1, cd.dof));
    cd.sensor = a1.empty() ? "2" : a2.empty() ? "1" : "both";
    cd.axis = a1.empty() ? axes_text(a2) : a2.empty() ? axes_text(a1) : "s1:" + axes_text(a1) + " s2:" + axes_text(a2);
    cands.push_back(cd);
  }

  // ---- ADC effects: quantisation lattice, saturation plateaus, missing codes ----
  {
    Candidate q, sat, miss;
    q.effect = "quantization"; q.kind = "adc";
    sat.effect = "saturation"; sat.kind = "adc";
    miss.effect = "adc_missing_codes"; miss.kind = "adc";
    std::vector<int> qa1, qa2, sa1, sa2, ma1, ma2;
    double qev = 0, sev = 0, mev = 0;
    q.evidence = sat.evidence = miss.evidence = -log_m;
    for (int c = 0; c < 6; ++c) {
      const int s = c / 3, j = c % 3;
      const SensorParams& p = model.sensor[s];
      std::vector<double> y;
      y.reserve(n);
      for (std::size_t k = 0; k < n; ++k) if (r.usable[k]) y.push_back(r.gyro_dps[s][k][j]);
      const double ny = static_cast<double>(y.size());
      // lattice strength |mean exp(2 pi i y / step)|
      auto lattice = [&](double step) {
        double cr = 0, si = 0;
        for (double v : y) { const double ph = 2.0 * kPi * v / step; cr += std::cos(ph); si += std::sin(ph); }
        return std::hypot(cr, si) / std::max(1.0, ny);
      };
      // candidate LSBs: the model's, common full-scale ranges, and the data's smallest step
      std::vector<double> steps;
      if (p.quantization.enabled) steps.push_back(1.0 / p.quantization.sensitivity_lsb_per_dps);
      for (int fs_sel = 0; fs_sel < 4; ++fs_sel) steps.push_back(1.0 / mpu6050::gyro_lsb_per_dps(fs_sel));
      {
        std::vector<double> u(y.begin(), y.begin() + static_cast<std::ptrdiff_t>(std::min<std::size_t>(y.size(), 20000)));
        std::sort(u.begin(), u.end());
        u.erase(std::unique(u.begin(), u.end(), [](double a, double b) { return std::abs(a - b) < 2e-7; }), u.end());
        std::vector<double> d;
        for (std::size_t i = 1; i < u.size(); ++i) d.push_back(u[i] - u[i - 1]);
        if (d.size() > 10) {
          std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
          steps.push_back(d[d.size() / 2]);
        }
      }
      double best_step = 0.0, best_R = 0.0;
      for (double st : steps) {
        if (!(st > 1e-6)) continue;
        const double R = lattice(st);
        if (R > 0.9 && st > best_step) { best_step = st; best_R = R; }
      }
      const double model_step = p.quantization.enabled ? 1.0 / p.quantization.sensitivity_lsb_per_dps : 0.0;
      const double chi_data = 2.0 * ny * best_R * best_R;
      double ev_q = -log_m;
      if (best_step > 0 && (model_step == 0.0 || std::abs(best_step - model_step) > 1e-3 * model_step)) {
        ev_q = std::min(chi_data, 2.0 * ny) - 2 * log_m;
      } else if (best_step == 0.0 && model_step > 0.0) {
        const double Rm = lattice(model_step);
        // the model quantises but the data lie on no lattice
        ev_q = (Rm < 0.5 ? 2.0 * ny * (1.0 - Rm) * 0.01 : 0.0) - log_m;
      }
      if (ev_q > 0) {
        qev += ev_q;
        (s == 0 ? qa1 : qa2).push_back(j);
        q.params.push_back({fmt::format("s{}.{}.sensitivity_lsb_per_dps", s + 1, kAxis[j]),
                            best_step > 0 ? 1.0 / best_step : 0.0, 0.0, "LSB/(deg/s)"});
      }
      // missing codes: zero counts where neighbours are well populated
      if (best_step > 0) {
        std::map<long, long> hist;
        for (double v : y) hist[std::lround(v / best_step)]++;
        std::vector<long> missing;
        double ev_m = 0.0;
        if (!hist.empty()) {
          const long lo = hist.begin()->first, hi = hist.rbegin()->first;
          if (hi - lo < 200000) {
            for (long code = lo + 2; code <= hi - 2; ++code) {
              if (hist.count(code)) continue;
              auto cnt = [&](long cc) { auto it = hist.find(cc); return it == hist.end() ? 0.0 : static_cast<double>(it->second); };
              // both sides must be well populated (a clipped pile on one side is no evidence)
              const double lam = 0.5 * std::min(cnt(code - 2) + cnt(code - 1), cnt(code + 1) + cnt(code + 2));
              if (lam >= 40.0) { missing.push_back(code); ev_m += 2.0 * lam - log_m - 2.0 * std::log(static_cast<double>(hi - lo + 1)); }
            }
          }
        }
        const bool model_has = p.adc_missing_codes.enabled;
        if (!missing.empty() && ev_m > 0 && !model_has) {
          mev += ev_m;
          (s == 0 ? ma1 : ma2).push_back(j);
          std::string codes;
          for (std::size_t i = 0; i < std::min<std::size_t>(missing.size(), 50); ++i) codes += (i ? " " : "") + std::to_string(missing[i]);
          miss.params.push_back({fmt::format("s{}.{}.missing_codes_count", s + 1, kAxis[j]), static_cast<double>(missing.size()), 0.0, "codes"});
          miss.note += fmt::format("s{}.{}: codes {} ", s + 1, kAxis[j], codes);
          for (long code : missing) miss.fit.push_back({c, static_cast<int>(code), 0.0, 0.0});
        }
      }
      // saturation: repeated extreme outputs where the model predicts beyond them
      {
        double ymax = 0.0;
        for (double v : y) ymax = std::max(ymax, std::abs(v));
        const double tol = std::max(best_step, 1e-6) * 0.51;
        double dj = 0.0;
        std::size_t plateau = 0;
        const double fsm = p.saturation.enabled ? p.saturation.full_scale_dps : kInf;
        for (std::size_t k = 0; k < n; ++k) {
          if (!r.usable[k]) continue;
          const double v = r.gyro_dps[s][k][j], pv = pred[s].gyro_dps[k][j];
          if (std::abs(std::abs(v) - ymax) <= tol && std::abs(pv) > ymax + 5.0 * out.channels[c].noise_floor_dps) {
            ++plateau;
            const double sd = std::max(out.channels[c].noise_floor_dps, 1e-3);
            dj += std::pow((std::abs(pv) - ymax) / sd, 2);
          }
        }
        if (plateau >= 3 && ymax < fsm - 1e-6) {
          const double ev_s = dj - log_m;
          if (ev_s > 0) {
            sev += ev_s;
            (s == 0 ? sa1 : sa2).push_back(j);
            sat.params.push_back({fmt::format("s{}.{}.full_scale_dps", s + 1, kAxis[j]), ymax, best_step, "deg/s"});
          }
        }
      }
    }
    auto finish = [&](Candidate& cd, double ev, const std::vector<int>& a1, const std::vector<int>& a2) {
      if (ev > 0) {
        cd.evidence = ev;
        cd.chi2 = ev;
        cd.dof = static_cast<int>(a1.size() + a2.size());
        cd.p_value = 0.0;
        cd.sensor = a1.empty() ? "2" : a2.empty() ? "1" : "both";
        cd.axis = a1.empty() ? axes_text(a2) : a2.empty() ? axes_text(a1) : "s1:" + axes_text(a1) + " s2:" + axes_text(a2);
      }
      cands.push_back(cd);
    };
    finish(q, qev, qa1, qa2);
    finish(sat, sev, sa1, sa2);
    finish(miss, mev, ma1, ma2);
  }

  // ---- sample_jitter: residual variance growing with the angular acceleration ----
  {
    Candidate cd;
    cd.effect = "sample_jitter";
    cd.kind = "noise";
    std::vector<std::string> used;
    double ev_sum = 0.0;
    for (int s = 0; s < 2; ++s) {
      const SensorParams& p = model.sensor[s];
      const double sj2 = p.sample_jitter.enabled ? p.sample_jitter.sigma_s * p.sample_jitter.sigma_s : 0.0;
      // weighted regression of e^2 - model jitter term on [1, (dw/dt)^2]
      Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
      Eigen::Vector2d bvec = Eigen::Vector2d::Zero();
      for (int j = 0; j < 3; ++j) {
        const double v0 = std::pow(out.channels[s * 3 + j].noise_floor_dps, 2);
        for (std::size_t k = 0; k < n; ++k) {
          if (!mask[k] || !std::isfinite(e[s * 3 + j][k])) continue;
          const double g2 = std::pow(r.dw_radps2[s][k][j] * kDegPerRad, 2);
          const double y = e[s * 3 + j][k] * e[s * 3 + j][k] - sj2 * g2;
          const double var = 2.0 * std::pow(v0 + sj2 * g2, 2) + 1e-30;
          const Eigen::Vector2d x(1.0, g2);
          A += x * x.transpose() / var;
          bvec += x * y / var;
        }
      }
      if (A(1, 1) <= 0) continue;
      const Eigen::Vector2d beta = A.ldlt().solve(bvec);
      const double sd = std::sqrt(std::max(0.0, A.inverse()(1, 1)));
      if (!(sd > 0)) continue;
      const double t = beta[1] / sd;
      const double ev = (t > 0 ? t * t : 0.0) - log_m;
      if (ev > 0 || used.empty()) {
        if (ev > 0) ev_sum += ev;
        else if (cd.params.empty()) ev_sum = ev;
        used.push_back(std::to_string(s + 1));
        const double sig = std::sqrt(std::max(0.0, beta[1] + sj2));
        cd.params.push_back({fmt::format("s{}.sigma_s", s + 1), sig, sig > 0 ? 0.5 * sd / sig : 0.0, "s"});
      }
    }
    if (used.empty()) {
      cd.testable = false;
      cd.note = "no angular acceleration in this log";
    } else {
      cd.evidence = ev_sum;
      cd.sensor = used.size() == 2 ? "both" : used[0];
      cd.axis = "x,y,z";
      cd.dof = static_cast<int>(used.size());
    }
    cands.push_back(cd);
  }

  // ---- regimes ----
  auto add_regime = [&](const std::string& group, const std::string& name, const std::function<bool(std::size_t)>& sel) {
    RegimeSummary rs;
    rs.group = group;
    rs.name = name;
    std::array<double, 6> s1{}, s2{};
    for (std::size_t k = 0; k < n; ++k) {
      if (!r.usable[k] || !sel(k)) continue;
      bool ok = true;
      for (int c = 0; c < 6; ++c) ok = ok && std::isfinite(e[c][k]);
      if (!ok) continue;
      ++rs.samples;
      for (int c = 0; c < 6; ++c) { s1[c] += e[c][k]; s2[c] += e[c][k] * e[c][k]; }
    }
    if (rs.samples == 0) return;
    for (int c = 0; c < 6; ++c) {
      rs.mean_dps[c] = s1[c] / static_cast<double>(rs.samples);
      rs.rms_dps[c] = std::sqrt(s2[c] / static_cast<double>(rs.samples));
    }
    out.regimes.push_back(rs);
  };
  for (int a : {1, -1})
    for (int b : {1, -1})
      add_regime("standstill", fmt::format("plat1 {}, plat2 {}", a > 0 ? "+" : "-", b > 0 ? "+" : "-"),
                 [&, a, b](std::size_t k) { return !r.flipping[k] && r.rest_side[0][k] == a && r.rest_side[1][k] == b; });
  add_regime("flip", "during flips", [&](std::size_t k) { return r.flipping[k] != 0; });
  add_regime("flip", "0-2 s after a flip", [&](std::size_t k) {
    return !r.flipping[k] && (r.since_flip_s[0][k] < 2.0f || r.since_flip_s[1][k] < 2.0f);
  });
  const double we = kEarthRateRadps * kDegPerRad;
  const std::vector<double> rate_edges{0.0, 1.0, 10.0, 30.0, kInf};
  for (std::size_t i = 0; i + 1 < rate_edges.size(); ++i) {
    const double lo = rate_edges[i], hi = rate_edges[i + 1];
    add_regime("base rate", std::isinf(hi) ? fmt::format(">= {:g} deg/s", lo) : fmt::format("{:g}-{:g} deg/s", lo, hi),
               [&, lo, hi](std::size_t k) {
                 const double w = std::max(0.0, r.w_body_radps[k].norm() * kDegPerRad - we);
                 return !r.flipping[k] && w >= lo && w < hi;
               });
  }
  const std::vector<double> acc_edges{0.0, 0.5, 2.0, kInf};
  for (std::size_t i = 0; i + 1 < acc_edges.size(); ++i) {
    const double lo = acc_edges[i], hi = acc_edges[i + 1];
    add_regime("acceleration", std::isinf(hi) ? fmt::format(">= {:g} m/s^2", lo) : fmt::format("{:g}-{:g} m/s^2", lo, hi),
               [&, lo, hi](std::size_t k) {
                 const double a = std::abs(r.f_body_mps2[k].norm() - kStandardGravityMps2);
                 return !r.flipping[k] && a >= lo && a < hi;
               });
  }
  if (r.has_temp && temp_span >= 0.2) {
    std::vector<double> t;
    for (std::size_t k = 0; k < n; k += 7) if (std::isfinite(r.temp_c[0][k])) t.push_back(r.temp_c[0][k]);
    std::sort(t.begin(), t.end());
    if (t.size() > 8) {
      std::vector<double> edges{-kInf};
      for (int qn = 1; qn < 4; ++qn) edges.push_back(t[t.size() * static_cast<std::size_t>(qn) / 4]);
      edges.push_back(kInf);
      for (std::size_t i = 0; i + 1 < edges.size(); ++i) {
        const double lo = edges[i], hi = edges[i + 1];
        add_regime("temperature", fmt::format("temp1 {}..{} degC", std::isinf(lo) ? std::string("min") : fmt::format("{:.2f}", lo),
                                              std::isinf(hi) ? std::string("max") : fmt::format("{:.2f}", hi)),
                   [&, lo, hi](std::size_t k) { return !r.flipping[k] && r.temp_c[0][k] >= lo && r.temp_c[0][k] < hi; });
      }
    }
  }

  // ---- windows ----
  {
    double ws = opt.window_s > 0 ? opt.window_s : std::clamp(out.duration_s / 30.0, 10.0, 300.0);
    const double t0 = r.t_s.front();
    std::size_t k = 0;
    while (k < n) {
      WindowSummary w;
      w.t0_s = r.t_s[k];
      std::array<double, 6> s2{};
      std::size_t cnt = 0;
      while (k < n && r.t_s[k] < w.t0_s + ws) {
        if (mask[k]) {
          bool ok = true;
          for (int c = 0; c < 6; ++c) ok = ok && std::isfinite(e[c][k]);
          if (ok) { for (int c = 0; c < 6; ++c) s2[c] += e[c][k] * e[c][k]; ++cnt; }
        }
        ++k;
      }
      w.t1_s = k < n ? r.t_s[k] : r.t_s.back();
      if (cnt < 10) continue;
      for (int c = 0; c < 6; ++c) {
        w.rms_dps[c] = std::sqrt(s2[c] / static_cast<double>(cnt));
        const double ratio = w.rms_dps[c] / std::max(1e-9, out.channels[c].noise_floor_dps);
        if (ratio > w.worst_ratio) { w.worst_ratio = ratio; w.worst_channel = c; }
      }
      out.windows.push_back(w);
    }
    (void)t0;
    out.worst_windows = out.windows;
    std::sort(out.worst_windows.begin(), out.worst_windows.end(), [](const WindowSummary& a, const WindowSummary& b) { return a.worst_ratio > b.worst_ratio; });
    if (out.worst_windows.size() > static_cast<std::size_t>(opt.worst_windows)) out.worst_windows.resize(static_cast<std::size_t>(opt.worst_windows));
    std::sort(out.worst_windows.begin(), out.worst_windows.end(), [](const WindowSummary& a, const WindowSummary& b) { return a.t0_s < b.t0_s; });
  }

  // ---- correlations of the whitened residual with inputs ----
  {
    struct Sig { std::string name; std::function<double(std::size_t)> f; };
    std::vector<Sig> sigs;
    for (int a = 0; a < 3; ++a)
      sigs.push_back({fmt::format("body rate {}", kAxis[a]), [&, a](std::size_t k) { return r.w_body_radps[k][a]; }});
    for (int a = 0; a < 3; ++a)
      sigs.push_back({fmt::format("|body rate {}|", kAxis[a]), [&, a](std::size_t k) { return std::abs(r.w_body_radps[k][a]); }});
    for (int a = 0; a < 3; ++a)
      sigs.push_back({fmt::format("specific force {}", kAxis[a]), [&, a](std::size_t k) { return r.f_body_mps2[k][a]; }});
    sigs.push_back({"time", [&](std::size_t k) { return r.t_s[k]; }});
    sigs.push_back({"temperature 1", [&](std::size_t k) { return pred[0].temp_c[k]; }});
    sigs.push_back({"temperature 2", [&](std::size_t k) { return pred[1].temp_c[k]; }});
    sigs.push_back({"time since flip 1", [&](std::size_t k) { return std::min(10.0f, r.since_flip_s[0][k]); }});
    sigs.push_back({"time since flip 2", [&](std::size_t k) { return std::min(10.0f, r.since_flip_s[1][k]); }});
    std::vector<double> sb(mb), sw(mb), rw(mb);
    for (const auto& sg : sigs) {
      for (std::size_t k = 0; k < n; ++k) tmp[k] = bmask[k] ? sg.f(k) : 0.0;
      block_means(tmp, bmask, L, sb);
      for (int c = 0; c < 6; ++c) {
        BiasWhitener W(blocks, ch[c].noise);
        W.whiten(sb, sw);
        W.whiten(nuisance_residual(ch[c]), rw);
        double sxy = 0, sxx = 0, syy = 0;
        for (std::size_t b = 0; b < mb; ++b) {
          if (!W.used()[b]) continue;
          sxy += sw[b] * rw[b]; sxx += sw[b] * sw[b]; syy += rw[b] * rw[b];
        }
        if (sxx <= 1e-300 || syy <= 0) continue;
        const double rho = sxy / std::sqrt(sxx * syy);
        const double z = rho * std::sqrt(static_cast<double>(ch[c].m));
        // significant and material: a long log makes a negligible correlation significant
        if (std::abs(z) > opt.correlation_z && rho * rho >= opt.min_effect_fraction) out.correlations.push_back({sg.name, c, rho, z});
      }
    }
    std::sort(out.correlations.begin(), out.correlations.end(), [](const Correlation& a, const Correlation& b) { return std::abs(a.z) > std::abs(b.z); });
  }

  // ---- ranking, after-residuals, verdict ----
  // sample_jitter is judged on the full-rate residual with the systematic part still in it:
  // when a systematic candidate is supported, its excess variance is a symptom, not a cause
  double best_sys = -kInf;
  for (const auto& cd : cands)
    if (cd.testable && cd.kind != "noise") best_sys = std::max(best_sys, cd.evidence);
  const bool sys_first = best_sys > opt.evidence_threshold;
  std::stable_sort(cands.begin(), cands.end(), [&](const Candidate& a, const Candidate& b) {
    if (a.testable != b.testable) return a.testable;
    const bool an = a.effect == "sample_jitter", bn = b.effect == "sample_jitter";
    if (sys_first && an != bn) return bn;
    return a.evidence > b.evidence;
  });
  for (auto& cd : cands) {
    for (int c = 0; c < 6; ++c) cd.rms_after_dps[c] = out.channels[c].rms_dps;
    if (cd.fit.empty() || cd.kind == "adc") continue;
    // subtract the candidate's fitted contribution, then re-smooth the bias of touched channels
    for (int c = 0; c < 6; ++c) {
      bool touched = false;
      for (const auto& f : cd.fit) touched = touched || f.channel == c;
      if (!touched) continue;
      // the candidate's columns at their fitted values, the nuisance re-fitted given them
      const Eigen::VectorXd coef = coefficients_given(ch[c], c, cd);
      std::vector<double> es(n);
      for (std::size_t k = 0; k < n; ++k) {
        double v = e_nuis[c][k];
        for (int i = 0; i < static_cast<int>(ch[c].cols.size()); ++i) {
          const double d = coef[i] - ch[c].beta_null[i];
          if (d != 0.0) v -= column_value(in, c / 3, c % 3, ch[c].cols[i], k) * d;
        }
        es[k] = v;
      }
      std::vector<double> zb(mb);
      block_means(es, bmask, L, zb);
      const std::vector<double> bias = BiasWhitener(blocks, ch[c].noise).smooth(zb);
      double s2 = 0; std::size_t cnt = 0;
      for (std::size_t k = 0; k < n; ++k) {
        if (!mask[k] || !std::isfinite(es[k])) continue;
        const double v = es[k] - bias[k / L];
        s2 += v * v; ++cnt;
      }
      cd.rms_after_dps[c] = cnt ? std::sqrt(s2 / static_cast<double>(cnt)) : 0.0;
    }
  }
  out.ranking = cands;
  const Candidate* best = out.ranking.empty() ? nullptr : &out.ranking.front();
  bool white_ok = true;
  for (const auto& cs : out.channels) white_ok = white_ok && cs.white;
  auto fmt_params = [](const Candidate& cd) {
    std::string s;
    for (std::size_t i = 0; i < std::min<std::size_t>(cd.params.size(), 6); ++i) {
      const auto& p = cd.params[i];
      s += fmt::format("{}{} = {:.4g} ± {:.2g} {}", i ? ", " : "", p.name, p.value, p.sigma, p.unit);
    }
    if (cd.params.size() > 6) s += fmt::format(", ... ({} more)", cd.params.size() - 6);
    return s;
  };
  if (best && best->testable && best->evidence > opt.evidence_threshold) {
    out.verdict = "missing_effect";
    out.statement = fmt::format("missing effect: {} on sensor {} axis {}: {} (evidence {:.1f}, explains {:.1f} % of the residual)",
                                best->effect, best->sensor, best->axis, fmt_params(*best), best->evidence,
                                100.0 * best->explained_fraction);
  } else if (!white_ok || !out.correlations.empty()) {
    out.verdict = "unexplained_structure";
    std::string sig;
    for (std::size_t i = 0; i < std::min<std::size_t>(out.correlations.size(), 4); ++i)
      sig += fmt::format("{}{} on {} (rho {:+.3f})", i ? ", " : "", out.correlations[i].signal,
                         channel_name(out.correlations[i].channel), out.correlations[i].rho);
    std::string bad;
    for (int c = 0; c < 6; ++c)
      if (!out.channels[c].white) bad += (bad.empty() ? "" : ", ") + channel_name(c);
    out.statement = fmt::format("unexplained structure: no candidate effect explains the residual{}{}",
                                bad.empty() ? "" : "; not white on " + bad,
                                sig.empty() ? "" : "; it correlates with " + sig);
  } else {
    out.verdict = "consistent_with_noise";
    out.statement = "consistent with the noise model: the residual is white and no candidate effect is supported by the data";
  }
  return out;
}

void apply_candidate(CompareModel& model, const Candidate& c) {
  if (!c.applicable) {
    throw std::runtime_error(fmt::format(
        "{} cannot be written into the model file: {}", c.effect,
        c.effect == "flip_transient" ? "it is a property of the platform motors (box block), lengthen the settle margin instead"
                                       : "no model key holds it"));
  }
  auto sensor_of = [](const std::string& name) { return name.size() > 2 && name[0] == 's' ? name[1] - '1' : -1; };
  auto axis_of = [](const std::string& name, std::size_t pos) {
    const char ch = name[pos];
    return ch == 'x' ? 0 : ch == 'y' ? 1 : ch == 'z' ? 2 : -1;
  };
  const std::string& e = c.effect;
  if (e == "scale_factor" || e == "misalignment" || e == "g_sensitivity" || e == "temperature" ||
      e == "adc_nonlinearity" || e == "mounting_misalignment") {
    for (const auto& f : c.fit) {
      SensorParams& p = model.sensor[f.channel / 3];
      const int j = f.channel % 3;
      switch (f.column) {
        case kScale:
          p.scale_factor.enabled = true;
          p.scale_factor.value_pct[j] += f.beta;
          p.scale_factor.sigma_pct[j] = 0.0;
          break;
        case kMisA: case kMisB: {
          const int lo = std::min((j + 1) % 3, (j + 2) % 3), hi = std::max((j + 1) % 3, (j + 2) % 3);
          p.misalignment.enabled = true;
          p.misalignment.matrix_pct(j, f.column == kMisA ? lo : hi) += f.beta;
          p.misalignment.sigma_pct = 0.0;
          break;
        }
        case kG0: case kG1: case kG2:
          p.g_sensitivity.enabled = true;
          p.g_sensitivity.matrix_dps_per_g(j, f.column - kG0) += f.beta;
          p.g_sensitivity.sigma_dps_per_g = 0.0;
          break;
        case kTempBias:
          p.temperature.enabled = true;
          p.temperature.bias_tc_dps_per_degc[j] += f.beta;
          p.temperature.bias_tc_sigma_dps_per_degc[j] = 0.0;
          break;
        case kTempScale:
          p.temperature.enabled = true;
          p.temperature.scale_tc_pct_per_degc[j] += f.beta;
          p.temperature.scale_tc_sigma_pct_per_degc[j] = 0.0;
          break;
        case kNonlin2:
          p.adc_nonlinearity.enabled = true;
          p.adc_nonlinearity.quadratic_pct_fs += f.beta / 3.0;  // one coefficient per sensor: mean of axes
          break;
        case kNonlin3:
          p.adc_nonlinearity.enabled = true;
          p.adc_nonlinearity.cubic_pct_fs += f.beta / 3.0;
          break;
        case kMount0: case kMount1: case kMount2: {
          // the rotation is shared by the sensor's three channels (a channel along the rotation
          // axis has no column): set it once per sensor and angle
          bool first = true;
          for (const auto& g : c.fit)
            if (g.channel / 3 == f.channel / 3 && g.column == f.column && g.channel < f.channel) first = false;
          if (first) {
            p.mounting_misalignment.enabled = true;
            p.mounting_misalignment.angles_deg[f.column - kMount0] += f.beta;
            p.mounting_misalignment.sigma_deg[f.column - kMount0] = 0.0;
          }
          break;
        }
        default: break;
      }
    }
    if (e == "adc_nonlinearity") {
      // the nonlinearity is one set of coefficients per sensor: average only over the axes fitted
      for (int s = 0; s < 2; ++s) {
        int axes = 0;
        for (const auto& f : c.fit) axes += f.channel / 3 == s && f.column == kNonlin3;
        if (axes > 0 && axes < 3) {
          SensorParams& p = model.sensor[s];
          double sum3 = 0, sum2 = 0;
          for (const auto& f : c.fit) {
            if (f.channel / 3 != s) continue;
            if (f.column == kNonlin3) sum3 += f.beta;
            if (f.column == kNonlin2) sum2 += f.beta;
          }
          p.adc_nonlinearity.cubic_pct_fs += sum3 / axes - sum3 / 3.0;
          p.adc_nonlinearity.quadratic_pct_fs += sum2 / axes - sum2 / 3.0;
        }
      }
    }
    return;
  }
  if (e == "lowpass_latency") {
    for (int s = 0; s < 2; ++s) {
      double delay = kNaN;
      for (const auto& p : c.params)
        if (sensor_of(p.name) == s && p.name.find("delay_s") != std::string::npos) delay = p.value;
      if (!std::isfinite(delay)) continue;
      SensorParams& p = model.sensor[s];
      const double have = p.lowpass_latency.enabled ? mpu6050::dlpf_setting(p.lowpass_latency.dlpf_cfg).gyro_delay_s : 0.0;
      int best = 0;
      double err = kInf;
      for (int cfg = 0; cfg <= 6; ++cfg) {
        const double d = std::abs(mpu6050::dlpf_setting(cfg).gyro_delay_s - (have + delay));
        if (d < err) { err = d; best = cfg; }
      }
      p.lowpass_latency.enabled = true;
      p.lowpass_latency.dlpf_cfg = best;
    }
    return;
  }
  if (e == "white_noise" || e == "bias_instability" || e == "rate_random_walk" || e == "constant_bias" ||
      e == "quantization" || e == "saturation" || e == "sample_jitter") {
    for (const auto& fp : c.params) {
      const int s = sensor_of(fp.name);
      if (s < 0) continue;
      SensorParams& p = model.sensor[s];
      const int j = axis_of(fp.name, 3);
      if (e == "white_noise" && j >= 0) { p.white_noise.enabled = true; p.white_noise.density_dps_rthz[j] = fp.value; }
      if (e == "bias_instability" && j >= 0) {
        p.bias_instability.enabled = true;
        if (fp.name.find("sigma") != std::string::npos) p.bias_instability.sigma_dps[j] = fp.value;
        if (fp.name.find("tau") != std::string::npos) p.bias_instability.tau_s[j] = fp.value;
      }
      if (e == "rate_random_walk" && j >= 0) { p.rate_random_walk.enabled = true; p.rate_random_walk.k_dps_rts[j] = fp.value; }
      if (e == "constant_bias" && j >= 0) {
        p.constant_bias.enabled = true;
        p.constant_bias.value_dps[j] += fp.value;
        p.constant_bias.sigma_dps[j] = 0.0;
      }
      if (e == "quantization" && fp.value > 0) { p.quantization.enabled = true; p.quantization.sensitivity_lsb_per_dps = fp.value; }
      if (e == "saturation") { p.saturation.enabled = true; p.saturation.full_scale_dps = fp.value; }
      if (e == "sample_jitter") { p.sample_jitter.enabled = true; p.sample_jitter.sigma_s = fp.value; }
    }
    return;
  }
  if (e == "adc_missing_codes") {
    for (const auto& f : c.fit) {
      SensorParams& p = model.sensor[f.channel / 3];
      p.adc_missing_codes.enabled = true;
      p.adc_missing_codes.fraction = 0.0;
      p.adc_missing_codes.codes.push_back(f.column);
    }
    for (auto& p : model.sensor) {
      std::sort(p.adc_missing_codes.codes.begin(), p.adc_missing_codes.codes.end());
      p.adc_missing_codes.codes.erase(std::unique(p.adc_missing_codes.codes.begin(), p.adc_missing_codes.codes.end()),
                                      p.adc_missing_codes.codes.end());
    }
    return;
  }
  if (e == "earth_rate") {
    double d = 0;
    for (const auto& fp : c.params) d = fp.value;
    if (!std::isfinite(model.latitude_deg)) {
      throw std::runtime_error("earth_rate: the model file states no latitude_deg to correct; set latitude_deg (or the log's) by " +
                               fmt::format("{:+.3f} deg", d));
    }
    model.latitude_deg += d;
    return;
  }
  if (e == "end_stop_error") {
    // model.box.stopI_error_deg = [at -stop, at +stop]; one value per sensor and side
    for (int s = 0; s < 2; ++s) {
      Eigen::Vector2d& err = s == 0 ? model.box.stop1_error_deg : model.box.stop2_error_deg;
      for (int col : {kEndMinus, kEndPlus}) {
        for (const auto& f : c.fit) {
          if (f.channel / 3 != s || f.column != col) continue;
          err[col == kEndPlus ? 1 : 0] += f.beta;
          break;  // shared by the sensor's three channels
        }
      }
    }
    return;
  }
  if (e == "time_offset") {
    for (const auto& f : c.fit) {
      if (f.column != kDelay) continue;
      model.time_offset_s += f.beta;
      break;  // shared by all six channels
    }
    if (!(std::abs(model.time_offset_s) <= 1.0)) {
      throw std::runtime_error(fmt::format("time_offset: fitted offset {:.4f} s is outside the model's [-1, 1] s",
                                           model.time_offset_s));
    }
    return;
  }
  throw std::runtime_error(fmt::format("{}: the model's box block (twin-core) holds it; set it by hand: {}", e,
                                       c.params.empty() ? std::string("-") : fmt::format("{} = {:.4g} {}", c.params[0].name, c.params[0].value, c.params[0].unit)));
}

}  // namespace driftless::diagnose
