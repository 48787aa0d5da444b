// The fast closed-form kinematic path for sweeps: the same Scenario, Motion, flip schedule and
// sensor model as the Simulator, without MuJoCo. The platforms follow their motor reference
// exactly (clipped at the true end stops, stop-angle errors included), so there is no servo lag,
// end-stop ringing or motor overshoot: studies of those use the full twin (runner: twin). The
// sensors' sampling offset (model.time_offset_s) is applied as in the Simulator.
// Sensor i's frame is Rot(hinge_i, platform angle) in box axes, eq. (1):
//   y_i = R_i^T x + thetadot_i a_i + b_i + n_i (plus every effect of the sensor model).
#pragma once

#include <cstdint>
#include <memory>

#include <Eigen/Core>

#include "estimator/log.hpp"
#include "estimator/sample.hpp"
#include "twin/flip_schedule.hpp"
#include "twin/motion.hpp"
#include "twin/scenario.hpp"
#include "twin/sensor/sensor_model.hpp"
#include "twin/truth_delay.hpp"

namespace driftless::twin {

/// A closed-form source of Samples (true_ columns included) for one scenario.
class FastBox {
 public:
  /// Validates the scenario and builds motion, schedule and the two sensor models.
  explicit FastBox(const Scenario& scenario);
  /// Fills the next sample; false once the duration is reached.
  bool next(Sample& out);
  /// Log metadata (sample rate, latitude, hinge axes, seed, source: fast).
  log::Metadata metadata() const;
  std::uint64_t total_samples() const { return total_; }
  /// Box rate in box axes (Earth rate included) of the last sample, deg/s.
  const Eigen::Vector3d& rate_body_dps() const { return w_body_dps_; }

 private:
  Scenario sc_;
  std::unique_ptr<Motion> motion_;
  FlipController flips_;
  SensorModel sensor1_, sensor2_;
  TruthDelay delay_;  // model.time_offset_s
  Eigen::Vector3d earth_enu_radps_;
  Eigen::Vector3d a1_, a2_;
  std::uint64_t total_ = 0, k_ = 0;
  double angle_rad_[2] = {0, 0};
  double rate_radps_[2] = {0, 0};
  Eigen::Vector3d w_body_dps_ = Eigen::Vector3d::Zero();
};

}  // namespace driftless::twin
