// Drives the hardware emulators with the twin's sensor model (twin/sensor/sensor_model.hpp):
// the truth of a box at rest with EmulatedMotors turning the platforms goes through
// twin::SensorModel per sensor, so emulated MPU-6050s show the effect catalogue's errors.
#pragma once

#include <array>
#include <memory>

#include "hil_bridge/imu_generator.hpp"
#include "twin/sensor/sensor_model.hpp"

namespace driftless::hil {

class SensorModelGenerator final : public ImuGenerator {
 public:
  /// `box`: latitude and hinge axes (its bias/noise fields are not used: the sensor model's are).
  SensorModelGenerator(const twin::SensorParams& sensor1, const twin::SensorParams& sensor2,
                       double sample_rate_hz, std::uint64_t seed, BoxAtRestGenerator::Params box,
                       const EmulatedMotors* motors);
  ImuReading sample(int sensor, double t_s) override;

 private:
  BoxAtRestGenerator::Params box_;
  const EmulatedMotors* motors_;
  std::array<std::unique_ptr<twin::SensorModel>, 2> models_;
};

}  // namespace driftless::hil
