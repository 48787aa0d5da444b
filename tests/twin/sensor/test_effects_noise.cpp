// Statistical signatures of the stochastic effects that need few samples: run-to-run draw spreads,
// accelerometer noise, the Gauss-Markov start. The million-sample Allan / autocovariance checks
// live in slow_test_effects_noise.cpp (skipped in the sanitizer pass).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "estimator/sample.hpp"
#include "twin/sensor/sensor_model.hpp"

using namespace driftless;
using namespace driftless::twin;


TEST(EffectsNoise, GaussMarkovZeroStartStartsAtZero) {
  SensorParams p = ideal_sensor();
  p.bias_instability.enabled = true;
  p.bias_instability.sigma_dps = Eigen::Vector3d::Constant(0.1);
  p.bias_instability.stationary_start = false;
  SensorModel m(p, 100.0, 1);
  EXPECT_EQ(m.step(SensorTruth{}).bias_radps, Eigen::Vector3d::Zero());
  EXPECT_NE(m.step(SensorTruth{}).bias_radps, Eigen::Vector3d::Zero());
}

TEST(EffectsNoise, AccelWhiteNoiseHasItsDensity) {
  SensorParams p = ideal_sensor();
  p.accel_white_noise.enabled = true;
  const double fs = 100.0;
  SensorModel m(p, fs, 9);
  const int n = 100000;
  Eigen::Vector3d s2 = Eigen::Vector3d::Zero();
  for (int k = 0; k < n; ++k) s2 += m.step(SensorTruth{}).accel_mps2.cwiseAbs2();
  const Eigen::Vector3d sd = (s2 / n).cwiseSqrt();
  const Eigen::Vector3d want = p.accel_white_noise.density_mps2_rthz * std::sqrt(fs);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(sd[i], want[i], 0.02 * want[i]);
}

TEST(EffectsNoise, RunToRunDrawsHaveTheirSigmas) {
  // GIVEN 3000 power-ons of the default MPU6050 THEN each draw's spread matches its sigma
  const SensorParams p = mpu6050_defaults();
  const int runs = 3000;
  double b2 = 0, s2 = 0, m2 = 0, g2 = 0, tc2 = 0, mount2 = 0;
  for (int k = 0; k < runs; ++k) {
    const SensorInstance s = draw_sensor_instance(p, 1000 + k);
    b2 += (s.bias_radps * kDegPerRad).squaredNorm();
    s2 += ((s.scale - Eigen::Vector3d::Ones()) * 100.0).squaredNorm();
    m2 += ((s.misalignment - Eigen::Matrix3d::Identity()) * 100.0).squaredNorm();
    g2 += (s.G_radps_per_mps2 * kDegPerRad * kStandardGravityMps2).squaredNorm();
    tc2 += (s.bias_tc_radps_per_degc * kDegPerRad).squaredNorm();
    mount2 += (s.mounting_rotvec_rad * kDegPerRad).squaredNorm();
  }
  // 3 (or 6, 9) components per run: sd of a sample sd is sigma/sqrt(2 n), so 5 % is > 4 sd
  EXPECT_NEAR(std::sqrt(b2 / (3 * runs)), 20.0 / 3.0, 0.05 * 20.0 / 3.0);
  EXPECT_NEAR(std::sqrt(s2 / (3 * runs)), 1.0, 0.05);
  EXPECT_NEAR(std::sqrt(m2 / (6 * runs)), 2.0 / 3.0, 0.05 * 2.0 / 3.0);
  EXPECT_NEAR(std::sqrt(g2 / (9 * runs)), 0.1 / std::sqrt(3.0), 0.05 * 0.1 / std::sqrt(3.0));
  EXPECT_NEAR(std::sqrt(tc2 / (3 * runs)), 20.0 / 125.0 / 3.0, 0.05 * 20.0 / 125.0 / 3.0);
  EXPECT_NEAR(std::sqrt(mount2 / (3 * runs)), 0.2, 0.05 * 0.2);
}


TEST(EffectsNoise, NoiseAliasesWhenTheDlpfIsWiderThanNyquist) {
  // GIVEN DLPF_CFG 0 (256 Hz) at a 100 Hz output: the chip's noise up to 256 Hz folds down,
  // so each sample carries sigma = N sqrt(2 * 256 Hz) and consecutive samples are uncorrelated
  SensorParams p = ideal_sensor();
  p.white_noise.enabled = true;
  p.lowpass_latency.enabled = true;
  p.lowpass_latency.dlpf_cfg = 0;
  const double fs = 100.0;
  SensorModel m(p, fs, 13);
  const int n = 50000;
  std::vector<double> x(n);
  for (int k = 0; k < n; ++k) x[k] = m.step(SensorTruth{k / fs, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()}).gyro_radps[1] * kDegPerRad;
  double s2 = 0, s11 = 0;
  for (int k = 0; k < n; ++k) {
    s2 += x[k] * x[k];
    if (k > 0) s11 += x[k] * x[k - 1];
  }
  const double want = 0.005 * std::sqrt(2.0 * 256.0);
  EXPECT_NEAR(std::sqrt(s2 / n), want, 0.02 * want);
  EXPECT_LT(std::abs(s11 / s2), 4.0 / std::sqrt(n));
  // WHEN the DLPF is narrower than fs/2 (cfg 4, 20 Hz) THEN the noise goes through the filter's
  // pole (not its delay): a first-order autoregression with lag-1 correlation a and per-sample
  // sigma N sqrt(fs (1 - a) / (1 + a))
  p.lowpass_latency.dlpf_cfg = 4;
  SensorModel m4(p, fs, 13);
  s2 = 0, s11 = 0;
  double prev = 0.0;
  for (int k = 0; k < n; ++k) {
    const double v = m4.step(SensorTruth{k / fs, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()}).gyro_radps[1] * kDegPerRad;
    s2 += v * v;
    if (k > 0) s11 += v * prev;
    prev = v;
  }
  const double a = m4.gyro_lowpass().pole;
  EXPECT_NEAR(a, std::exp(-2.0 * kPi * 20.0 / fs), 1e-12);
  const double want4 = 0.005 * std::sqrt(fs * (1 - a) / (1 + a));
  EXPECT_NEAR(std::sqrt(s2 / n), want4, 0.02 * want4);
  EXPECT_NEAR(s11 / s2, a, 4.0 / std::sqrt(n));
  EXPECT_LT(want4, 0.9 * 0.005 * std::sqrt(fs));
}
