// What the emulated sensors measure: a generator of physical gyro/accel/temperature readings for
// sensor 1 and 2, called once per emulated sample in time order. BoxAtRestGenerator is the
// stand-alone one (a box at rest on the Earth, platforms driven by EmulatedMotors); the twin's
// sensor model drives the emulators through twin/sensor_model_generator.hpp when it is built.
#pragma once

#include <array>
#include <cstdint>
#include <functional>

#include <Eigen/Core>

#include "estimator/random.hpp"
#include "hil_bridge/motors.hpp"

namespace driftless::hil {

/// One sensor's physical output at one instant (file units).
struct ImuReading {
  Eigen::Vector3d gyro_dps = Eigen::Vector3d::Zero();     // sensor axes
  Eigen::Vector3d accel_mps2 = Eigen::Vector3d::Zero();   // specific force, sensor axes
  double temp_c = 25.0;
  Eigen::Vector3d true_bias_dps = Eigen::Vector3d::Zero();  // the bias in force (for tests)
};

/// Produces readings for sensor 1 (index 0) and sensor 2 (index 1). Calls for each sensor come
/// with non-decreasing t_s.
class ImuGenerator {
 public:
  virtual ~ImuGenerator() = default;
  virtual ImuReading sample(int sensor, double t_s) = 0;
};

/// A box at rest at a latitude, platforms turned by EmulatedMotors, each sensor with a constant
/// bias plus a seeded random walk and white noise. Ideal reading: y_i = R_i^T w_body + th_dot_i a_i
/// + b_i + n_i (docs/log-format.md frame convention), R_i = Rot(a_i, th_i).
class BoxAtRestGenerator final : public ImuGenerator {
 public:
  struct Params {
    double latitude_deg = 52.0;
    Eigen::Vector3d hinge1_axis = Eigen::Vector3d::UnitZ();  // box axes
    Eigen::Vector3d hinge2_axis = Eigen::Vector3d::UnitX();
    std::array<Eigen::Vector3d, 2> bias_dps{Eigen::Vector3d(0.5, -0.3, 0.8), Eigen::Vector3d(-0.6, 0.4, 0.2)};
    double noise_density_dps_rthz = 0.005;  // gyro white noise, deg/s/sqrt(Hz) (paper: 0.005)
    double bias_walk_dps_rts = 0.0;         // bias random walk, deg/s/sqrt(s)
    double sample_rate_hz = 100.0;          // for the discrete noise: sigma = density * sqrt(rate)
    double temp_c = 30.0;
    /// extra box rate in box axes, deg/s, as a function of time (e.g. a spike to saturate)
    std::function<Eigen::Vector3d(double)> extra_rate_dps;
    std::uint64_t seed = 1;
    void validate() const;
  };
  /// `motors` may be null (platforms fixed at +90 deg).
  BoxAtRestGenerator(Params p, const EmulatedMotors* motors);
  ImuReading sample(int sensor, double t_s) override;
  /// The box's inertial rate in box axes, deg/s (Earth rate, box at identity attitude in ENU).
  Eigen::Vector3d body_rate_dps(double t_s) const;

 private:
  Params p_;
  const EmulatedMotors* motors_;
  std::array<rnd::NormalStream, 2> rng_;
  std::array<Eigen::Vector3d, 2> walk_dps_{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  std::array<double, 2> last_t_{kNaN, kNaN};
};

}  // namespace driftless::hil
