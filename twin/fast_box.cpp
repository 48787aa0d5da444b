// Closed-form kinematic source for sweeps (see fast_box.hpp for what it leaves out).
#include "twin/fast_box.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "estimator/geometry.hpp"
#include "estimator/log_metadata.hpp"
#include "estimator/random.hpp"
#include "twin/simulator.hpp"

namespace driftless::twin {
FastBox::FastBox(const Scenario& scenario)
    : sc_((scenario.validate(), scenario)),
      motion_(make_motion(sc_.motion, sc_.duration_s, sc_.seed, sc_.base_dir)),
      flips_(sc_.flip_schedule, sc_.model.box),
      sensor1_(sc_.model.sensor1, sc_.sample_rate_hz,
               rnd::stream_seed(sc_.seed, rnd::Stream::kSensor1)),
      sensor2_(sc_.model.sensor2, sc_.sample_rate_hz,
               rnd::stream_seed(sc_.seed, rnd::Stream::kSensor2)),
      delay_(sc_.model.time_offset_s, sc_.sample_rate_hz),
      earth_enu_radps_(geo::earth_rate_enu_radps(sc_.latitude_deg)),
      a1_(sc_.model.box.hinge_axis(1)),
      a2_(sc_.model.box.hinge_axis(2)),
      total_(sc_.total_samples()) {
  for (int i = 0; i < 2; ++i) angle_rad_[i] = flips_.initial_angle_rad(i + 1);
}

log::Metadata FastBox::metadata() const {
  log::LogInfo info;
  info.sample_rate_hz = sc_.sample_rate_hz;
  info.latitude_deg = sc_.latitude_deg;
  info.hinge1_axis = a1_;
  info.hinge2_axis = a2_;
  info.source = "fast (closed-form kinematics, twin/fast_box.hpp)";
  info.scenario = sc_.name;
  info.seed = sc_.seed;
  log::Metadata m;
  log::write_log_info(m, info);
  return m;
}

bool FastBox::next(Sample& out) {
  if (k_ >= total_) return false;
  const double dt = 1.0 / sc_.sample_rate_hz;
  const double t = static_cast<double>(k_) * dt;
  // platforms: the motor reference, clipped at the true stops (ideal servo, no ringing)
  flips_.update(t, Eigen::Vector2d(rate_radps_[0], rate_radps_[1]));
  for (int i = 0; i < 2; ++i) {
    const double lo = sc_.model.box.stop_rad(i + 1, -1), hi = sc_.model.box.stop_rad(i + 1, +1);
    const double ang = std::clamp(flips_.reference_rad(i + 1), lo, hi);
    rate_radps_[i] = k_ == 0 ? 0.0 : (ang - angle_rad_[i]) / dt;
    angle_rad_[i] = ang;
  }

  const MotionState ms = motion_->at(t);
  const Eigen::Matrix3d R_body_from_enu = ms.q_enu_from_body.toRotationMatrix().transpose();
  const Eigen::Vector3d w_body = ms.w_body_radps + R_body_from_enu * earth_enu_radps_;
  const Eigen::Vector3d f_body =
      R_body_from_enu * (ms.a_enu_mps2 + Eigen::Vector3d(0, 0, kStandardGravityMps2));
  w_body_dps_ = w_body * kDegPerRad;

  const Eigen::Matrix3d R1 = geo::rot_about_axis_rad(a1_, angle_rad_[0]);
  const Eigen::Matrix3d R2 = geo::rot_about_axis_rad(a2_, angle_rad_[1]);
  // eq. (1) truth: R_i^T x + thetadot_i a_i (the hinge axis is the same in sensor axes)
  Eigen::Vector3d w[2] = {R1.transpose() * w_body + rate_radps_[0] * a1_, R2.transpose() * w_body + rate_radps_[1] * a2_};
  Eigen::Vector3d f[2] = {R1.transpose() * f_body, R2.transpose() * f_body};
  delay_.apply(w, f);  // model.time_offset_s: the truth the sensors sampled
  const SensorTruth t1{t, w[0], f[0]};
  const SensorTruth t2{t, w[1], f[1]};
  const SensorReading r1 = sensor1_.step(t1);
  const SensorReading r2 = sensor2_.step(t2);

  out = Sample{};
  out.t_s = t;
  out.gyro1_dps = r1.gyro_radps * kDegPerRad;
  out.gyro2_dps = r2.gyro_radps * kDegPerRad;
  out.accel1_mps2 = r1.accel_mps2;
  out.accel2_mps2 = r2.accel_mps2;
  out.temp1_c = r1.temp_c;
  out.temp2_c = r2.temp_c;
  out.true_bias1_dps = r1.bias_radps * kDegPerRad;
  out.true_bias2_dps = r2.bias_radps * kDegPerRad;
  out.true_rate_body_dps = w_body_dps_;
  out.true_plat1_deg = angle_rad_[0] * kDegPerRad;
  out.true_plat2_deg = angle_rad_[1] * kDegPerRad;
  const bool encoder = sc_.platform_readback == PlatformReadback::encoder;
  out.plat1_deg = encoder ? out.true_plat1_deg
                          : (flips_.moving(1) ? kNaN : flips_.commanded_rest_rad(1) * kDegPerRad);
  out.plat2_deg = encoder ? out.true_plat2_deg
                          : (flips_.moving(2) ? kNaN : flips_.commanded_rest_rad(2) * kDegPerRad);
  out.set_q_enu_from_body(ms.q_enu_from_body);
  out.ref_p_enu_m = ms.p_enu_m;
  ++k_;
  return true;
}

}  // namespace driftless::twin
