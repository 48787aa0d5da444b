// Test helper: a closed-form calibration rig. The table follows the plan's square wave with a
// finite acceleration; the box attitude (ref_q) integrates it; each sensor reads
// y = M^-1 (w_table + w_earth) + b + noise. No MuJoCo: an independent check of the twin's rig.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "estimator/calibration.hpp"
#include "estimator/geometry.hpp"
#include "estimator/log.hpp"
#include "calibration/rig_plan.hpp"

namespace driftless::calib::testing {

struct ClosedFormRig {
  est::CalibMatrices M;  // true matrices
  Eigen::Vector3d bias_dps[2] = {Eigen::Vector3d(1.5, -0.8, 0.3), Eigen::Vector3d(-2.1, 0.4, 1.1)};
  double sigma_dps = 0.05;        // per-sample white noise (MPU6050 at 100 Hz)
  double accel_dps2 = 1000.0;     // table acceleration
  double sample_rate_hz = 100.0;
  double latitude_deg = 52.0;
  double lsb_dps = 0.0;           // quantization step (0 = off)

  /// The rate the table really turns at (deg/s, signed about the segment axis).
  static double table_rate(const PlanSegment& s, double t, double accel_dps2) {
    if (t < s.t_start_s || t >= s.t_end_s) return 0.0;
    const double since = std::fmod(t - s.t_start_s, s.half_period_s);
    const double target = s.sign_at(t) * s.rate_dps;
    const double ramp_s = 2.0 * s.rate_dps / accel_dps2;
    const bool first = t - s.t_start_s < s.half_period_s;
    if (first) return std::clamp(since * accel_dps2, 0.0, s.rate_dps) * s.sign_at(t);
    if (since >= ramp_s) return target;
    return -target + (target > 0 ? 1 : -1) * accel_dps2 * since;
  }

  std::vector<Sample> run(const RigPlan& plan, std::uint64_t seed, log::Metadata* meta) const {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> n01(0.0, 1.0);
    const double lat = latitude_deg * kRadPerDeg;
    const Eigen::Vector3d w_earth_enu =
        kEarthRateRadps * kDegPerRad * Eigen::Vector3d(0, std::cos(lat), std::sin(lat));
    std::vector<Sample> out;
    const double dt = 1.0 / sample_rate_hz;
    const double t_end = plan.segments.back().t_end_s + 1.0;
    std::size_t seg = 0;
    double pan_deg = 0.0;
    for (long k = 0;; ++k) {
      const double t = k * dt;
      if (t > t_end) break;
      while (seg + 1 < plan.segments.size() && t >= plan.segments[seg].t_end_s + 0.5 * (plan.segments[seg + 1].t_start_s - plan.segments[seg].t_end_s)) {
        ++seg;
        pan_deg = 0.0;  // remounted
      }
      const PlanSegment& s = plan.segments[seg];
      const double rate = table_rate(s, t, accel_dps2);
      const Eigen::Quaterniond q = Eigen::AngleAxisd(pan_deg * kRadPerDeg, Eigen::Vector3d::UnitZ()) *
                                   orientation_mount(s.axis_box);
      const Eigen::Vector3d w_box = rate * s.axis_box + q.conjugate() * w_earth_enu;
      Sample x;
      x.t_s = t;
      x.plat1_deg = s.plat1_deg;
      x.plat2_deg = s.plat2_deg;
      x.set_q_enu_from_body(q);
      Eigen::Vector3d y[2];
      for (int i = 0; i < 2; ++i) {
        const int p = est::position_index(i == 0 ? s.plat1_deg : s.plat2_deg);
        y[i] = est::sensor_output_dps(M.M(i, p), w_box, bias_dps[i]);
        for (int j = 0; j < 3; ++j) {
          y[i][j] += sigma_dps * n01(rng);
          if (lsb_dps > 0) y[i][j] = std::round(y[i][j] / lsb_dps) * lsb_dps;
        }
      }
      x.gyro1_dps = y[0];
      x.gyro2_dps = y[1];
      out.push_back(x);
      pan_deg += rate * dt;
    }
    if (meta) {
      meta->set("sample_rate_hz", std::to_string(sample_rate_hz));
      meta->set("latitude_deg", std::to_string(latitude_deg));
      meta->set("hinge1_axis", "0 0 1");
      meta->set("hinge2_axis", "1 0 0");
    }
    return out;
  }
};

/// 2 % scale, 1 deg misalignment, 0.5 % cross-coupling, 2 deg error of the +90 stop.
inline est::CalibMatrices planted_matrices() {
  est::CalibMatrices m;
  const Eigen::Vector3d hinge[2] = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()};
  for (int i = 0; i < 2; ++i) {
    const double sgn = i == 0 ? 1.0 : -1.0;
    Eigen::Matrix3d K;
    K << 0, 0.005, -0.005, 0.005 * sgn, 0, 0.005, -0.005, 0.005, 0;
    const Eigen::Matrix3d C = Eigen::Vector3d(1.02, 0.98, 1.0 + 0.02 * sgn).asDiagonal() *
                              (Eigen::Matrix3d::Identity() + K) *
                              geo::rot_about_axis_deg(Eigen::Vector3d(1, sgn, 0.5).normalized(), 1.0).transpose();
    for (int p = 0; p < 2; ++p) {
      const double stop = est::position_deg(p) + (p == est::kPosPlus90 ? 2.0 * sgn : 0.0);
      m.M(i, p) = (C * geo::rot_about_axis_deg(hinge[i], stop).transpose()).inverse();
    }
  }
  return m;
}


/// A closed-form dynamic run: the box turns with a smooth, non-zero-mean rate; the platforms
/// follow the paper's flip sequence (+,+) (+,-) (-,-) (-,+) with standstill_s rests and 1 s flips
/// (plat*_deg empty while flipping); sensors read y = M^-1 w + b + noise at their end stop.
inline std::vector<Sample> dynamic_log(const est::CalibMatrices& M, const Eigen::Vector3d bias_dps[2],
                                       double duration_s, double sigma_dps, std::uint64_t seed,
                                       log::Metadata* meta, double standstill_s = 20.0) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  const double fs = 100.0, dt = 1.0 / fs, lat = 52.0 * kRadPerDeg;
  const Eigen::Vector3d w_earth_enu = kEarthRateRadps * kDegPerRad * Eigen::Vector3d(0, std::cos(lat), std::sin(lat));
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  static const int kSign1[4] = {+1, +1, -1, -1}, kSign2[4] = {+1, -1, -1, +1};
  std::vector<Sample> out;
  for (long k = 0; k * dt < duration_s; ++k) {
    const double t = k * dt;
    const double kPiX2 = 2.0 * kPi;
    // the box rate relative to ENU, deg/s: a smooth function of time
    const auto rate_rel_dps = [kPiX2](double u) {
      return Eigen::Vector3d(10.0 + 20.0 * std::sin(kPiX2 * u / 37.0), -8.0 + 15.0 * std::sin(kPiX2 * u / 23.0),
                             12.0 * std::cos(kPiX2 * u / 53.0));
    };
    const Eigen::Vector3d w_rel = rate_rel_dps(t);
    const Eigen::Vector3d w_box = w_rel + q.conjugate() * w_earth_enu;
    const long phase = static_cast<long>(t / (standstill_s + 1.0));
    const bool flipping = t - static_cast<double>(phase) * (standstill_s + 1.0) >= standstill_s;
    Sample s;
    s.t_s = t;
    s.set_q_enu_from_body(q);
    const int sign[2] = {kSign1[phase % 4], kSign2[phase % 4]};
    Eigen::Vector3d y[2];
    for (int i = 0; i < 2; ++i) {
      const int p = sign[i] > 0 ? est::kPosPlus90 : est::kPosMinus90;
      y[i] = est::sensor_output_dps(M.M(i, p), w_box, bias_dps[i]);
      for (int j = 0; j < 3; ++j) y[i][j] += sigma_dps * n01(rng);
    }
    s.gyro1_dps = y[0];
    s.gyro2_dps = y[1];
    // the moving platform is the one whose sign changes at the next phase
    const int next1 = kSign1[(phase + 1) % 4], next2 = kSign2[(phase + 1) % 4];
    s.plat1_deg = flipping && next1 != sign[0] ? kNaN : 90.0 * sign[0];
    s.plat2_deg = flipping && next2 != sign[1] ? kNaN : 90.0 * sign[1];
    s.true_bias1_dps = bias_dps[0];
    s.true_bias2_dps = bias_dps[1];
    s.true_rate_body_dps = w_box;
    out.push_back(s);
    // attitude in the Earth-fixed ENU frame: the continuous motion to the next sample (midpoint
    // substeps, so ref_q is the true attitude at each sample time, not a rectangle-rule lag)
    constexpr int kSub = 20;
    for (int j = 0; j < kSub; ++j) {
      const Eigen::Vector3d w = rate_rel_dps(t + (j + 0.5) * dt / kSub);
      q = q * Eigen::Quaterniond(Eigen::AngleAxisd(w.norm() * kRadPerDeg * dt / kSub, w.normalized()));
    }
    q.normalize();
  }
  if (meta) {
    meta->set("sample_rate_hz", "100");
    meta->set("latitude_deg", "52");
    meta->set("hinge1_axis", "0 0 1");
    meta->set("hinge2_axis", "1 0 0");
  }
  return out;
}

}  // namespace driftless::calib::testing
