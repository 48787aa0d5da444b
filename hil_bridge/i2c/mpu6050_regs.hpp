// MPU-6050 register map (the subset the bridge uses) and the raw <-> register conversions,
// after the InvenSense "MPU-6000/MPU-6050 Register Map and Descriptions" rev. 4.2.
// Shared by the driver (i2c/mpu6050_driver) and the emulator (i2c/mpu6050_emulator). The
// datasheet's numbers (sensitivities, rates, DLPF, temperature law) live in estimator/mpu6050.hpp.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "estimator/mpu6050.hpp"

namespace driftless::hil::mpu6050 {

// the datasheet facts, under the register map's names
using driftless::mpu6050::accel_lsb_per_g;
using driftless::mpu6050::gyro_full_scale_dps;
using driftless::mpu6050::gyro_lsb_per_dps;
using driftless::mpu6050::gyro_output_rate_hz;
using driftless::mpu6050::sample_rate_hz;

// i2c addresses: AD0 low / high
inline constexpr std::uint8_t kAddrAd0Low = 0x68;
inline constexpr std::uint8_t kAddrAd0High = 0x69;

// registers
inline constexpr std::uint8_t kSmplrtDiv = 0x19;   // sample rate = gyro output rate / (1 + div)
inline constexpr std::uint8_t kConfig = 0x1A;      // EXT_SYNC_SET[5:3], DLPF_CFG[2:0]
inline constexpr std::uint8_t kGyroConfig = 0x1B;  // FS_SEL[4:3]
inline constexpr std::uint8_t kAccelConfig = 0x1C; // AFS_SEL[4:3]
inline constexpr std::uint8_t kFifoEn = 0x23;      // TEMP7 XG6 YG5 ZG4 ACCEL3
inline constexpr std::uint8_t kIntEnable = 0x38;   // FIFO_OFLOW_EN4 DATA_RDY_EN0
inline constexpr std::uint8_t kIntStatus = 0x3A;   // FIFO_OFLOW_INT4 DATA_RDY_INT0, cleared on read
inline constexpr std::uint8_t kAccelXoutH = 0x3B;  // 0x3B..0x40 accel, 0x41..0x42 temp, 0x43..0x48 gyro
inline constexpr std::uint8_t kTempOutH = 0x41;
inline constexpr std::uint8_t kGyroXoutH = 0x43;
inline constexpr std::uint8_t kGyroZoutL = 0x48;
inline constexpr std::uint8_t kUserCtrl = 0x6A;    // FIFO_EN6 FIFO_RESET2 SIG_COND_RESET0
inline constexpr std::uint8_t kPwrMgmt1 = 0x6B;    // DEVICE_RESET7 SLEEP6 CYCLE5 TEMP_DIS3 CLKSEL[2:0]
inline constexpr std::uint8_t kFifoCountH = 0x72;
inline constexpr std::uint8_t kFifoRw = 0x74;
inline constexpr std::uint8_t kWhoAmI = 0x75;      // reads 0x68 (bits 6:1), whatever AD0 is

// bits
inline constexpr std::uint8_t kWhoAmIValue = 0x68;
inline constexpr std::uint8_t kPwrDeviceReset = 0x80;
inline constexpr std::uint8_t kPwrSleep = 0x40;
inline constexpr std::uint8_t kClkPllXGyro = 0x01;  // CLKSEL = 1: PLL with X-axis gyro reference
inline constexpr std::uint8_t kPwrMgmt1Reset = 0x40;  // power-on value: asleep, internal 8 MHz
inline constexpr std::uint8_t kUserFifoEn = 0x40;
inline constexpr std::uint8_t kUserFifoReset = 0x04;
inline constexpr std::uint8_t kFifoEnTempGyroAccel = 0xF8;  // temp, xg, yg, zg, accel
inline constexpr std::uint8_t kIntFifoOflow = 0x10;
inline constexpr std::uint8_t kIntDataRdy = 0x01;

inline constexpr int kFifoSizeBytes = 1024;
// one FIFO record with accel + temp + gyro enabled: the same 14 bytes as a 0x3B..0x48 burst
inline constexpr int kRecordBytes = 14;

/// Gyro DLPF bandwidth, Hz, for DLPF_CFG 0..7 (7 is reserved: treated as off).
inline double gyro_dlpf_bandwidth_hz(int dlpf_cfg) {
  return driftless::mpu6050::kDlpfTable[static_cast<std::size_t>(driftless::mpu6050::effective_dlpf_cfg(dlpf_cfg))]
      .gyro_bandwidth_hz;
}
/// Gyro DLPF group delay, s, for DLPF_CFG 0..7 (7 is reserved: treated as off).
inline double gyro_dlpf_delay_s(int dlpf_cfg) {
  return driftless::mpu6050::kDlpfTable[static_cast<std::size_t>(driftless::mpu6050::effective_dlpf_cfg(dlpf_cfg))]
      .gyro_delay_s;
}

/// Temperature, degC, from the raw TEMP_OUT register.
inline double temp_c_from_raw(std::int16_t raw) {
  return raw / driftless::mpu6050::kTempLsbPerDegC + driftless::mpu6050::kTempOffsetDegC;
}

/// Rounds to the nearest int16, clipping at the ends (where a real ADC saturates).
inline std::int16_t clip_round_i16(double v) {
  if (!(v == v)) return 0;
  const double r = std::nearbyint(v);
  return static_cast<std::int16_t>(std::clamp(r, -32768.0, 32767.0));
}
/// The inverse of temp_c_from_raw, rounded and clipped to int16.
inline std::int16_t temp_raw_from_c(double temp_c) {
  return clip_round_i16((temp_c - driftless::mpu6050::kTempOffsetDegC) * driftless::mpu6050::kTempLsbPerDegC);
}

/// Big-endian int16 at p (the register order: high byte first).
inline std::int16_t be16(const std::uint8_t* p) {
  return static_cast<std::int16_t>(static_cast<std::uint16_t>(p[0] << 8 | p[1]));
}
inline void put_be16(std::uint8_t* p, std::int16_t v) {
  const auto u = static_cast<std::uint16_t>(v);
  p[0] = static_cast<std::uint8_t>(u >> 8);
  p[1] = static_cast<std::uint8_t>(u & 0xFF);
}
/// A raw value at either end of the int16 range: the axis is saturated.
inline bool is_saturated(std::int16_t raw) { return raw == 32767 || raw == -32768; }

/// One 14-byte record (registers 0x3B..0x48) decoded to raw counts.
struct RawRecord {
  std::array<std::int16_t, 3> accel{};
  std::int16_t temp = 0;
  std::array<std::int16_t, 3> gyro{};
};
inline RawRecord decode_record(const std::uint8_t* p) {
  RawRecord r;
  for (int i = 0; i < 3; ++i) r.accel[static_cast<std::size_t>(i)] = be16(p + 2 * i);
  r.temp = be16(p + 6);
  for (int i = 0; i < 3; ++i) r.gyro[static_cast<std::size_t>(i)] = be16(p + 8 + 2 * i);
  return r;
}
inline void encode_record(const RawRecord& r, std::uint8_t* p) {
  for (int i = 0; i < 3; ++i) put_be16(p + 2 * i, r.accel[static_cast<std::size_t>(i)]);
  put_be16(p + 6, r.temp);
  for (int i = 0; i < 3; ++i) put_be16(p + 8 + 2 * i, r.gyro[static_cast<std::size_t>(i)]);
}

}  // namespace driftless::hil::mpu6050
