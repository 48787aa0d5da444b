// A register-level MPU-6050: the registers the driver uses, big-endian int16 data scaled by
// FS_SEL / AFS_SEL and clipped at full scale, sample timing from SMPLRT_DIV and DLPF_CFG (rate
// and group delay), the 1024-byte FIFO with overflow (oldest bytes lost, FIFO_OFLOW_INT set),
// temperature raw = (T - 36.53) * 340, WHO_AM_I = 0x68, power-on reset state (asleep).
// What it measures comes from an ImuGenerator; time comes from a Clock.
#pragma once

#include <array>
#include <cstdint>
#include <deque>

#include "hil_bridge/clock.hpp"
#include "hil_bridge/i2c/mpu6050_regs.hpp"
#include "hil_bridge/imu_generator.hpp"

namespace driftless::hil {

class Mpu6050Emulator {
 public:
  /// `sensor`: 0 or 1, which generator channel this chip reads.
  Mpu6050Emulator(int sensor, ImuGenerator& generator, const Clock& clock);

  /// I2C write: first byte sets the register pointer, the rest are written with auto-increment.
  void i2c_write(const std::uint8_t* data, std::size_t n);
  /// I2C read of n bytes from the register pointer (FIFO_R_W does not increment).
  void i2c_read(std::uint8_t* out, std::size_t n);
  /// Back to the power-on state (a brown-out, or unplugged and plugged back).
  void power_on_reset();

  // inspection for tests
  std::uint8_t reg(std::uint8_t r) const { return regs_[r]; }
  std::size_t fifo_bytes() const { return fifo_.size(); }
  std::uint64_t samples_generated() const { return samples_; }
  std::uint64_t overflow_bytes_lost() const { return overflow_lost_; }
  /// Sample rate, Hz, as the registers set it now.
  double sample_rate_hz() const;
  /// Group delay of the gyro DLPF, s (the sample at tick t shows the input at t - delay).
  double gyro_delay_s() const;
  /// Source time of sample k since wake (for tests): wake time + (k+1) / rate.
  double tick_time_s(std::uint64_t k) const { return t_anchor_s_ + static_cast<double>(k + 1 - k_anchor_) / sample_rate_hz(); }
  /// The reading that went into the most recent sample (for tests).
  const ImuReading& last_reading() const { return last_; }

 private:
  void advance();  // produce every sample due by clock.now_s()
  void produce(double t_tick_s);
  void write_reg(std::uint8_t r, std::uint8_t v);
  std::uint8_t read_reg(std::uint8_t r);
  bool awake() const { return (regs_[mpu6050::kPwrMgmt1] & mpu6050::kPwrSleep) == 0; }
  void reanchor();

  int sensor_;
  ImuGenerator& gen_;
  const Clock& clock_;
  std::array<std::uint8_t, 128> regs_{};
  std::uint8_t ptr_ = 0;
  std::deque<std::uint8_t> fifo_;
  std::uint64_t samples_ = 0;
  std::uint64_t overflow_lost_ = 0;
  // sample k is due at t_anchor_s_ + (k + 1 - k_anchor_) / rate
  double t_anchor_s_ = 0.0;
  std::uint64_t k_anchor_ = 0;
  std::uint16_t fifo_count_latch_ = 0;
  ImuReading last_;
};

}  // namespace driftless::hil
