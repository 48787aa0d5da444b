// Raw MPU-6050 counts -> Sample fields, shared by the I2C and serial sources. A gyro axis at
// either end of the int16 range is clipped, not measured: it becomes NaN (an empty field in the
// log) and the SaturationTracker reports where saturation starts and ends.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "estimator/sample.hpp"
#include "hil_bridge/i2c/mpu6050_regs.hpp"

namespace driftless::hil {

/// Fills sensor `sensor` (0 or 1) of `s` from raw counts. Returns the saturated gyro axes (bit a = axis a).
int fill_from_raw(int sensor, const mpu6050::RawRecord& r, int gyro_fs_sel, int accel_fs_sel, Sample& s);

/// Turns per-sample saturation masks into start / end messages.
class SaturationTracker {
 public:
  /// Returns a message when sensor's saturation state changes (else empty).
  std::string update(int sensor, int mask, int gyro_fs_sel);

 private:
  std::array<int, 2> mask_{0, 0};
  std::array<std::uint64_t, 2> count_{0, 0};
};

}  // namespace driftless::hil
