// Synthetic dual-gyro samples from the closed-form sensor equation of docs/log-format.md, with
// the temperature and g-sensitivity terms of docs/estimator.md sections 1a, 1b when asked for:
//   y_i = R_i^T w_body + thetadot_i a_i + b_i + k_i (T - T0) + G_i f_i + n_i,   R_i = Rot(a_i, theta_i)
//   f_i = R_i^T up_box (g: a box that does not accelerate)
// Test-only; independent of the twin. Flips follow eq. (5)'s sequence (+,+) (+,-) (-,-) (-,+).
// The one Eigen-only generator of the estimator tests (filter, pipeline, FDI, tuning, health);
// twin-side tests use twin::FastBox.
#pragma once

#include <array>
#include <cmath>
#include <filesystem>
#include <functional>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "estimator/box_geometry.hpp"
#include "estimator/log.hpp"
#include "estimator/sample.hpp"

namespace driftless::test {

struct SynthParams {
  double rate_hz = 100.0;
  double duration_s = 600.0;
  double standstill_s = 10.0;   // s at rest per position
  double flip_s = 1.0;          // s per flip
  double flip_angle_deg = 90.0;
  bool hold_platform2 = false;  // only platform 1 flips (two positions)
  long both_at_cycle = -1;      // the flip ending this cycle moves both platforms (skips a position)
  bool nan_while_moving = false;  // end-stop hardware: angles empty while moving
  Eigen::Vector3d hinge1 = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d hinge2 = Eigen::Vector3d::UnitX();
  Eigen::Vector3d b1_dps{1.5, -0.7, 0.4};
  Eigen::Vector3d b2_dps{-2.0, 0.3, 1.1};
  double noise_sigma_dps = 0.0;     // per-sample white noise, each axis
  double gm_sigma_dps = 0.0;        // Gauss-Markov bias wander (steady-state sigma)
  double gm_tau_s = 1000.0;         // its correlation time
  // an extra sensor-2 offset (deg/s, sensor axes) while platform 2 sits at a negative angle: the
  // signature of a position-dependent error (g-sensitivity on a horizontal hinge, misalignment)
  Eigen::Vector3d b2_extra_at_negative_plat2_dps = Eigen::Vector3d::Zero();
  // box rate relative to ENU in box axes (zero if empty); the sensors also see the Earth rate
  std::function<Eigen::Vector3d(double)> body_rate_dps;
  // extra noise per sample (deg/s, sensor axes) from outside, e.g. a real recording's: (sensor 1|2, index)
  std::function<Eigen::Vector3d(int, std::size_t)> extra_noise_dps;
  double bias_walk_dps = 0.0;       // random-walk step of both biases per sample, deg/s (0: none)
  double lsb_dps = 0.0;             // readings quantised to this step, deg/s (MPU6050: 1/131; 0: not)
  // a last change to each sample's readings before they are quantised (planted faults)
  std::function<void(Sample&)> before_quantise;
  bool earth_rate = true;
  double latitude_deg = 52.0;
  std::uint64_t seed = 1;
  // sensor errors beyond the paper's (zero = its ideal sensor); true_bias holds b + k (T - T0)
  std::array<Eigen::Matrix3d, 2> G_dps_per_g{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  std::array<Eigen::Vector3d, 2> temp_coef_dps_per_degc{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  // scale-factor and misalignment error per sensor (fraction): y_i += E_i (R_i^T w + thetadot_i a_i),
  // w the box's inertial rate: the sensor scales whatever turns it, the flips included
  std::array<Eigen::Matrix3d, 2> E_frac{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  // end-stop angle errors per platform [at the negative stop, at the positive one] (deg, actual -
  // read about the hinge, as the twin's model.box.stopN_error_deg): the angle columns read the
  // nominal angles, the sensors turn through the actual ones (the flips too)
  std::array<Eigen::Vector2d, 2> stop_error_deg{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  double temp0_c = 25.0, temp_rise_c = 0.0, temp_tau_s = 600.0;  // T = T0 + rise (1 - e^-t/tau), degC
  bool write_accel_temp = false;  // log accel (m/s^2, sensor axes) and temperature columns
};

inline log::Metadata synth_metadata(const SynthParams& p) {
  log::Metadata m;
  m.set("complete", "true");
  m.set("sample_rate_hz", std::to_string(p.rate_hz));
  m.set("latitude_deg", std::to_string(p.latitude_deg));
  auto vec = [](const Eigen::Vector3d& v) {
    return std::to_string(v.x()) + " " + std::to_string(v.y()) + " " + std::to_string(v.z());
  };
  m.set("hinge1_axis", vec(p.hinge1));
  m.set("hinge2_axis", vec(p.hinge2));
  m.set("source", "synth");
  return m;
}

inline est::BoxGeometry synth_geometry(const SynthParams& p) {
  est::BoxGeometry g = est::box_geometry_from_metadata(synth_metadata(p));
  g.flip_angle_deg = p.flip_angle_deg;
  return g;
}

/// Streams samples to `sink` (so 14 h runs need no memory).
inline void synth_samples(const SynthParams& p, const std::function<void(const Sample&)>& sink) {
  std::mt19937_64 rng(p.seed);
  std::normal_distribution<double> g(0.0, 1.0);
  const double dt = 1.0 / p.rate_hz;
  const double cycle = p.standstill_s + p.flip_s;
  const std::size_t n = static_cast<std::size_t>(std::llround(p.duration_s * p.rate_hz));
  const double a = p.flip_angle_deg;
  static constexpr int kS1[4] = {+1, +1, -1, -1};
  static constexpr int kS2[4] = {+1, -1, -1, +1};
  Eigen::Vector3d gm1 = Eigen::Vector3d::Zero(), gm2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d walk1 = Eigen::Vector3d::Zero(), walk2 = Eigen::Vector3d::Zero();
  const double gm_phi = std::exp(-dt / p.gm_tau_s);
  const double drive = p.gm_sigma_dps * std::sqrt(1.0 - gm_phi * gm_phi);
  if (p.gm_sigma_dps > 0.0) {
    for (int i = 0; i < 3; ++i) {
      gm1[i] = p.gm_sigma_dps * g(rng);
      gm2[i] = p.gm_sigma_dps * g(rng);
    }
  }
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  for (std::size_t k = 0; k < n; ++k) {
    const double t = k * dt;
    const long c = static_cast<long>(std::floor(t / cycle));
    const double in = t - c * cycle;
    // position index j = c; during the flip at the end of cycle c we move to j = c + 1
    auto angles = [&](long j, double& t1, double& t2) {
      const int pj = static_cast<int>((p.both_at_cycle >= 0 && j > p.both_at_cycle ? j + 1 : j) % 4);
      t1 = a * kS1[pj];
      t2 = p.hold_platform2 ? a : a * kS2[pj];
    };
    // t1, t2: the angles read; e1, e2: how far the actual ones are off (the stop's error)
    const auto off = [&](std::size_t i, double read_deg) { return p.stop_error_deg[i][read_deg < 0.0 ? 0 : 1]; };
    double t1, t2, w1 = 0.0, w2 = 0.0;
    angles(c, t1, t2);
    double e1 = off(0, t1), e2 = off(1, t2);
    bool moving = false;
    if (in >= p.standstill_s) {
      double n1, n2;
      angles(c + 1, n1, n2);
      const double f1 = off(0, n1), f2 = off(1, n2);
      const double u = (in - p.standstill_s) / p.flip_s;
      const double s = 0.5 * (1.0 - std::cos(kPi * u));
      const double sd = 0.5 * kPi * std::sin(kPi * u) / p.flip_s;
      w1 = (n1 + f1 - t1 - e1) * sd;
      w2 = (n2 + f2 - t2 - e2) * sd;
      t1 = t1 + (n1 - t1) * s;
      t2 = t2 + (n2 - t2) * s;
      e1 = e1 + (f1 - e1) * s;
      e2 = e2 + (f2 - e2) * s;
      moving = true;
    }
    const Eigen::Vector3d w_nb = p.body_rate_dps ? p.body_rate_dps(t) : Eigen::Vector3d::Zero();
    const double phi = p.latitude_deg * kRadPerDeg;
    const Eigen::Vector3d w_ie_enu_dps =
        p.earth_rate ? Eigen::Vector3d(Eigen::Vector3d(0.0, std::cos(phi), std::sin(phi)) * kEarthRateRadps * kDegPerRad)
                     : Eigen::Vector3d(Eigen::Vector3d::Zero());
    const Eigen::Vector3d w = w_nb + q.conjugate() * w_ie_enu_dps;  // inertial, box axes
    const Eigen::Matrix3d R1 = Eigen::AngleAxisd((t1 + e1) * kRadPerDeg, p.hinge1.normalized()).toRotationMatrix();
    const Eigen::Matrix3d R2 = Eigen::AngleAxisd((t2 + e2) * kRadPerDeg, p.hinge2.normalized()).toRotationMatrix();
    const double temp_c = p.temp0_c + p.temp_rise_c * (1.0 - std::exp(-t / p.temp_tau_s));
    const Eigen::Vector3d b1 = p.b1_dps + gm1 + walk1 + p.temp_coef_dps_per_degc[0] * (temp_c - p.temp0_c);
    const Eigen::Vector3d b2 = p.b2_dps + gm2 + walk2 + p.temp_coef_dps_per_degc[1] * (temp_c - p.temp0_c) +
                               (t2 < 0.0 ? p.b2_extra_at_negative_plat2_dps : Eigen::Vector3d::Zero());
    const Eigen::Vector3d up_box = q.conjugate() * Eigen::Vector3d::UnitZ();  // specific force at rest, g
    const Eigen::Vector3d f1 = R1.transpose() * up_box, f2 = R2.transpose() * up_box;
    Sample s;
    s.t_s = t;
    s.gyro1_dps = R1.transpose() * w + w1 * p.hinge1.normalized() + b1 + p.G_dps_per_g[0] * f1;
    s.gyro2_dps = R2.transpose() * w + w2 * p.hinge2.normalized() + b2 + p.G_dps_per_g[1] * f2;
    if (!p.E_frac[0].isZero(0.0) || !p.E_frac[1].isZero(0.0)) {
      s.gyro1_dps += p.E_frac[0] * (R1.transpose() * w + w1 * p.hinge1.normalized());
      s.gyro2_dps += p.E_frac[1] * (R2.transpose() * w + w2 * p.hinge2.normalized());
    }
    if (p.write_accel_temp) {
      s.accel1_mps2 = f1 * kStandardGravityMps2;
      s.accel2_mps2 = f2 * kStandardGravityMps2;
      s.temp1_c = s.temp2_c = temp_c;
    }
    if (p.noise_sigma_dps > 0.0) {
      for (int i = 0; i < 3; ++i) {
        s.gyro1_dps[i] += p.noise_sigma_dps * g(rng);
        s.gyro2_dps[i] += p.noise_sigma_dps * g(rng);
      }
    }
    if (p.extra_noise_dps) {
      s.gyro1_dps += p.extra_noise_dps(1, k);
      s.gyro2_dps += p.extra_noise_dps(2, k);
    }
    const bool hide = p.nan_while_moving && moving;
    s.plat1_deg = hide && w1 != 0.0 ? kNaN : t1;
    s.plat2_deg = hide && w2 != 0.0 ? kNaN : t2;
    s.true_plat1_deg = t1 + e1;
    s.true_plat2_deg = t2 + e2;
    s.true_bias1_dps = b1;
    s.true_bias2_dps = b2;
    s.true_rate_body_dps = w;
    s.set_q_enu_from_body(q);
    if (p.before_quantise) p.before_quantise(s);  // the truth columns are set
    if (p.lsb_dps > 0.0) {
      for (int i = 0; i < 3; ++i) {
        s.gyro1_dps[i] = std::round(s.gyro1_dps[i] / p.lsb_dps) * p.lsb_dps;
        s.gyro2_dps[i] = std::round(s.gyro2_dps[i] / p.lsb_dps) * p.lsb_dps;
      }
    }
    sink(s);
    // truth attitude q_enu_from_body follows the rate relative to ENU
    const Eigen::Vector3d wr = w_nb * kRadPerDeg * dt;
    if (wr.norm() > 0.0) q = (q * Eigen::Quaterniond(Eigen::AngleAxisd(wr.norm(), wr.normalized()))).normalized();
    if (p.gm_sigma_dps > 0.0) {
      for (int i = 0; i < 3; ++i) {
        gm1[i] = gm_phi * gm1[i] + drive * g(rng);
        gm2[i] = gm_phi * gm2[i] + drive * g(rng);
      }
    }
    if (p.bias_walk_dps > 0.0) {
      for (int i = 0; i < 3; ++i) {
        walk1[i] += p.bias_walk_dps * g(rng);
        walk2[i] += p.bias_walk_dps * g(rng);
      }
    }
  }
}

/// Writes the samples as a log (ref_q and truth columns included).
inline void synth_log(const SynthParams& p, const std::filesystem::path& path) {
  const std::uint32_t extra = p.write_accel_temp ? (kFieldAccel | kFieldTemp) : 0u;
  log::LogWriter w(path, synth_metadata(p), kFieldRefQ | kFieldTrueBias | kFieldTrueRate | kFieldTruePlat | extra);
  synth_samples(p, [&](const Sample& s) { w.write(s); });
  w.finish(true);
}

inline std::vector<Sample> synth_all(const SynthParams& p) {
  std::vector<Sample> v;
  synth_samples(p, [&](const Sample& s) { v.push_back(s); });
  return v;
}

}  // namespace driftless::test
