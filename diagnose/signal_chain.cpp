#include "diagnose/signal_chain.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "diagnose/parallel.hpp"
#include "estimator/sample.hpp"

namespace driftless::diagnose {
namespace {

constexpr double kShapeTolerance = 0.05;  // colour spread allowed for another filter shape
constexpr std::size_t kWindow = 12;       // samples per detrended window

// the projector that takes out a cubic in time from a window of w samples
Eigen::MatrixXd cubic_detrend(std::size_t w) {
  const auto n = static_cast<Eigen::Index>(w);
  Eigen::MatrixXd X(n, 4);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = (static_cast<double>(i) - 0.5 * static_cast<double>(n - 1)) / static_cast<double>(n);
    X(i, 0) = 1.0, X(i, 1) = t, X(i, 2) = t * t, X(i, 3) = t * t * t;
  }
  return Eigen::MatrixXd::Identity(n, n) - X * (X.transpose() * X).ldlt().solve(X.transpose());
}

// expected sum_k C(k, k-1) and trace(C) of C = P Gamma P for a stationary process with
// autocovariance gamma(0..w-1) in windows of w samples, P the cubic detrend
struct WindowMoments {
  double num = 0.0, trace = 0.0;
};
WindowMoments window_moments(const std::vector<double>& gamma, std::size_t w) {
  const auto n = static_cast<Eigen::Index>(w);
  Eigen::MatrixXd G(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j) {
      const auto lag = static_cast<std::size_t>(std::abs(i - j));
      G(i, j) = lag < gamma.size() ? gamma[lag] : 0.0;
    }
  const Eigen::MatrixXd P = cubic_detrend(w);
  const Eigen::MatrixXd C = P * G * P;
  WindowMoments m;
  for (Eigen::Index k = 1; k < n; ++k) m.num += C(k, k - 1);
  m.trace = C.trace();
  return m;
}

// the residual of one channel with its delay signature taken out: OLS of the masked samples on
// [1, -dw/dt, d2w/dt2] (whatever delays the signal - a filter, a late sample, a time offset -
// leaves about that; what remains of it is smooth and goes with the detrending)
std::vector<double> without_delay_signature(const Replay& r, const Residual& res, int c) {
  const int s = c / 3, j = c % 3;
  const std::size_t n = res.n;
  std::vector<double> out(n, kNaN);
  if (n < 3) return out;
  // the regressors at k from d(w_j)/dt at k - 1, k, k + 1, each evaluated once per sample
  // (stored, the two series were 5.8 MB an hour per channel)
  auto sweep = [&](const auto& use) {
    double dm = r.dw_axis_radps2(s, 0, j), d0 = r.dw_axis_radps2(s, 1, j);
    for (std::size_t k = 1; k + 1 < n; ++k) {
      const double dp = r.dw_axis_radps2(s, k + 1, j);
      use(k, -d0 * kDegPerRad, (dp - dm) / (r.t_s[k + 1] - r.t_s[k - 1]) * kDegPerRad);
      dm = d0, d0 = dp;
    }
  };
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  sweep([&](std::size_t k, double d1, double d2) {
    if (!res.mask[k]) return;
    const Eigen::Vector3d x(1.0, d1, d2);
    A += x * x.transpose();
    b += x * res.e_dps(c, k);
  });
  const Eigen::Vector3d beta = A.ldlt().solve(b);
  sweep([&](std::size_t k, double d1, double d2) {
    if (res.mask[k]) out[k] = res.e_dps(c, k) - beta.dot(Eigen::Vector3d(1.0, d1, d2));
  });
  return out;
}

}  // namespace

std::array<NoiseColour, 2> measure_noise_colour(const Replay& r, const Residual& res) {
  std::array<NoiseColour, 2> out;
  const Eigen::MatrixXd P = cubic_detrend(kWindow);
  // the two sensors on the machine's cores, each into its own slot
  for_each_index(2, [&](int s) {
    NoiseColour& nc = out[static_cast<std::size_t>(s)];
    nc.block_len = kWindow;
    double num = 0.0, den = 0.0, pairs = 0.0, count = 0.0;
    for (int j = 0; j < 3; ++j) {
      const std::vector<double> x = without_delay_signature(r, res, s * 3 + j);
      Eigen::VectorXd v(static_cast<Eigen::Index>(kWindow));
      for (std::size_t a = 0; a + kWindow <= res.n; a += kWindow) {
        bool ok = true;
        for (std::size_t k = a; k < a + kWindow && ok; ++k) ok = std::isfinite(x[k]);
        if (!ok) continue;
        for (std::size_t k = 0; k < kWindow; ++k) v[static_cast<Eigen::Index>(k)] = x[a + k];
        const Eigen::VectorXd d = P * v;
        for (Eigen::Index k = 0; k < d.size(); ++k) {
          den += d[k] * d[k];
          if (k > 0) num += d[k] * d[k - 1];
        }
        pairs += static_cast<double>(kWindow - 4);  // independent pairs: the cubic takes 4
        count += static_cast<double>(kWindow);
      }
    }
    if (den <= 0.0) return;
    nc.stat = num / den;
    nc.pairs = pairs;
    nc.mean_square_dps2 = den / count;
  });
  return out;
}

ChainTerms chain_moments(double group_delay_s, double pole_time_s, double extra_delay_s) {
  const double D = group_delay_s, T = pole_time_s, d = extra_delay_s, a = D - T + d;
  return {0.5 * (D * D + T * T) + d * D + 0.5 * d * d, (6.0 * T * T * T + 6.0 * a * T * T + 3.0 * a * a * T + a * a * a) / 6.0};
}

double lowpass_delay_s(const twin::SensorParams& p) {
  return p.lowpass_latency.enabled ? twin::lowpass_setting(p.lowpass_latency).gyro_delay_s : 0.0;
}

twin::SensorParams with_lowpass_delay(twin::SensorParams p, double delay_s) {
  p.lowpass_latency.enabled = delay_s > 0.0;
  if (delay_s > 0.0) {
    p.lowpass_latency.delay_s = delay_s;
    p.lowpass_latency.bandwidth_hz = 0.0;
  }
  return p;
}

double expected_colour(const twin::SensorParams& p, double fs, const NoiseColour& measured) {
  const std::size_t w = measured.block_len;
  const WhiteNoiseShape shape = white_noise_shape(p, fs, static_cast<int>(w));
  const double q = p.quantization.enabled ? 1.0 / p.quantization.sensitivity_lsb_per_dps : 0.0;
  const double var_q = q * q / 12.0;  // quantisation: white, deg/s^2
  std::vector<double> white(w, 0.0);
  white[0] = 1.0;
  const WindowMoments mf = window_moments(shape.rho, w), mw = window_moments(white, w);
  // the filtered noise's variance that gives the measured mean square
  const double ms_total = measured.mean_square_dps2 * static_cast<double>(w);
  const double var_f = mf.trace > 0 ? std::max(0.0, (ms_total - var_q * mw.trace) / mf.trace) : 0.0;
  const double num = var_f * mf.num + var_q * mw.num, trace = var_f * mf.trace + var_q * mw.trace;
  return trace > 0 ? num / trace : 0.0;
}

double colour_penalty(const NoiseColour& measured, double expected) {
  if (!measured.usable()) return 0.0;
  const double var = 1.0 / measured.pairs + kShapeTolerance * kShapeTolerance;
  const double d = measured.stat - expected;
  return d * d / var;
}

}  // namespace driftless::diagnose
