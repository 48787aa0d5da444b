#include "estimator/attitude.hpp"

#include "estimator/geometry.hpp"

#include <algorithm>
#include <cmath>

namespace driftless::est {

AttitudeIntegrator::AttitudeIntegrator(double latitude_deg) {
  w_ie_enu_ = geo::earth_rate_enu_radps(std::isfinite(latitude_deg) ? latitude_deg : 0.0);
}

void AttitudeIntegrator::reset(const Eigen::Quaterniond& q, double t_s) {
  q_ = q.normalized();
  t_ = t_s;
  last_rate_radps_.setConstant(kNaN);  // no rate yet: the first interval uses its end rate
  initialized_ = true;
}

void AttitudeIntegrator::step(double t_s, const Eigen::Vector3d& rate_body_dps) {
  if (!initialized_) return;
  const Eigen::Vector3d w_now = rate_body_dps.allFinite() ? Eigen::Vector3d(rate_body_dps * kRadPerDeg)
                                                          : last_rate_radps_;
  if (!w_now.allFinite()) {  // no rate seen yet: nothing to integrate with
    t_ = t_s;
    return;
  }
  const Eigen::Vector3d w_prev = last_rate_radps_.allFinite() ? last_rate_radps_ : w_now;
  const double dt = t_s - t_;
  if (dt > 0.0) {
    // w_nb^b = w_ib^b - C_bn w_ie^n: the box's rate relative to the (Earth-fixed) ENU frame
    const Eigen::Vector3d w_ib = 0.5 * (w_now + w_prev);
    const Eigen::Vector3d w_nb = w_ib - q_.conjugate() * w_ie_enu_;
    const Eigen::Vector3d phi = w_nb * dt;
    q_ = (q_ * geo::quat_from_rotvec(phi)).normalized();
  }
  t_ = t_s;
  last_rate_radps_ = w_now;
}

Eigen::Vector3d roll_pitch_yaw_deg(const Eigen::Quaterniond& q) {
  const Eigen::Matrix3d R = q.normalized().toRotationMatrix();
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double roll = std::atan2(R(2, 1), R(2, 2));
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  return Eigen::Vector3d(roll, pitch, yaw) * kDegPerRad;
}

void ErrorAccumulator::add(const Eigen::Quaterniond& q_est, const Eigen::Quaterniond& q_ref) {
  const Eigen::Quaterniond err = q_est.normalized() * q_ref.normalized().conjugate();
  // after the first call: the error's increment in ENU; the starting error (normally none: both
  // start at ref) counts in full
  acc_rad_ += geo::rotvec_rad(started_ ? Eigen::Quaterniond(err * last_err_.conjugate()) : err);
  started_ = true;
  last_err_ = err;
}

AttitudeError attitude_error(const Eigen::Quaterniond& q_est, const Eigen::Quaterniond& q_ref) {
  // the error rotation in ENU, E = q_est q_ref^-1, as a rotation vector: its Up part is the
  // heading error, its North/East parts the tilt (roll/pitch for a box facing north); unlike
  // Euler-angle differences this has no singularity at +-90 deg pitch
  const Eigen::Vector3d phi = geo::rotvec_rad(q_est.normalized() * q_ref.normalized().conjugate());
  AttitudeError e;
  e.roll_deg = phi.y() * kDegPerRad;     // about North
  e.pitch_deg = phi.x() * kDegPerRad;    // about East
  e.heading_deg = phi.z() * kDegPerRad;  // about Up
  e.angle_deg = phi.norm() * kDegPerRad;
  return e;
}

double drift_deg_per_h(const std::vector<double>& t_s, const std::vector<double>& err_deg) {
  if (t_s.size() < 2 || t_s.size() != err_deg.size()) return kNaN;
  // straight-line fit with intercept: the error left by the filter's start-up does not count
  const double n = double(t_s.size());
  double mt = 0.0, me = 0.0;
  for (std::size_t i = 0; i < t_s.size(); ++i) {
    mt += t_s[i];
    me += err_deg[i];
  }
  mt /= n;
  me /= n;
  double stt = 0.0, ste = 0.0;
  for (std::size_t i = 0; i < t_s.size(); ++i) {
    stt += (t_s[i] - mt) * (t_s[i] - mt);
    ste += (t_s[i] - mt) * (err_deg[i] - me);
  }
  return stt > 0.0 ? 3600.0 * ste / stt : kNaN;
}

}  // namespace driftless::est
