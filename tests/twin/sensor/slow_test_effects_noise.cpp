// Statistical signatures of the stochastic effects over millions of samples, seeded, against closed
// forms: white noise (Allan slope -1/2, N), Gauss-Markov (sigma, tau from the autocovariance),
// rate random walk (Allan slope +1/2, K), and the default drift magnitude over hours.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "estimator/allan.hpp"
#include "estimator/allan_fit.hpp"
#include "estimator/sample.hpp"
#include "twin/sensor/sensor_model.hpp"

using namespace driftless;
using namespace driftless::twin;

namespace {

// n samples of one gyro axis (deg/s) of a static sensor
std::vector<std::vector<double>> record_dps(const SensorParams& p, double fs, int n, std::uint64_t seed,
                                            bool bias_only = false) {
  SensorModel m(p, fs, seed);
  std::vector<std::vector<double>> out(3, std::vector<double>(static_cast<std::size_t>(n)));
  SensorTruth tr;
  for (int k = 0; k < n; ++k) {
    tr.t_s = k / fs;
    const SensorReading r = m.step(tr);
    for (int i = 0; i < 3; ++i)
      out[i][static_cast<std::size_t>(k)] = (bias_only ? r.bias_radps[i] : r.gyro_radps[i]) * kDegPerRad;
  }
  return out;
}

// least-squares slope of log(adev) against log(tau) over [tau_lo, tau_hi]
double loglog_slope(const est::AllanCurve& c, double tau_lo, double tau_hi) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (const auto& pt : c.points) {
    if (pt.tau_s < tau_lo || pt.tau_s > tau_hi) continue;
    const double x = std::log(pt.tau_s), y = std::log(pt.adev);
    sx += x, sy += y, sxx += x * x, sxy += x * y, ++n;
  }
  EXPECT_GE(n, 4);
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

est::AllanCurve adev(const std::vector<double>& x, double fs) {
  est::AllanOptions o;
  o.sample_rate_hz = fs;
  return est::allan_deviation(x, o);
}

}  // namespace

TEST(EffectsNoiseLong, WhiteNoiseHasAllanSlopeMinusHalfAndItsDensity) {
  // GIVEN white noise only, N = (0.004, 0.005, 0.007) deg/s/rtHz at 100 Hz, one hour
  SensorParams p = ideal_sensor();
  p.white_noise.enabled = true;
  p.white_noise.density_dps_rthz = {0.004, 0.005, 0.007};
  const double fs = 100.0;
  const auto x = record_dps(p, fs, 360000, 21);
  for (int i = 0; i < 3; ++i) {
    const est::AllanCurve c = adev(x[i], fs);
    // THEN slope -1/2 and N read on the line at tau = 1 s within 5 %
    EXPECT_NEAR(loglog_slope(c, 0.01, 100.0), -0.5, 0.03) << i;
    const est::NoiseFit fit = est::fit_noise_parameters(c);
    ASSERT_TRUE(fit.N.valid) << fit.N.note;
    EXPECT_NEAR(fit.N.value, p.white_noise.density_dps_rthz[i], 0.05 * p.white_noise.density_dps_rthz[i]) << i;
  }
}

TEST(EffectsNoiseLong, DefaultChainKeepsTheNoiseDensityAtLongTau) {
  // GIVEN the default MPU6050 with the slow bias processes off (DLPF, quantisation on):
  // the DLPF has DC gain 1, so beyond its time constant the -1/2 line still reads N
  SensorParams p = mpu6050_defaults();
  p.bias_instability.enabled = false;
  p.rate_random_walk.enabled = false;
  p.temperature.enabled = false;
  const double fs = 100.0;
  const auto x = record_dps(p, fs, 360000, 4);
  for (int i = 0; i < 3; ++i) {
    const est::AllanCurve c = adev(x[i], fs);
    double sum = 0;
    int n = 0;
    for (const auto& pt : c.points)
      if (pt.tau_s >= 0.1 && pt.tau_s <= 30.0) sum += pt.adev * std::sqrt(pt.tau_s), ++n;
    EXPECT_NEAR(sum / n, 0.005, 0.05 * 0.005) << i;
  }
}

TEST(EffectsNoiseLong, GaussMarkovRecoversSigmaAndTau) {
  // GIVEN a Gauss-Markov bias with sigma = (0.1, 0.05, 0.2) deg/s and tau = (0.2, 0.1, 0.4) s at
  // 100 Hz over 10^4 s: the estimates' sd is ~1 % (Bartlett), so 3 % / 5 % are > 3 sd
  SensorParams p = ideal_sensor();
  p.bias_instability.enabled = true;
  p.bias_instability.sigma_dps = {0.1, 0.05, 0.2};
  p.bias_instability.tau_s = {0.2, 0.1, 0.4};
  const double fs = 100.0;
  const int n = 1000000;
  const auto x = record_dps(p, fs, n, 77, /*bias_only=*/true);
  for (int i = 0; i < 3; ++i) {
    const auto& b = x[i];
    double mean = 0;
    for (double v : b) mean += v;
    mean /= n;
    auto acov = [&](int lag) {
      double s = 0;
      for (int k = 0; k + lag < n; ++k) s += (b[k] - mean) * (b[k + lag] - mean);
      return s / (n - lag);
    };
    // THEN sigma^2 is the lag-0 autocovariance (within 3 % in sigma)
    const double c0 = acov(0);
    EXPECT_NEAR(std::sqrt(c0), p.bias_instability.sigma_dps[i], 0.03 * p.bias_instability.sigma_dps[i]) << i;
    // and the normalised autocovariance crosses e^-1 at tau (within 5 %)
    const int max_lag = static_cast<int>(3.0 * p.bias_instability.tau_s[i] * fs);
    double prev = 1.0, tau_hat = -1.0;
    for (int lag = 1; lag <= max_lag; ++lag) {
      const double r = acov(lag) / c0;
      if (r < std::exp(-1.0)) {
        tau_hat = (lag - 1 + (prev - std::exp(-1.0)) / (prev - r)) / fs;
        break;
      }
      prev = r;
    }
    EXPECT_NEAR(tau_hat, p.bias_instability.tau_s[i], 0.05 * p.bias_instability.tau_s[i]) << i;
  }
}

TEST(EffectsNoiseLong, RateRandomWalkHasAllanSlopePlusHalfAndItsK) {
  // GIVEN a rate random walk K = (1e-3, 2e-3, 5e-4) deg/s/rts at 10 Hz for ~28 h
  SensorParams p = ideal_sensor();
  p.rate_random_walk.enabled = true;
  p.rate_random_walk.k_dps_rts = {1e-3, 2e-3, 5e-4};
  const double fs = 10.0;
  const auto x = record_dps(p, fs, 1000000, 5);
  for (int i = 0; i < 3; ++i) {
    const est::AllanCurve c = adev(x[i], fs);
    // THEN slope +1/2 and K read on the line at tau = 3 s within 10 %
    EXPECT_NEAR(loglog_slope(c, 2.0, 3000.0), 0.5, 0.05) << i;
    const est::NoiseFit fit = est::fit_noise_parameters(c);
    ASSERT_TRUE(fit.K.valid) << fit.K.note;
    EXPECT_NEAR(fit.K.value, p.rate_random_walk.k_dps_rts[i], 0.10 * p.rate_random_walk.k_dps_rts[i]) << i;
  }
}

TEST(EffectsNoiseLong, DefaultBiasDriftsByHundredsOfDegPerHourOverHours) {
  // GIVEN the default slow bias processes (Gauss-Markov + rate random walk), sampled at 1 Hz
  // (both are discretised exactly, so the rate does not matter for their statistics)
  SensorParams p = ideal_sensor();
  p.bias_instability.enabled = true;
  p.rate_random_walk.enabled = true;
  const SensorParams d = mpu6050_defaults();
  const double sigma = d.bias_instability.sigma_dps[0], tau = d.bias_instability.tau_s[0];
  const double K = d.rate_random_walk.k_dps_rts[0];
  const double dt = 4.0 * 3600.0;
  // THEN the 4 h change has sd sqrt(2 sigma^2 (1 - e^{-dt/tau}) + K^2 dt) (within 6 %)
  const double want = std::sqrt(2 * sigma * sigma * (1 - std::exp(-dt / tau)) + K * K * dt);
  EXPECT_GT(want * 3600.0, 300.0);  // deg/h: "almost 1000 deg/h after several hours" (Fig. 1)
  double s2 = 0;
  const int runs = 200;
  for (int r = 0; r < runs; ++r) {
    SensorModel m(p, 1.0, 500 + r);
    SensorTruth tr;
    const Eigen::Vector3d b0 = m.step(tr).bias_radps;
    Eigen::Vector3d b = b0;
    for (int k = 1; k <= static_cast<int>(dt); ++k) {
      tr.t_s = k;
      b = m.step(tr).bias_radps;
    }
    s2 += ((b - b0) * kDegPerRad).squaredNorm();
  }
  EXPECT_NEAR(std::sqrt(s2 / (3 * runs)), want, 0.06 * want);
}
