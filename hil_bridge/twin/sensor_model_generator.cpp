#include "hil_bridge/twin/sensor_model_generator.hpp"

#include <cmath>

#include <Eigen/Geometry>

namespace driftless::hil {

SensorModelGenerator::SensorModelGenerator(const twin::SensorParams& sensor1, const twin::SensorParams& sensor2,
                                           double sample_rate_hz, std::uint64_t seed,
                                           BoxAtRestGenerator::Params box, const EmulatedMotors* motors)
    : box_(std::move(box)), motors_(motors) {
  box_.hinge1_axis.normalize();
  box_.hinge2_axis.normalize();
  // one seed stream per sensor, so the two never share draws
  models_[0] = std::make_unique<twin::SensorModel>(sensor1, sample_rate_hz, seed * 2 + 1);
  models_[1] = std::make_unique<twin::SensorModel>(sensor2, sample_rate_hz, seed * 2 + 2);
}

ImuReading SensorModelGenerator::sample(int sensor, double t_s) {
  const Eigen::Vector3d& axis = sensor == 0 ? box_.hinge1_axis : box_.hinge2_axis;
  const double angle_deg = motors_ ? motors_->angle_deg(sensor + 1, t_s) : 90.0;
  const double rate_dps = motors_ ? motors_->rate_dps(sensor + 1, t_s) : 0.0;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(angle_deg * kRadPerDeg, axis).toRotationMatrix();
  // box at identity attitude in ENU: Earth rate Omega (0, cos phi, sin phi), gravity reaction up
  const double phi = box_.latitude_deg * kRadPerDeg;
  Eigen::Vector3d w_body_radps = kEarthRateRadps * Eigen::Vector3d(0.0, std::cos(phi), std::sin(phi));
  if (box_.extra_rate_dps) w_body_radps += box_.extra_rate_dps(t_s) * kRadPerDeg;
  twin::SensorTruth truth;
  truth.t_s = t_s;
  truth.w_radps = R.transpose() * w_body_radps + rate_dps * kRadPerDeg * axis;
  truth.f_mps2 = R.transpose() * Eigen::Vector3d(0.0, 0.0, kStandardGravityMps2);
  const twin::SensorReading r = models_[static_cast<std::size_t>(sensor)]->step(truth);
  ImuReading out;
  out.gyro_dps = r.gyro_radps * kDegPerRad;
  out.accel_mps2 = r.accel_mps2;
  out.temp_c = r.temp_c;
  out.true_bias_dps = r.bias_radps * kDegPerRad;
  return out;
}

}  // namespace driftless::hil
