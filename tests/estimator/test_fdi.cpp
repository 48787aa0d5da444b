// Fault detection and isolation on synthetic closed-form box data, eq. (1):
// y_i = R_i^T x + thetadot_i a_i + b_i + n_i, quantised to the MPU6050's 1/131 deg/s.
// GIVEN a planted fault WHEN the stream runs THEN it is detected within the stated delay and
// attributed to the right sensor and axis; fault-free runs over many seeds raise no alarm.
#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "estimator/fdi.hpp"

namespace driftless::est {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kD2R = kPi / 180.0;

struct Fault {
  FaultKind kind = FaultKind::kNone;
  int sensor = 1, axis = 0;
  double t_s = 60.0;
  double size = 0.0;  // bias step deg/s, noise sigma ratio, relative scale change
};

struct Box {
  double rate_hz = 100.0;
  double standstill_s = 5.0, flip_s = 0.5;
  double noise_dps = 0.05;          // per-sample sigma: 0.005 deg/s/rtHz at 100 Hz
  double lsb_dps = 1.0 / 131.0;
  double motion_dps = 0.0;          // amplitude of a smooth box rotation, deg/s per axis
  Eigen::Vector3d a1 = Eigen::Vector3d::UnitZ(), a2 = Eigen::Vector3d::UnitX();
};

// platform angles of the eq. (5) cycle (+,+) (+,-) (-,-) (-,+); returns at_rest
bool platforms(const Box& box, double t, double* th1, double* th2, double* w1, double* w2) {
  const double period = box.standstill_s + box.flip_s;
  const long k = static_cast<long>(std::floor(t / period));
  const double tau = t - k * period;
  static const int s1[4] = {+1, +1, -1, -1}, s2[4] = {+1, -1, -1, +1};
  const int i = static_cast<int>(k % 4), n = (i + 1) % 4;
  double a1 = s1[i] * 90.0, a2 = s2[i] * 90.0;
  *w1 = *w2 = 0.0;
  bool rest = true;
  if (tau > box.standstill_s) {
    const double frac = (tau - box.standstill_s) / box.flip_s;
    if (s1[n] != s1[i]) {
      a1 += frac * (s1[n] - s1[i]) * 90.0;
      *w1 = (s1[n] - s1[i]) * 90.0 / box.flip_s;
    }
    if (s2[n] != s2[i]) {
      a2 += frac * (s2[n] - s2[i]) * 90.0;
      *w2 = (s2[n] - s2[i]) * 90.0 / box.flip_s;
    }
    rest = false;
  }
  *th1 = a1;
  *th2 = a2;
  return rest;
}

struct Outcome {
  std::optional<FaultReport> fault;
  std::optional<double> first_alarm;
};

Outcome run(const Box& box, const Fault& fault, std::uint64_t seed, double duration_s) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss;
  FdiParams p;
  p.sample_rate_hz = box.rate_hz;
  FaultDetector fdi(p);
  Eigen::Matrix<double, 6, 1> bias;
  for (int i = 0; i < 6; ++i) bias[i] = 0.5 * gauss(rng);  // run-to-run bias, deg/s
  const double rw = 1e-4;                                   // bias random walk per sample, deg/s
  const Eigen::Vector3d earth(0, 7.292115e-5 / kD2R * std::cos(52 * kD2R),
                              7.292115e-5 / kD2R * std::sin(52 * kD2R));
  Eigen::Vector3d phase(gauss(rng), gauss(rng), gauss(rng));
  double stuck_value = 0.0;
  const long n = static_cast<long>(duration_s * box.rate_hz);
  for (long k = 0; k < n; ++k) {
    const double t = k / box.rate_hz;
    double th1, th2, w1, w2;
    const bool rest = platforms(box, t, &th1, &th2, &w1, &w2);
    const Eigen::Matrix3d R1 = Eigen::AngleAxisd(th1 * kD2R, box.a1).toRotationMatrix();
    const Eigen::Matrix3d R2 = Eigen::AngleAxisd(th2 * kD2R, box.a2).toRotationMatrix();
    Eigen::Vector3d x = earth;
    for (int j = 0; j < 3; ++j) {
      x[j] += box.motion_dps * std::sin(2 * kPi * (0.13 + 0.07 * j) * t + phase[j]);
    }
    for (int i = 0; i < 6; ++i) bias[i] += rw * gauss(rng);
    Eigen::Vector3d y1 = R1.transpose() * x + w1 * box.a1 + bias.head<3>();
    Eigen::Vector3d y2 = R2.transpose() * x + w2 * box.a2 + bias.tail<3>();
    Eigen::Vector3d n1(gauss(rng), gauss(rng), gauss(rng)), n2(gauss(rng), gauss(rng), gauss(rng));
    n1 *= box.noise_dps;
    n2 *= box.noise_dps;
    const bool active = fault.kind != FaultKind::kNone && t >= fault.t_s;
    Eigen::Vector3d& yf = fault.sensor == 1 ? y1 : y2;
    Eigen::Vector3d& nf = fault.sensor == 1 ? n1 : n2;
    const Eigen::Vector3d clean = (fault.sensor == 1 ? R1 : R2).transpose() * x;
    if (active && fault.kind == FaultKind::kBiasStep) yf[fault.axis] += fault.size;
    if (active && fault.kind == FaultKind::kNoiseBurst) nf[fault.axis] *= fault.size;
    if (active && fault.kind == FaultKind::kScaleChange) yf[fault.axis] += fault.size * clean[fault.axis];
    y1 += n1;
    y2 += n2;
    for (int j = 0; j < 3; ++j) {
      y1[j] = std::round(y1[j] / box.lsb_dps) * box.lsb_dps;
      y2[j] = std::round(y2[j] / box.lsb_dps) * box.lsb_dps;
    }
    if (fault.kind == FaultKind::kStuck) {
      if (!active) stuck_value = yf[fault.axis];
      else yf[fault.axis] = stuck_value;
    }
    FdiInput in;
    in.t_s = t;
    in.gyro1_dps = y1;
    in.gyro2_dps = y2;
    in.R_body_from_sensor1 = R1;
    in.R_body_from_sensor2 = R2;
    in.at_rest = rest;
    // an ideal filter: the true pre-fault bias, with a small covariance
    in.bias_dps = bias;
    in.bias_cov_dps2 = Matrix6d::Identity() * 1e-6;
    if (fdi.push(in) == FdiStatus::kIsolated) break;
  }
  return {fdi.fault(), fdi.first_alarm_s()};
}

// stated delays (docs/fdi.md): stuck 0.5 s; noise burst x5 alarm 1 s, isolation 3 s;
// scale +5 % under 20 deg/s motion alarm 1 s, isolation 3 s;
// bias step 0.5 deg/s alarm 1 s, isolation within three platform cycles' segments (20 s)
struct Case {
  FaultKind kind;
  double size, motion_dps, alarm_s, isolate_s;
};

class FdiPlanted : public ::testing::TestWithParam<Case> {};

TEST_P(FdiPlanted, DetectsAndIsolatesOnEverySensorAxis) {
  const Case c = GetParam();
  Box box;
  box.motion_dps = c.motion_dps;
  for (int sensor = 1; sensor <= 2; ++sensor) {
    for (int axis = 0; axis < 3; ++axis) {
      for (std::uint64_t seed = 1; seed <= 3; ++seed) {
        Fault f{c.kind, sensor, axis, 60.0 + 1.7 * axis + seed, c.size};
        const Outcome o = run(box, f, seed * 100 + sensor * 10 + axis, f.t_s + 40.0);
        SCOPED_TRACE(::testing::Message() << to_string(c.kind) << " sensor " << sensor << " axis "
                                          << axis << " seed " << seed);
        ASSERT_TRUE(o.fault.has_value());
        EXPECT_EQ(o.fault->kind, c.kind) << o.fault->describe();
        EXPECT_EQ(o.fault->sensor, sensor) << o.fault->describe();
        EXPECT_EQ(o.fault->axis, axis) << o.fault->describe();
        EXPECT_TRUE(o.fault->confident) << o.fault->describe();
        ASSERT_TRUE(o.first_alarm.has_value());
        EXPECT_GE(*o.first_alarm, f.t_s);
        EXPECT_LE(*o.first_alarm - f.t_s, c.alarm_s) << o.fault->describe();
        EXPECT_LE(o.fault->t_isolated_s - f.t_s, c.isolate_s) << o.fault->describe();
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Faults, FdiPlanted,
    ::testing::Values(Case{FaultKind::kStuck, 0.0, 0.0, 0.5, 0.5},
                      Case{FaultKind::kBiasStep, 0.5, 0.0, 1.0, 20.0},
                      Case{FaultKind::kBiasStep, 0.5, 20.0, 1.0, 20.0},
                      Case{FaultKind::kNoiseBurst, 5.0, 0.0, 1.0, 3.0},
                      Case{FaultKind::kNoiseBurst, 5.0, 20.0, 1.0, 3.0},
                      Case{FaultKind::kScaleChange, 0.05, 20.0, 1.0, 3.0}),
    [](const auto& info) {
      return std::string(to_string(info.param.kind)) + (info.param.motion_dps > 0 ? "_moving" : "_static");
    });

// GIVEN fault-free runs WHEN 40 seeds x 10 min run (static and moving) THEN no alarm at all
TEST(Fdi, NoFalseAlarmOverManySeeds) {
  Box box;
  int alarms = 0;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    box.motion_dps = seed % 2 ? 0.0 : 20.0;
    const Outcome o = run(box, Fault{}, 7000 + seed, 600.0);
    if (o.first_alarm) {
      ++alarms;
      ADD_FAILURE() << "seed " << seed << " alarm at " << *o.first_alarm;
    }
  }
  EXPECT_EQ(alarms, 0);
}

// the learned residual sigma matches the closed form sqrt(2) * sigma_sensor (+ quantisation)
TEST(Fdi, LearnsResidualNoise) {
  Box box;
  FdiParams p;
  FaultDetector fdi(p);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> gauss;
  for (int k = 0; k < 2000; ++k) {
    FdiInput in;
    in.t_s = k / 100.0;
    in.at_rest = true;
    for (int j = 0; j < 3; ++j) {
      in.gyro1_dps[j] = box.noise_dps * gauss(rng);
      in.gyro2_dps[j] = box.noise_dps * gauss(rng);
    }
    fdi.push(in);
  }
  const Eigen::Vector3d s = fdi.residual_sigma_dps();
  for (int j = 0; j < 3; ++j) EXPECT_NEAR(s[j], std::sqrt(2.0) * box.noise_dps, 0.004);
}

TEST(Fdi, DegradedModeHoldsBiasAndGrowsSigma) {
  Vector6d b;
  b << 1, 2, 3, 4, 5, 6;
  Matrix6d P = Matrix6d::Identity() * 1e-4;
  DegradedBias deg(1, b, P, 100.0, 1e-6);
  EXPECT_EQ(deg.healthy_sensor(), 2);
  EXPECT_EQ(deg.bias_dps(), Eigen::Vector3d(4, 5, 6));
  EXPECT_NEAR(deg.sigma_dps(100.0)[0], 1e-2, 1e-12);
  // sigma^2 = 1e-4 + 1e-6 * 3600
  EXPECT_NEAR(deg.sigma_dps(3700.0)[1], std::sqrt(1e-4 + 3.6e-3), 1e-12);
  FdiInput in;
  in.gyro2_dps = Eigen::Vector3d(4.5, 5, 6);
  in.R_body_from_sensor2 = Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  EXPECT_TRUE(deg.body_rate_dps(in).isApprox(Eigen::Vector3d(0.5, 0, 0), 1e-12));
  EXPECT_THROW(DegradedBias(3, b, P, 0, 0), std::invalid_argument);
}

TEST(Fdi, ValidateNamesTheField) {
  FdiParams p;
  p.noise_ratio = 0.5;
  try {
    p.validate();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("noise_ratio"), std::string::npos);
  }
}

}  // namespace
}  // namespace driftless::est
