#include "hil_bridge/imu_generator.hpp"

#include "estimator/geometry.hpp"
#include "estimator/random.hpp"

#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

namespace driftless::hil {

void BoxAtRestGenerator::Params::validate() const {
  if (!(std::abs(latitude_deg) <= 90.0)) throw std::invalid_argument("generator: latitude_deg must be in [-90, 90]");
  if (!(hinge1_axis.norm() > 0.5 && hinge2_axis.norm() > 0.5)) {
    throw std::invalid_argument("generator: hinge axes must be non-zero vectors");
  }
  if (!(noise_density_dps_rthz >= 0.0)) throw std::invalid_argument("generator: noise_density_dps_rthz must be >= 0");
  if (!(bias_walk_dps_rts >= 0.0)) throw std::invalid_argument("generator: bias_walk_dps_rts must be >= 0");
  if (!(sample_rate_hz > 0.0)) throw std::invalid_argument("generator: sample_rate_hz must be > 0 Hz");
}

BoxAtRestGenerator::BoxAtRestGenerator(Params p, const EmulatedMotors* motors)
    : p_(std::move(p)), motors_(motors) {
  p_.validate();
  p_.hinge1_axis.normalize();
  p_.hinge2_axis.normalize();
  // the simulator's named streams, one per sensor, so the two sensors never share noise
  rng_[0] = rnd::NormalStream(p_.seed, rnd::Stream::kSensor1);
  rng_[1] = rnd::NormalStream(p_.seed, rnd::Stream::kSensor2);
}

Eigen::Vector3d BoxAtRestGenerator::body_rate_dps(double t_s) const {
  // box at identity attitude in ENU: the Earth rate
  Eigen::Vector3d w = geo::earth_rate_enu_radps(p_.latitude_deg) * kDegPerRad;
  if (p_.extra_rate_dps) w += p_.extra_rate_dps(t_s);
  return w;
}

ImuReading BoxAtRestGenerator::sample(int sensor, double t_s) {
  const auto i = static_cast<std::size_t>(sensor);
  const Eigen::Vector3d& axis = sensor == 0 ? p_.hinge1_axis : p_.hinge2_axis;
  const double angle_deg = motors_ ? motors_->angle_deg(sensor + 1, t_s) : 90.0;
  const double rate_dps = motors_ ? motors_->rate_dps(sensor + 1, t_s) : 0.0;
  const Eigen::Matrix3d R = geo::rot_about_axis_deg(axis, angle_deg);

  auto& n01 = rng_[i];
  // bias random walk, integrated over the time since this sensor's last sample
  if (!std::isnan(last_t_[i]) && t_s > last_t_[i] && p_.bias_walk_dps_rts > 0.0) {
    const double s = p_.bias_walk_dps_rts * std::sqrt(t_s - last_t_[i]);
    const double wx = n01(), wy = n01(), wz = n01();  // in this order (argument order is unspecified)
    walk_dps_[i] += s * Eigen::Vector3d(wx, wy, wz);
  }
  last_t_[i] = t_s;
  const double sigma = p_.noise_density_dps_rthz * std::sqrt(p_.sample_rate_hz);

  ImuReading r;
  r.true_bias_dps = p_.bias_dps[i] + walk_dps_[i];
  // y_i = R_i^T w_body + th_dot_i a_i + b_i + n_i
  const double nx = n01(), ny = n01(), nz = n01();
  r.gyro_dps = R.transpose() * body_rate_dps(t_s) + rate_dps * axis + r.true_bias_dps +
               sigma * Eigen::Vector3d(nx, ny, nz);
  // at rest the specific force points up (ENU z), box at identity attitude
  r.accel_mps2 = R.transpose() * Eigen::Vector3d(0.0, 0.0, kStandardGravityMps2);
  r.temp_c = p_.temp_c;
  return r;
}

}  // namespace driftless::hil
