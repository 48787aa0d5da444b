// Synthetic closed-form box streams for the FDI tests, eq. (1):
// y_i = R_i^T x + thetadot_i a_i + b_i + n_i, quantised to the MPU6050's 1/131 deg/s, with a
// planted fault. Shared by test_fdi.cpp (quick) and slow_test_fdi.cpp (many seeds).
#pragma once

#include <cmath>
#include <optional>
#include <random>

#include <Eigen/Geometry>

#include "estimator/fdi.hpp"

namespace driftless::est::fdi_test {

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
inline bool platforms(const Box& box, double t, double* th1, double* th2, double* w1, double* w2) {
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

inline Outcome run(const Box& box, const Fault& fault, std::uint64_t seed, double duration_s) {
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

}  // namespace driftless::est::fdi_test
