// Sensor model: deterministic signatures of each effect, the inverse, determinism, sub-streams.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <filesystem>
#include <fstream>
#include <set>
#include <vector>

#include <unistd.h>

#include <Eigen/Geometry>

#include "estimator/sample.hpp"
#include "twin/sensor/sensor_model.hpp"

using namespace driftless;
using namespace driftless::twin;

namespace {

constexpr double kFs = 100.0;

SensorTruth truth_at(double t, const Eigen::Vector3d& w, const Eigen::Vector3d& f = {0, 0, 9.81}) {
  return SensorTruth{t, w, f};
}

// deg/s -> rad/s
Eigen::Vector3d dps(double x, double y, double z) { return Eigen::Vector3d(x, y, z) * kRadPerDeg; }

}  // namespace

TEST(SensorModel, IdealSensorOutputsTheTruthExactly) {
  SensorModel m(ideal_sensor(), kFs, 1);
  for (int k = 0; k < 100; ++k) {
    const Eigen::Vector3d w(0.1 * k, -0.02, 3.0);
    const Eigen::Vector3d f(0.5, -9.7, 1.0 * k);
    const SensorReading r = m.step(truth_at(k / kFs, w, f));
    EXPECT_EQ(r.gyro_radps, w);
    EXPECT_EQ(r.accel_mps2, f);
    EXPECT_EQ(r.bias_radps, Eigen::Vector3d::Zero());
    EXPECT_EQ(r.temp_c, 25.0);
  }
}

TEST(SensorModel, ScaleMisalignmentGSensitivityMountingAreExact) {
  // GIVEN fixed scale, misalignment, g-sensitivity, mounting and constant bias (no draws)
  SensorParams p = ideal_sensor();
  p.scale_factor.enabled = true;
  p.scale_factor.value_pct = {1.0, -2.0, 0.5};
  p.scale_factor.sigma_pct.setZero();  // enabling keeps the MPU6050 draws; fix them to 0 here
  p.misalignment.enabled = true;
  p.misalignment.sigma_pct = 0.0;
  p.g_sensitivity.sigma_dps_per_g = 0.0;
  p.mounting_misalignment.sigma_deg.setZero();
  p.constant_bias.sigma_dps.setZero();
  p.misalignment.matrix_pct << 0, 0.5, -1.0, 2.0, 0, 0.25, -0.75, 1.5, 0;
  p.g_sensitivity.enabled = true;
  p.g_sensitivity.matrix_dps_per_g << 0.1, 0.02, 0, 0, -0.1, 0.03, 0.01, 0, 0.05;
  p.mounting_misalignment.enabled = true;
  p.mounting_misalignment.angles_deg = {0.0, 0.0, 30.0};
  p.constant_bias.enabled = true;
  p.constant_bias.value_dps = {0.5, -1.0, 2.0};
  SensorModel m(p, kFs, 99);
  // WHEN the sensor sees rate w and specific force f
  const Eigen::Vector3d w = dps(10.0, -20.0, 5.0);
  const Eigen::Vector3d f(1.0, -2.0, 9.0);
  const SensorReading r = m.step(truth_at(0.0, w, f));
  // THEN y = (I + M) diag(1 + s) R w + G R f + b, with R = Rz(30 deg)^T
  const Eigen::Matrix3d R = Eigen::AngleAxisd(30.0 * kRadPerDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix().transpose();
  const Eigen::Matrix3d C = (Eigen::Matrix3d::Identity() + p.misalignment.matrix_pct / 100.0) *
                            (Eigen::Vector3d::Ones() + p.scale_factor.value_pct / 100.0).asDiagonal();
  const Eigen::Matrix3d G = p.g_sensitivity.matrix_dps_per_g * (kRadPerDeg / kStandardGravityMps2);
  const Eigen::Vector3d want = C * R * w + G * R * f + p.constant_bias.value_dps * kRadPerDeg;
  EXPECT_LT((r.gyro_radps - want).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LT((r.bias_radps - p.constant_bias.value_dps * kRadPerDeg).norm(), 1e-16);
  // a 30 deg mounting yaw turns x into (cos30, -sin30) on the sensor axes
  SensorParams q = ideal_sensor();
  q.mounting_misalignment = p.mounting_misalignment;
  SensorModel mq(q, kFs, 1);
  const SensorReading rq = mq.step(truth_at(0.0, Eigen::Vector3d::UnitX()));
  EXPECT_NEAR(rq.gyro_radps[0], std::cos(30.0 * kRadPerDeg), 1e-15);
  EXPECT_NEAR(rq.gyro_radps[1], -std::sin(30.0 * kRadPerDeg), 1e-15);
  EXPECT_NEAR(rq.gyro_radps[2], 0.0, 1e-15);
}

TEST(SensorModel, DeterministicChainInvertsExactly) {
  // GIVEN the default MPU6050 with its random run-to-run draws
  const SensorParams p = mpu6050_defaults();
  const SensorInstance inst = draw_sensor_instance(p, 2024);
  EXPECT_GT((inst.misalignment - Eigen::Matrix3d::Identity()).norm(), 0.0);
  for (int k = 0; k < 50; ++k) {
    const Eigen::Vector3d w = dps(50.0 * std::sin(k), 30.0 * std::cos(3 * k), -40.0 + k);
    const Eigen::Vector3d f(0.3 * k, -9.0, 2.0);
    const double temp = 20.0 + 0.5 * k;
    // WHEN the deterministic output is inverted THEN the truth comes back
    const Eigen::Vector3d y = gyro_deterministic_radps(p, inst, w, f, temp);
    EXPECT_LT((gyro_invert_radps(p, inst, y, f, temp) - w).norm(), 1e-14 * (1.0 + w.norm()));
    const Eigen::Vector3d a = accel_deterministic_mps2(p, inst, f);
    EXPECT_LT((accel_invert_mps2(p, inst, a) - f).norm(), 1e-13);
  }
}

TEST(SensorModel, RealisedParamsReproduceTheDraws) {
  const SensorParams p = mpu6050_defaults();
  SensorModel m(p, kFs, 7);
  const SensorParams fixed = m.realised();
  EXPECT_NO_THROW(fixed.validate());
  EXPECT_EQ(fixed.constant_bias.sigma_dps, Eigen::Vector3d::Zero());
  // any seed gives the same instance once every run-to-run sigma is 0
  const SensorInstance a = draw_sensor_instance(fixed, 1);
  const SensorInstance b = m.instance();
  EXPECT_LT((a.bias_radps - b.bias_radps).norm(), 1e-17);
  EXPECT_LT((a.misalignment - b.misalignment).norm(), 1e-15);
  EXPECT_LT((a.scale - b.scale).norm(), 1e-15);
  EXPECT_LT((a.G_radps_per_mps2 - b.G_radps_per_mps2).norm(), 1e-17);
  EXPECT_LT((a.R_sensor_from_nominal - b.R_sensor_from_nominal).norm(), 1e-15);
  EXPECT_LT((a.bias_tc_radps_per_degc - b.bias_tc_radps_per_degc).norm(), 1e-18);
  EXPECT_LT((a.accel_bias_mps2 - b.accel_bias_mps2).norm(), 1e-15);
}

TEST(SensorModel, QuantizationLandsOnTheLsbGrid) {
  SensorParams p = ideal_sensor();
  p.quantization.enabled = true;
  SensorModel m(p, kFs, 1);
  for (int k = 0; k < 2000; ++k) {
    const double in_dps = -100.0 + 0.1003 * k;
    const SensorReading r = m.step(truth_at(k / kFs, dps(in_dps, 0.0037 * k, 1e-4)));
    const double code = r.gyro_radps[0] * kDegPerRad * 131.0;
    EXPECT_NEAR(code, std::round(code), 1e-9);
    EXPECT_EQ(std::round(code), std::nearbyint(in_dps * 131.0));
    EXPECT_LE(std::abs(r.gyro_radps[0] * kDegPerRad - in_dps), 0.5 / 131.0 + 1e-12);
    EXPECT_EQ(r.gyro_radps[2], 0.0);  // 1e-4 deg/s is below half an LSB
  }
}

TEST(SensorModel, SaturationClipsAtFullScale) {
  SensorParams p = ideal_sensor();
  p.saturation.enabled = true;
  p.quantization.enabled = true;
  p.accel_quantization.enabled = true;
  SensorModel m(p, kFs, 1);
  const SensorReading r = m.step(truth_at(0.0, dps(300.0, -1000.0, 249.0), {30.0, -30.0, 9.0}));
  EXPECT_DOUBLE_EQ(r.gyro_radps[0] * kDegPerRad, 250.0);
  EXPECT_DOUBLE_EQ(r.gyro_radps[1] * kDegPerRad, -250.0);
  EXPECT_NEAR(r.gyro_radps[2] * kDegPerRad, 249.0, 0.5 / 131.0);
  // +2 g is code 32768, one past the register: the MPU6050 tops out at 32767
  EXPECT_NEAR(r.accel_mps2[0], 32767.0 / 16384.0 * kStandardGravityMps2, 1e-12);
  EXPECT_NEAR(r.accel_mps2[1], -2.0 * kStandardGravityMps2, 1e-12);
  EXPECT_NEAR(r.accel_mps2[2], 9.0, 0.5 * kStandardGravityMps2 / 16384.0);
}

TEST(SensorModel, MissingCodesNeverAppear) {
  // GIVEN 5 % missing codes plus an explicit list, and white noise so many codes are visited
  SensorParams p = ideal_sensor();
  p.quantization.enabled = true;
  p.adc_missing_codes.enabled = true;
  p.adc_missing_codes.fraction = 0.05;
  p.adc_missing_codes.codes = {0, 1, 2, -7};
  p.white_noise.enabled = true;
  p.white_noise.density_dps_rthz = Eigen::Vector3d::Constant(0.05);
  SensorModel m(p, kFs, 3);
  const std::set<int> missing(m.instance().missing_codes.begin(), m.instance().missing_codes.end());
  EXPECT_GT(missing.size(), 3000u);
  EXPECT_TRUE(missing.count(1) && missing.count(-7));
  std::set<int> seen;
  for (int k = 0; k < 20000; ++k) {
    const double ramp_dps = -2.0 + 4.0 * k / 20000.0;
    const SensorReading r = m.step(truth_at(k / kFs, dps(ramp_dps, 0.0, 0.0)));
    for (int i = 0; i < 3; ++i) {
      const double code = r.gyro_radps[i] * kDegPerRad * 131.0;
      ASSERT_NEAR(code, std::round(code), 1e-9);
      seen.insert(static_cast<int>(std::round(code)));
    }
  }
  // THEN no missing code is ever output, while the present ones in range are
  int present_in_range = 0, seen_present = 0;
  for (int c = -250; c <= 250; ++c) {
    EXPECT_FALSE(missing.count(c) && seen.count(c)) << "missing code " << c << " was output";
    if (!missing.count(c)) {
      ++present_in_range;
      seen_present += seen.count(c) ? 1 : 0;
    }
  }
  EXPECT_EQ(seen_present, present_in_range);
}

TEST(SensorModel, NonlinearityFollowsItsPolynomial) {
  SensorParams p = ideal_sensor();
  p.saturation.enabled = true;
  p.adc_nonlinearity.enabled = true;
  p.adc_nonlinearity.quadratic_pct_fs = 0.1;
  p.adc_nonlinearity.cubic_pct_fs = -0.2;
  SensorModel m(p, kFs, 1);
  for (double in : {-200.0, -50.0, 0.0, 10.0, 125.0, 240.0}) {
    const double u = in / 250.0;
    const double want = in + 250.0 * (0.1 * u * u - 0.2 * u * u * u) / 100.0;
    EXPECT_NEAR(m.step(truth_at(0.0, dps(in, 0, 0))).gyro_radps[0] * kDegPerRad, want, 1e-12);
  }
}

TEST(SensorModel, DlpfGroupDelayMatchesTheDatasheet) {
  // a ramp through any unit-DC-gain LTI filter lags by exactly its DC group delay
  for (double fs : {100.0, 200.0, 1000.0}) {
    for (int cfg = 0; cfg <= 6; ++cfg) {
      SensorParams p = ideal_sensor();
      p.lowpass_latency.enabled = true;
      p.lowpass_latency.dlpf_cfg = cfg;
      SensorModel m(p, fs, 1);
      const DlpfSetting d = mpu6050::dlpf_setting(cfg);
      EXPECT_NEAR(m.gyro_lowpass().dc_group_delay_s(fs), d.gyro_delay_s, 1e-15);
      EXPECT_NEAR(m.accel_lowpass().dc_group_delay_s(fs), d.accel_delay_s, 1e-15);
      const double slope = 0.5;  // rad/s per s
      const int n = static_cast<int>(5.0 * fs);
      SensorReading r;
      for (int k = 0; k <= n; ++k) {
        const double t = k / fs;
        r = m.step(truth_at(t, Eigen::Vector3d::Constant(slope * t), Eigen::Vector3d::Constant(slope * t)));
      }
      const double t_end = n / fs;
      EXPECT_NEAR(r.gyro_radps[0], slope * (t_end - d.gyro_delay_s), 1e-10) << "cfg " << cfg << " fs " << fs;
      EXPECT_NEAR(r.accel_mps2[0], slope * (t_end - d.accel_delay_s), 1e-10) << "cfg " << cfg << " fs " << fs;
    }
  }
  // a filter that carries the delay in its pole has unit DC gain and the stated delay
  const LowpassDesign d = design_lowpass(5.0, 18.6e-3, 100.0);
  EXPECT_GT(d.pole, 0.0);
  EXPECT_NEAR(d.dc_group_delay_s(100.0), 18.6e-3, 1e-15);
}

TEST(SensorModel, ContinuousDlpfDelayFollowsTheDatasheetRelation) {
  // GIVEN the datasheet rows: a continuous delay equal to a row's gives that row's bandwidth
  for (int cfg = 0; cfg <= 6; ++cfg) {
    const DlpfSetting d = mpu6050::dlpf_setting(cfg);
    EXPECT_NEAR(mpu6050_gyro_bandwidth_for_delay_hz(d.gyro_delay_s), d.gyro_bandwidth_hz, 1e-9 * d.gyro_bandwidth_hz);
  }
  // between rows the bandwidth falls monotonically, and halfway in log delay it is the
  // geometric mean of the rows' bandwidths (log-log interpolation)
  double last = 1e9;
  for (double delay_ms = 0.2; delay_ms < 40.0; delay_ms *= 1.1) {
    const double bw = mpu6050_gyro_bandwidth_for_delay_hz(delay_ms * 1e-3);
    EXPECT_LT(bw, last) << delay_ms;
    last = bw;
  }
  const DlpfSetting a = mpu6050::dlpf_setting(3), b = mpu6050::dlpf_setting(4);
  EXPECT_NEAR(mpu6050_gyro_bandwidth_for_delay_hz(std::sqrt(a.gyro_delay_s * b.gyro_delay_s)),
              std::sqrt(a.gyro_bandwidth_hz * b.gyro_bandwidth_hz), 1e-9);
  // WHEN the model runs a continuous delay (no matching row) on a ramp
  for (double fs : {50.0, 100.0, 200.0}) {
    for (double delay_s : {0.0004, 0.0061, 0.0125, 0.031}) {
      SensorParams p = ideal_sensor();
      p.lowpass_latency.enabled = true;
      p.lowpass_latency.delay_s = delay_s;
      SensorModel m(p, fs, 1);
      const double slope = 0.5;
      const int n = static_cast<int>(5.0 * fs);
      SensorReading r;
      for (int k = 0; k <= n; ++k) {
        const double t = k / fs;
        r = m.step(truth_at(t, Eigen::Vector3d::Constant(slope * t), Eigen::Vector3d::Constant(slope * t)));
      }
      // THEN gyro and accelerometer lag by exactly that delay
      EXPECT_NEAR(r.gyro_radps[0], slope * (n / fs - delay_s), 1e-10) << delay_s << " at " << fs;
      EXPECT_NEAR(r.accel_mps2[0], slope * (n / fs - delay_s), 1e-10) << delay_s << " at " << fs;
    }
  }
  // AND a given bandwidth sets the pole by impulse invariance
  SensorParams p = ideal_sensor();
  p.lowpass_latency.enabled = true;
  p.lowpass_latency.delay_s = 0.02;
  p.lowpass_latency.bandwidth_hz = 10.0;
  EXPECT_NEAR(SensorModel(p, 100.0, 1).gyro_lowpass().pole, std::exp(-2.0 * kPi * 10.0 / 100.0), 1e-15);
}

TEST(SensorModel, SampleDelayShiftsTheTruthOnly) {
  // GIVEN sensor samples 15 ms after the time stamp (1.5 samples at 100 Hz) and the DLPF's 4.8 ms
  SensorParams p = ideal_sensor();
  p.sample_delay.enabled = true;
  p.sample_delay.delay_s = 0.015;
  SensorModel m(p, kFs, 1);
  SensorParams q = p;
  q.lowpass_latency.enabled = true;
  q.lowpass_latency.dlpf_cfg = 3;
  SensorModel mq(q, kFs, 1);
  // WHEN a ramp is sampled
  const double slope = 0.3;
  SensorReading r, rq;
  for (int k = 0; k <= 300; ++k) {
    const double t = k / kFs;
    r = m.step(truth_at(t, Eigen::Vector3d::Constant(slope * t), Eigen::Vector3d::Constant(slope * t)));
    rq = mq.step(truth_at(t, Eigen::Vector3d::Constant(slope * t), Eigen::Vector3d::Constant(slope * t)));
  }
  // THEN the output is the truth of 15 ms ago (gyro and accelerometer), and the delays add
  EXPECT_NEAR(r.gyro_radps[2], slope * (3.0 - 0.015), 1e-12);
  EXPECT_NEAR(r.accel_mps2[1], slope * (3.0 - 0.015), 1e-12);
  EXPECT_NEAR(rq.gyro_radps[0], slope * (3.0 - 0.015 - mpu6050::dlpf_setting(3).gyro_delay_s), 1e-10);
  // AND a constant input is untouched from the first sample on (the delay line starts full)
  SensorModel c(p, kFs, 1);
  EXPECT_NEAR(c.step(truth_at(0.0, dps(3, 2, 1))).gyro_radps[1], 2.0 * kRadPerDeg, 1e-15);
}

TEST(SensorModel, DlpfMagnitudeFollowsItsDesign) {
  // GIVEN cfg 6 (5 Hz, 18.6 ms) at 1 kHz: the pole carries the whole delay (first order,
  // a = D/(1+D) with D = 18.6 samples), so |H(f)| = (1-a) / |1 - a e^{-j 2 pi f / fs}|
  const double fs = 1000.0;
  const LowpassDesign d = design_lowpass(5.0, 18.6e-3, fs);
  EXPECT_NEAR(d.pole, 18.6 / 19.6, 1e-15);
  EXPECT_EQ(d.delay_whole_samples, 0);
  auto amplitude = [fs](double f_hz) {
    SensorParams p = ideal_sensor();
    p.lowpass_latency.enabled = true;
    p.lowpass_latency.dlpf_cfg = 6;
    SensorModel m(p, fs, 1);
    double peak = 0.0;
    for (int k = 0; k < 20000; ++k) {
      const double t = k / fs;
      const double y = m.step(truth_at(t, Eigen::Vector3d::Constant(std::sin(2 * kPi * f_hz * t)))).gyro_radps[0];
      if (k > 10000) peak = std::max(peak, std::abs(y));
    }
    return peak;
  };
  for (double f_hz : {0.5, 5.0, 40.0}) {
    const double w = 2 * kPi * f_hz / fs;
    const double want = (1 - d.pole) / std::abs(1.0 - d.pole * std::polar(1.0, -w));
    EXPECT_NEAR(amplitude(f_hz), want, 2e-3 * want) << f_hz;
  }
  EXPECT_LT(amplitude(40.0), 0.25);
}

TEST(SensorModel, TemperatureCoefficientsAct) {
  // GIVEN warm-up of 10 degC with tau 100 s and fixed bias and scale tempcos
  SensorParams p = ideal_sensor();
  p.temperature.enabled = true;
  p.temperature.ambient_degc = 20.0;
  p.temperature.warmup_rise_degc = 10.0;
  p.temperature.warmup_tau_s = 100.0;
  p.temperature.reference_degc = 25.0;
  p.temperature.bias_tc_dps_per_degc = {0.1, -0.2, 0.05};
  p.temperature.scale_tc_pct_per_degc = {0.01, 0.0, -0.02};
  p.temperature.bias_tc_sigma_dps_per_degc.setZero();
  p.temperature.scale_tc_sigma_pct_per_degc.setZero();
  SensorModel m(p, kFs, 1);
  const Eigen::Vector3d w = dps(100.0, 0.0, 50.0);
  for (double t : {0.0, 50.0, 100.0, 1000.0}) {
    const SensorReading r = m.step(truth_at(t, w));
    const double T = 20.0 + 10.0 * (1.0 - std::exp(-t / 100.0));
    const double dT = T - 25.0;
    const Eigen::Vector3d b = p.temperature.bias_tc_dps_per_degc * dT * kRadPerDeg;
    const Eigen::Vector3d k = Eigen::Vector3d::Ones() + p.temperature.scale_tc_pct_per_degc * dT / 100.0;
    EXPECT_LT((r.gyro_radps - (k.cwiseProduct(w) + b)).norm(), 1e-14) << t;
    EXPECT_LT((r.bias_radps - b).norm(), 1e-16) << t;
    // the temperature register reads T on its 1/340 degC grid
    EXPECT_NEAR(r.temp_c, T, 0.5 / 340.0 + 1e-12);
    const double code = (r.temp_c - 36.53) * 340.0;
    EXPECT_NEAR(code, std::round(code), 1e-6);
  }
}

TEST(SensorModel, TemperatureProfileIsInterpolated) {
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("temperature_profile_test-" + std::to_string(::getpid()) + ".csv");
  {
    std::ofstream out(file);
    out << "t_s,temp_degc\n0,20\n100,30\n# comment\n200,30\n";
  }
  TemperatureParams p;
  p.profile_file = file.string();
  const TemperatureModel t(p);
  EXPECT_DOUBLE_EQ(t.at(-5.0), 20.0);
  EXPECT_DOUBLE_EQ(t.at(25.0), 22.5);
  EXPECT_DOUBLE_EQ(t.at(150.0), 30.0);
  EXPECT_DOUBLE_EQ(t.at(1e6), 30.0);
  p.profile_file = file.string() + ".absent";
  EXPECT_THROW(TemperatureModel{p}, std::runtime_error);
}

TEST(SensorModel, SameSeedIsBitIdenticalOtherSeedDiffers) {
  const SensorParams p = mpu6050_defaults();
  SensorModel a(p, kFs, 42), b(p, kFs, 42), c(p, kFs, 43);
  bool differs = false;
  for (int k = 0; k < 5000; ++k) {
    const SensorTruth tr = truth_at(k / kFs, dps(std::sin(0.01 * k), 0.0, 1.0));
    const SensorReading ra = a.step(tr), rb = b.step(tr), rc = c.step(tr);
    ASSERT_EQ(ra.gyro_radps, rb.gyro_radps);
    ASSERT_EQ(ra.accel_mps2, rb.accel_mps2);
    ASSERT_EQ(ra.bias_radps, rb.bias_radps);
    ASSERT_EQ(ra.temp_c, rb.temp_c);
    differs = differs || ra.gyro_radps != rc.gyro_radps;
  }
  EXPECT_TRUE(differs);
}

TEST(SensorModel, SwitchingOneEffectLeavesTheOthersDrawsAlone) {
  // GIVEN the defaults, and the defaults with white noise, jitter and accel noise toggled
  SensorParams base = mpu6050_defaults();
  SensorParams other = base;
  other.white_noise.enabled = false;
  other.sample_jitter.enabled = true;
  other.accel_white_noise.enabled = false;
  other.scale_factor.enabled = false;
  SensorModel a(base, kFs, 5), b(other, kFs, 5);
  // THEN the run-to-run draws of untouched effects and the bias processes are identical
  EXPECT_EQ(a.instance().bias_radps, b.instance().bias_radps);
  EXPECT_EQ(a.instance().misalignment, b.instance().misalignment);
  EXPECT_EQ(a.instance().G_radps_per_mps2, b.instance().G_radps_per_mps2);
  for (int k = 0; k < 2000; ++k) {
    const SensorTruth tr = truth_at(k / kFs, Eigen::Vector3d::Zero());
    ASSERT_EQ(a.step(tr).bias_radps, b.step(tr).bias_radps) << k;
  }
}

TEST(SensorModel, SampleJitterMovesTheSampleInstant) {
  // GIVEN a ramp w = a t and 1 ms rms jitter THEN y - w = a dt_j with dt_j ~ N(0, 1 ms^2)
  SensorParams p = ideal_sensor();
  p.sample_jitter.enabled = true;
  p.sample_jitter.sigma_s = 1e-3;
  SensorModel m(p, kFs, 11);
  const double a = 2.0;
  double sum = 0.0, sum2 = 0.0;
  const int n = 40000;
  for (int k = 0; k < n; ++k) {
    const double t = k / kFs;
    const double e = (m.step(truth_at(t, Eigen::Vector3d::Constant(a * t))).gyro_radps[0] - a * t) / a;
    if (k == 0) {
      EXPECT_EQ(e, 0.0);  // no previous sample yet: no derivative
      continue;
    }
    sum += e;
    sum2 += e * e;
  }
  const double mean = sum / (n - 1);
  const double sd = std::sqrt(sum2 / (n - 1) - mean * mean);
  EXPECT_NEAR(mean, 0.0, 4.0 * 1e-3 / std::sqrt(n));
  EXPECT_NEAR(sd, 1e-3, 0.02 * 1e-3);
}

TEST(SensorModel, PredictionMatchesTheNoiseFreeModel) {
  // GIVEN the defaults with every stochastic process off: step() equals predict_gyro_radps()
  SensorParams p = mpu6050_defaults();
  p.bias_instability.enabled = false;
  p.rate_random_walk.enabled = false;
  p.white_noise.enabled = false;
  p.lowpass_latency.enabled = false;
  SensorModel m(p, kFs, 8);
  TemperatureModel temp(p.temperature);
  for (int k = 0; k < 200; ++k) {
    const SensorTruth tr = truth_at(k / kFs, dps(30.0 * std::sin(0.1 * k), 10.0, -5.0), {0.1, 0.2, 9.8});
    const SensorReading r = m.step(tr);
    EXPECT_EQ(r.gyro_radps, predict_gyro_radps(p, m.instance(), tr, temp.at(tr.t_s))) << k;
  }
}
