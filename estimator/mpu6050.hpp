// InvenSense MPU-6050 datasheet facts, defined once: the DLPF_CFG table, the gyro and accelerometer
// sensitivities and full scales, the output rates, and the temperature register law. Used by the
// twin's sensor model (twin/sensor), the register and firmware emulators and the I2C driver
// (hil_bridge), and diagnosis. Sources: "MPU-6000/MPU-6050 Product Specification" rev. 3.4
// (section 6.1) and "Register Map and Descriptions" rev. 4.2 (registers 26, 27, 28, 65-66).
// std only (this header also runs on hardware).
#pragma once

#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>

namespace driftless::mpu6050 {

/// One row of the DLPF_CFG table (register 26): bandwidth (Hz) and group delay (s) of the
/// accelerometer and gyroscope paths.
struct DlpfSetting {
  double accel_bandwidth_hz, accel_delay_s, gyro_bandwidth_hz, gyro_delay_s;
};

/// DLPF_CFG 0..6 (7 is reserved).
inline constexpr std::array<DlpfSetting, 7> kDlpfTable{{
    {260.0, 0.0e-3, 256.0, 0.98e-3},
    {184.0, 2.0e-3, 188.0, 1.9e-3},
    {94.0, 3.0e-3, 98.0, 2.8e-3},
    {44.0, 4.9e-3, 42.0, 4.8e-3},
    {21.0, 8.5e-3, 20.0, 8.3e-3},
    {10.0, 13.8e-3, 10.0, 13.4e-3},
    {5.0, 19.0e-3, 5.0, 18.6e-3},
}};

/// The DLPF row for DLPF_CFG 0..6; throws std::invalid_argument otherwise (user input).
inline DlpfSetting dlpf_setting(int dlpf_cfg) {
  if (dlpf_cfg < 0 || dlpf_cfg > 6)
    throw std::invalid_argument("MPU6050 dlpf_cfg must be 0..6, got " + std::to_string(dlpf_cfg));
  return kDlpfTable[static_cast<std::size_t>(dlpf_cfg)];
}

/// What the chip does with DLPF_CFG 7 (reserved): the register map gives it no row; the chip
/// behaves as with the filter off (cfg 0). Hardware code maps 7 to 0 with this.
inline int effective_dlpf_cfg(int dlpf_cfg) { return (dlpf_cfg & 7) == 7 ? 0 : (dlpf_cfg & 7); }

/// Gyro sensitivity, LSB per deg/s, for FS_SEL 0..3 (+-250, 500, 1000, 2000 deg/s).
inline double gyro_lsb_per_dps(int fs_sel) {
  constexpr std::array<double, 4> k{131.0, 65.5, 32.8, 16.4};
  return k[static_cast<std::size_t>(fs_sel & 3)];
}
/// Gyro full scale, deg/s, for FS_SEL 0..3.
inline double gyro_full_scale_dps(int fs_sel) { return 250.0 * (1 << (fs_sel & 3)); }
/// Accelerometer sensitivity, LSB per g, for AFS_SEL 0..3 (+-2, 4, 8, 16 g).
inline double accel_lsb_per_g(int afs_sel) { return 16384.0 / (1 << (afs_sel & 3)); }

/// Gyroscope output rate before SMPLRT_DIV, Hz: 8 kHz with the DLPF off (DLPF_CFG 0 or 7), else 1 kHz.
inline double gyro_output_rate_hz(int dlpf_cfg) {
  return (dlpf_cfg & 7) == 0 || (dlpf_cfg & 7) == 7 ? 8000.0 : 1000.0;
}
/// Sample rate, Hz = gyro output rate / (1 + SMPLRT_DIV).
inline double sample_rate_hz(int dlpf_cfg, int smplrt_div) {
  return gyro_output_rate_hz(dlpf_cfg) / (1.0 + (smplrt_div & 0xFF));
}

/// Initial zero-rate output (ZRO) tolerance of the gyro at 25 degC, deg/s (product specification
/// section 6.1: +-20 deg/s): a unit's turn-on bias lies within it.
inline constexpr double kGyroZroToleranceDps = 20.0;
/// Temperature register law: T (degC) = TEMP_OUT / 340 + 36.53.
inline constexpr double kTempLsbPerDegC = 340.0;
inline constexpr double kTempOffsetDegC = 36.53;

}  // namespace driftless::mpu6050
