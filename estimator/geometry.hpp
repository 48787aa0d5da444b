// Geometry every folder shares, defined once: the rotation of a sensor platform about its hinge
// (eq. (1): R_i = Rot(a_i, theta_i)), the quaternion log map, the Earth rate, and the flip cycle of
// eq. (5) / Fig. 3. Eigen and std only (this header also runs on hardware). Frames: docs/model.md.
#pragma once

#include <array>
#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "estimator/sample.hpp"

namespace driftless::geo {

/// Rotation by `angle_rad` about `axis` (normalised here; a zero axis gives the identity):
/// R = exp(angle [a]x), e.g. R_box_from_sensor_i = Rot(a_i, theta_i) of eq. (1).
inline Eigen::Matrix3d rot_about_axis_rad(const Eigen::Vector3d& axis, double angle_rad) {
  const double n = axis.norm();
  if (!(n > 0.0)) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle_rad, axis / n).toRotationMatrix();
}

/// The same with the angle in degrees (platform angles are in deg in logs and configs).
inline Eigen::Matrix3d rot_about_axis_deg(const Eigen::Vector3d& axis, double angle_deg) {
  return rot_about_axis_rad(axis, angle_deg * kRadPerDeg);
}

/// Rotation vector (rad) of a unit quaternion, the shorter way round (angle in [0, pi]): the
/// quaternion log map, exact down to zero angle (atan2(s, w) / s keeps full precision).
/// Below an angle of about 2e-3 rad (|vec| < 2^-10 w: a rotation between two samples, the attitude
/// comparison's per-sample error increments) atan(x) / x comes from its series to x^6; the first
/// omitted term, x^8 / 9 < 1e-25, is far below rounding, so it equals the atan2 form to rounding.
inline Eigen::Vector3d rotvec_rad(Eigen::Quaterniond q) {
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const double s = q.vec().norm();
  if (!(s > 0.0)) return Eigen::Vector3d::Zero();
  if (s < 0x1p-10 * q.w()) {
    const double x = s / q.w(), x2 = x * x;
    return q.vec() * (2.0 / q.w() * (1.0 - x2 * (1.0 / 3.0 - x2 * (1.0 / 5.0 - x2 / 7.0))));
  }
  return q.vec() * (2.0 * std::atan2(s, q.w()) / s);
}

/// Rotation vector (rad) of a rotation matrix (angle in [0, pi]).
inline Eigen::Vector3d rotvec_rad(const Eigen::Matrix3d& R) { return rotvec_rad(Eigen::Quaterniond(R)); }

/// The unit quaternion of a rotation vector (rad): the exponential map, inverse of rotvec_rad.
/// Below a half angle h = |phi| / 2 of 2^-5 rad (a 100 Hz sample's turn at up to 358 deg/s: every
/// step of an attitude integration) cos h and sin(h) / h come from their series to h^10 and h^8;
/// the first omitted terms (h^12 / 12!, h^10 / 11!) are below 1e-22, so they equal sincos to
/// rounding at a fraction of its cost.
inline Eigen::Quaterniond quat_from_rotvec(const Eigen::Vector3d& phi_rad) {
  const double h2 = 0.25 * phi_rad.squaredNorm();
  if (!(h2 > 0.0)) return Eigen::Quaterniond::Identity();  // zero, or not a number
  if (h2 < 0x1p-10) {
    const double c = 1.0 - h2 / 2.0 * (1.0 - h2 / 12.0 * (1.0 - h2 / 30.0 * (1.0 - h2 / 56.0 * (1.0 - h2 / 90.0))));
    const double half_sinc = 0.5 * (1.0 - h2 / 6.0 * (1.0 - h2 / 20.0 * (1.0 - h2 / 42.0 * (1.0 - h2 / 72.0))));
    return Eigen::Quaterniond(c, half_sinc * phi_rad.x(), half_sinc * phi_rad.y(), half_sinc * phi_rad.z());
  }
  const double a = std::sqrt(4.0 * h2);
  return Eigen::Quaterniond(Eigen::AngleAxisd(a, phi_rad / a));
}

/// Earth rotation rate in local ENU axes at geodetic latitude `latitude_deg`, rad/s:
/// Omega (0, cos phi, sin phi) with Omega = kEarthRateRadps (WGS-84).
inline Eigen::Vector3d earth_rate_enu_radps(double latitude_deg) {
  const double phi = latitude_deg * kRadPerDeg;
  return kEarthRateRadps * Eigen::Vector3d(0.0, std::cos(phi), std::sin(phi));
}

/// Derivative of earth_rate_enu_radps with respect to latitude, rad/s per rad:
/// Omega (0, -sin phi, cos phi) (a latitude error's regressor).
inline Eigen::Vector3d earth_rate_enu_dlat_radps_per_rad(double latitude_deg) {
  const double phi = latitude_deg * kRadPerDeg;
  return kEarthRateRadps * Eigen::Vector3d(0.0, -std::sin(phi), std::cos(phi));
}

/// One position of the flip cycle: the sign (+1 / -1) of each platform's rest angle.
struct FlipSigns {
  int plat1;
  int plat2;
};

/// eq. (5) / Fig. 3: the positions k mod 4 = 0..3 are (+,+) -> (+,-) -> (-,-) -> (-,+); one
/// platform moves per step: platform 2, then 1, then 2, then 1. Every flip schedule (the twin's
/// servos, the HIL motors, the filter's paper mode, the fast path) follows this one table.
inline constexpr std::array<FlipSigns, 4> kFlipCycle{{{+1, +1}, {+1, -1}, {-1, -1}, {-1, +1}}};

/// Index 0..3 in kFlipCycle of the position with these signs (a sign >= 0 counts as +).
inline int flip_cycle_index(double plat1_sign, double plat2_sign) {
  const bool s1 = plat1_sign >= 0.0, s2 = plat2_sign >= 0.0;
  if (s1) return s2 ? 0 : 1;
  return s2 ? 3 : 2;
}

/// kFlipCycle[k mod 4] for any integer k (negative k included).
inline FlipSigns flip_cycle_at(long long k) { return kFlipCycle[static_cast<std::size_t>(((k % 4) + 4) % 4)]; }

/// The platform (1 or 2) that moves from cycle position k to k + 1.
inline int flip_cycle_mover(long long k) { return flip_cycle_at(k).plat1 != flip_cycle_at(k + 1).plat1 ? 1 : 2; }

}  // namespace driftless::geo
