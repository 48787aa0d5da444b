// Strapdown attitude from the fused body rate (paper section 4): R_be integrated after removing
// the Earth rate, compared with the reference attitude (ref_q). Eigen + std only.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "estimator/sample.hpp"

namespace driftless::est {

/// Integrates q_enu_from_body from the inertial body rate (Earth rate included, box axes).
class AttitudeIntegrator {
 public:
  /// latitude_deg: for the Earth rate Omega (0, cos phi, sin phi) in ENU.
  explicit AttitudeIntegrator(double latitude_deg);
  /// Starts at attitude q (q_enu_from_body) at time t_s.
  void reset(const Eigen::Quaterniond& q_enu_from_body, double t_s);
  bool initialized() const { return initialized_; }
  /// Advances to t_s with the inertial body rate there (deg/s, box axes); the rate over the
  /// interval is the mean of the previous and this one. A NaN rate holds the last finite rate.
  void step(double t_s, const Eigen::Vector3d& rate_body_dps);
  const Eigen::Quaterniond& q_enu_from_body() const { return q_; }
  double t_s() const { return t_; }
  /// Earth rate in ENU, rad/s.
  const Eigen::Vector3d& earth_rate_enu_radps() const { return w_ie_enu_; }

 private:
  Eigen::Vector3d w_ie_enu_;
  Eigen::Quaterniond q_ = Eigen::Quaterniond::Identity();
  Eigen::Vector3d last_rate_radps_ = Eigen::Vector3d::Zero();
  double t_ = kNaN;
  bool initialized_ = false;
};

/// Attitude error of an estimate against the reference, deg: the error rotation
/// q_est q_ref^-1 in ENU as a rotation vector, split into roll (about North), pitch (about East)
/// and heading (about Up) -- the usual INS tilt/heading errors, exact for a box facing north --
/// and its total angle.
struct AttitudeError {
  double roll_deg = 0.0;
  double pitch_deg = 0.0;
  double heading_deg = 0.0;
  double angle_deg = 0.0;
};
/// No comparison was made (no ref_q, never locked, withheld): every angle unknown, so that
/// summary.json says null, not a perfect 0
inline constexpr AttitudeError kAttitudeErrorUnknown{kNaN, kNaN, kNaN, kNaN};
AttitudeError attitude_error(const Eigen::Quaterniond& q_est, const Eigen::Quaterniond& q_ref);

/// Accumulated (unwrapped) attitude error: the sum of the error rotation's increments between
/// successive comparisons, q_err,k q_err,k-1^-1 in ENU, as one rotation vector. Unlike the error
/// angle, which never exceeds 180 deg and folds back once an uncorrected gyro has turned the
/// estimate half a turn, its norm keeps growing with the drift, so a drift rate fitted to it
/// stays true for hours of a biased raw gyro. While the error is small both agree to first order.
/// Each increment must stay below 180 deg (rate error times comparison spacing).
class ErrorAccumulator {
 public:
  /// Adds the comparison q_est against q_ref; the first call only sets the starting error.
  void add(const Eigen::Quaterniond& q_est, const Eigen::Quaterniond& q_ref);
  /// |accumulated error rotation vector| in deg (0 before two comparisons).
  double angle_deg() const { return acc_rad_.norm() * kDegPerRad; }
  bool started() const { return started_; }

 private:
  Eigen::Quaterniond last_err_ = Eigen::Quaterniond::Identity();
  Eigen::Vector3d acc_rad_ = Eigen::Vector3d::Zero();
  bool started_ = false;
};

/// Roll, pitch, yaw (deg) of q_enu_from_body, ZYX convention.
Eigen::Vector3d roll_pitch_yaw_deg(const Eigen::Quaterniond& q_enu_from_body);

/// Drift rate in deg/h: slope of a least-squares line (with intercept) through err(t) (deg vs s).
double drift_deg_per_h(const std::vector<double>& t_s, const std::vector<double>& err_deg);

}  // namespace driftless::est
