#include "hil_bridge/twin/sensor_model_generator.hpp"

#include "estimator/geometry.hpp"
#include "estimator/random.hpp"

#include <cmath>

#include <Eigen/Geometry>

namespace driftless::hil {

SensorModelGenerator::SensorModelGenerator(const twin::SensorParams& sensor1, const twin::SensorParams& sensor2,
                                           double sample_rate_hz, std::uint64_t seed,
                                           BoxAtRestGenerator::Params box, const EmulatedMotors* motors)
    : box_(std::move(box)), motors_(motors) {
  box_.hinge1_axis.normalize();
  box_.hinge2_axis.normalize();
  // the simulator's named streams: the same seed emulates the same two units as `simulate`
  models_[0] = std::make_unique<twin::SensorModel>(sensor1, sample_rate_hz, rnd::stream_seed(seed, rnd::Stream::kSensor1));
  models_[1] = std::make_unique<twin::SensorModel>(sensor2, sample_rate_hz, rnd::stream_seed(seed, rnd::Stream::kSensor2));
}

ImuReading SensorModelGenerator::sample(int sensor, double t_s) {
  const Eigen::Vector3d& axis = sensor == 0 ? box_.hinge1_axis : box_.hinge2_axis;
  const double angle_deg = motors_ ? motors_->angle_deg(sensor + 1, t_s) : 90.0;
  const double rate_dps = motors_ ? motors_->rate_dps(sensor + 1, t_s) : 0.0;
  const Eigen::Matrix3d R = geo::rot_about_axis_deg(axis, angle_deg);
  // box at identity attitude in ENU: Earth rate, gravity reaction up
  Eigen::Vector3d w_body_radps = geo::earth_rate_enu_radps(box_.latitude_deg);
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
