// Test logs for compare/diagnose: closed-form pan/tilt kinematics (smooth body rotation, the
// flip schedule of paper Fig. 3) fed through the effects' SensorModel (the documented sensor
// equation), written as driftless-log samples.
#pragma once

#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "estimator/log.hpp"
#include "twin/sensor/sensor_model.hpp"

namespace driftless::diagnose::testlog {

using namespace driftless::twin;  // the sensor model, scenario and simulator

struct TestLog {
  std::vector<Sample> samples;
  log::Metadata meta;
  std::uint32_t fields = kFieldRefQ | kFieldRefP | kFieldTemp;
};

/// Platform angle (deg) and rate (deg/s) of the flip schedule: standstill, then a cosine flip.
inline void platform_state(double t, int platform, double standstill_s, double flip_s, double& ang, double& rate) {
  // sequence (+,+) -> (+,-) -> (-,-) -> (-,+) -> (+,+): platform 2 moves on odd steps, 1 on even
  const double period = standstill_s + flip_s;
  const int step = static_cast<int>(std::floor(t / period));
  const double u = t - step * period;
  auto side = [&](int k) {  // side of a platform after k flips
    const int moves = platform == 0 ? (k + 0) / 2 : (k + 1) / 2;
    return moves % 2 == 0 ? 1.0 : -1.0;
  };
  const bool moving_now = (platform == 0) ? (step % 2 == 1) : (step % 2 == 0);
  const double from = 90.0 * side(step), to = 90.0 * side(step + 1);
  if (u < standstill_s || !moving_now) {
    ang = from;
    rate = 0.0;
    if (!moving_now) ang = 90.0 * side(step + 1);
    return;
  }
  const double v = (u - standstill_s) / flip_s;
  ang = from + (to - from) * 0.5 * (1.0 - std::cos(kPi * v));
  rate = (to - from) * 0.5 * kPi * std::sin(kPi * v) / flip_s;
}

/// Box body rate relative to ENU, rad/s (a smooth "random but known" pan/tilt pattern).
inline Eigen::Vector3d body_rate(double t, double amp_dps) {
  return amp_dps * kRadPerDeg *
         Eigen::Vector3d(std::sin(2 * kPi * 0.031 * t + 0.3), 0.8 * std::sin(2 * kPi * 0.047 * t + 1.1),
                         std::sin(2 * kPi * 0.023 * t + 2.0) * std::cos(2 * kPi * 0.011 * t));
}

/// Box-level errors planted in a test log (the log does not know them).
struct Planted {
  double stop_error_deg[2][2] = {{0, 0}, {0, 0}};  // [platform][0: + stop, 1: - stop], deg
  double time_offset_s = 0.0;                      // sensors sample this much before the log time
  bool with_ref_q = true;
};

/// Simulates `duration_s` at `fs` Hz with sensors p1, p2 (seeded). amp_dps = 0: static box.
inline TestLog make_log(const SensorParams& p1, const SensorParams& p2, double duration_s, std::uint64_t seed,
                        double amp_dps = 30.0, double fs = 100.0, double lat_deg = 52.0, const Planted& pl = {}) {
  TestLog out;
  out.meta.set("format", "driftless-log 1");
  out.meta.set("complete", "true");
  out.meta.set("sample_rate_hz", std::to_string(fs));
  if (!pl.with_ref_q) out.fields = kFieldTemp;
  out.meta.set("latitude_deg", std::to_string(lat_deg));
  SensorModel s1(p1, fs, seed * 2 + 1), s2(p2, fs, seed * 2 + 2);
  const double lat = lat_deg * kRadPerDeg;
  const Eigen::Vector3d earth(0, kEarthRateRadps * std::cos(lat), kEarthRateRadps * std::sin(lat));
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  const int sub = 20;
  const auto n = static_cast<std::size_t>(duration_s * fs);
  const Eigen::Vector3d axes[2] = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()};
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / fs;
    if (k > 0) {  // integrate the attitude from the previous sample (midpoint substeps)
      const double t0 = static_cast<double>(k - 1) / fs, h = 1.0 / fs / sub;
      for (int i = 0; i < sub; ++i) {
        const Eigen::Vector3d w = body_rate(t0 + (i + 0.5) * h, amp_dps);
        const double a = w.norm() * h;
        if (a > 0) q = q * Eigen::Quaterniond(Eigen::AngleAxisd(a, w.normalized()));
      }
      q.normalize();
    }
    const Eigen::Matrix3d R_eb = q.toRotationMatrix();
    const double ts = t - pl.time_offset_s;  // when the sensors really sampled
    const Eigen::Vector3d w_body = body_rate(ts, amp_dps) + R_eb.transpose() * earth;
    const Eigen::Vector3d f_body = R_eb.transpose() * Eigen::Vector3d(0, 0, kStandardGravityMps2);
    Sample s;
    s.t_s = t;
    s.set_q_enu_from_body(q);
    s.ref_p_enu_m.setZero();
    double ang[2], rate[2];
    SensorReading rd[2];
    for (int p = 0; p < 2; ++p) {
      platform_state(ts, p, 10.0, 1.0, ang[p], rate[p]);
      // a platform resting against a stop sits at the stop's true angle
      double true_ang = ang[p];
      if (rate[p] == 0.0) true_ang += ang[p] > 0 ? pl.stop_error_deg[p][0] : pl.stop_error_deg[p][1];
      const Eigen::Matrix3d R = Eigen::AngleAxisd(true_ang * kRadPerDeg, axes[p]).toRotationMatrix();
      SensorTruth tr;
      tr.t_s = t;
      tr.w_radps = R.transpose() * w_body + rate[p] * kRadPerDeg * axes[p];
      tr.f_mps2 = R.transpose() * f_body;
      rd[p] = p == 0 ? s1.step(tr) : s2.step(tr);
    }
    // the log's fixed precision, as LogWriter writes it
    auto r7 = [](double v) { return std::round(v * 1e7) / 1e7; };
    auto r6 = [](double v) { return std::round(v * 1e6) / 1e6; };
    for (int i = 0; i < 3; ++i) {
      s.gyro1_dps[i] = r7(rd[0].gyro_radps[i] * kDegPerRad);
      s.gyro2_dps[i] = r7(rd[1].gyro_radps[i] * kDegPerRad);
    }
    double lang[2], lrate[2];
    for (int p = 0; p < 2; ++p) platform_state(t, p, 10.0, 1.0, lang[p], lrate[p]);
    s.plat1_deg = r6(lang[0]);
    s.plat2_deg = r6(lang[1]);
    s.temp1_c = std::round(rd[0].temp_c * 1e3) / 1e3;
    s.temp2_c = std::round(rd[1].temp_c * 1e3) / 1e3;
    out.samples.push_back(s);
  }
  return out;
}

}  // namespace driftless::diagnose::testlog
