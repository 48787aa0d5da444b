// One time step of a dual-gyro box, in file units (deg/s, deg, s, m/s^2, degC).
// This is the currency between sources (twin, replay, hardware), the log, and the estimator.
#pragma once

#include <cstdint>
#include <limits>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace driftless {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Earth rotation rate (WGS-84), rad/s.
inline constexpr double kEarthRateRadps = 7.292115e-5;
inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kDegPerRad = 180.0 / kPi;
inline constexpr double kRadPerDeg = kPi / 180.0;
inline constexpr double kStandardGravityMps2 = 9.80665;

/// A time gap is an interval longer than max(kGapMinS, kGapIntervals x the sample interval), the
/// sample interval being 1 / sample_rate_hz (or, without a stated rate, the shortest interval seen).
/// The log reader reports gaps by it; the estimator withholds what a gap leaves unknown.
inline constexpr double kGapMinS = 1.0;
inline constexpr double kGapIntervals = 10.0;
/// The gap threshold, s, for a sample interval `interval_s` (NaN: unknown, kGapMinS).
inline double gap_threshold_s(double interval_s) {
  return interval_s * kGapIntervals > kGapMinS ? interval_s * kGapIntervals : kGapMinS;
}

/// Optional column groups a log (or a stream) carries. Required columns are always present.
enum SampleField : std::uint32_t {
  kFieldAccel = 1u << 0,      // accel1_x..accel2_z, m/s^2
  kFieldTemp = 1u << 1,       // temp1, temp2, degC
  kFieldRefQ = 1u << 2,       // ref_qw..ref_qz, q_enu_from_body, scalar first
  kFieldRefP = 1u << 3,       // ref_px..ref_pz, m, ENU
  kFieldTrueBias = 1u << 4,   // true_bias1_x..true_bias2_z, deg/s
  kFieldTrueRate = 1u << 5,   // true_rate_x..z, body inertial rate in body axes, deg/s
  kFieldTruePlat = 1u << 6,   // true_plat1_deg, true_plat2_deg
  // layout, not a column group: the single-sensor log form (docs/log-format.md): one gyro triad,
  // no gyro2_*, plat2_deg or sensor-2 columns; gyro2_dps and plat2_deg stay NaN
  kLayoutSingleSensor = 1u << 7,
};

/// One sample. Missing values are NaN (e.g. plat*_deg while a hardware platform moves).
struct Sample {
  double t_s = kNaN;
  Eigen::Vector3d gyro1_dps = Eigen::Vector3d::Constant(kNaN);  // sensor 1 output, sensor-1 frame
  Eigen::Vector3d gyro2_dps = Eigen::Vector3d::Constant(kNaN);  // sensor 2 output, sensor-2 frame
  double plat1_deg = kNaN;  // platform angle as the system knows it
  double plat2_deg = kNaN;
  Eigen::Vector4d ref_q_wxyz = Eigen::Vector4d::Constant(kNaN);  // q_enu_from_body, scalar first
  Eigen::Vector3d ref_p_enu_m = Eigen::Vector3d::Constant(kNaN);
  Eigen::Vector3d accel1_mps2 = Eigen::Vector3d::Constant(kNaN);
  Eigen::Vector3d accel2_mps2 = Eigen::Vector3d::Constant(kNaN);
  double temp1_c = kNaN;
  double temp2_c = kNaN;
  // truth, simulated logs only; estimator and diagnosis code never read these
  Eigen::Vector3d true_bias1_dps = Eigen::Vector3d::Constant(kNaN);
  Eigen::Vector3d true_bias2_dps = Eigen::Vector3d::Constant(kNaN);
  Eigen::Vector3d true_rate_body_dps = Eigen::Vector3d::Constant(kNaN);
  double true_plat1_deg = kNaN;
  double true_plat2_deg = kNaN;

  /// The reference attitude as a unit quaternion (q_enu_from_body).
  Eigen::Quaterniond q_enu_from_body() const {
    return Eigen::Quaterniond(ref_q_wxyz[0], ref_q_wxyz[1], ref_q_wxyz[2], ref_q_wxyz[3]);
  }
  void set_q_enu_from_body(const Eigen::Quaterniond& q) {
    ref_q_wxyz = Eigen::Vector4d(q.w(), q.x(), q.y(), q.z());
  }
  /// True when both gyro triads hold finite numbers.
  bool gyros_finite() const { return gyro1_dps.allFinite() && gyro2_dps.allFinite(); }
};

}  // namespace driftless
