// Two MPU-6050s on one I2C bus (AD0 low = 0x68: sensor 1, AD0 high = 0x69: sensor 2), read
// through their FIFOs (default) or by 0x3B..0x48 bursts paced by DATA_RDY. Works on any
// I2cTransport: LinuxI2c for hardware, EmulatedI2cBus for tests and `--source emu-i2c`.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <string>

#include "hil_bridge/clock.hpp"
#include "hil_bridge/i2c/mpu6050_regs.hpp"
#include "hil_bridge/i2c/transport.hpp"
#include "hil_bridge/raw_sample.hpp"
#include "hil_bridge/source.hpp"

namespace driftless::hil {

/// Settings of the I2C source (docs/hil.md).
struct I2cSourceParams {
  std::uint8_t address1 = mpu6050::kAddrAd0Low;   // sensor 1
  std::uint8_t address2 = mpu6050::kAddrAd0High;  // sensor 2
  double sample_rate_hz = 100.0;  // must be gyro output rate / (1 + SMPLRT_DIV), Hz
  int dlpf_cfg = 3;               // CONFIG DLPF_CFG 0..6 (3: 42 Hz gyro bandwidth, 1 kHz output)
  int gyro_fs_sel = 0;            // GYRO_CONFIG FS_SEL 0..3: +-250, 500, 1000, 2000 deg/s
  int accel_fs_sel = 0;           // ACCEL_CONFIG AFS_SEL 0..3: +-2, 4, 8, 16 g
  bool use_fifo = true;           // FIFO reads; false: bursts paced by DATA_RDY
  double poll_timeout_s = 0.1;    // read() waits at most this long for a sample, s
  double stall_timeout_s = 0.5;   // no data for this long: look at the device (reset? asleep?), s
  int max_consecutive_errors = 5; // failed transactions in a row before the device counts as gone
  int max_records_per_read = 18;  // FIFO records per I2C read (18 x 14 = 252 bytes)
  double reset_wait_s = 0.1;      // wait after DEVICE_RESET (datasheet: 100 ms), s
  // polling: wake this long after a sample is due on the host clock (the chip's clock runs
  // slightly apart), and when the FIFO has nothing yet, poll again this long later
  double wake_margin_s = 2e-5;    // s
  double repoll_interval_s = 2e-5; // s

  /// SMPLRT_DIV for the sample rate (throws if the rate is not reachable exactly).
  int smplrt_div() const;
  void validate() const;
};

class I2cSource final : public SampleSource {
 public:
  /// `bus` and `clock` must outlive the source.
  I2cSource(I2cTransport& bus, Clock& clock, I2cSourceParams p);
  ~I2cSource() override { deactivate(); }

  std::string name() const override { return "i2c:" + bus_.name(); }
  double sample_rate_hz() const override { return p_.sample_rate_hz; }
  std::uint32_t fields() const override { return kFieldAccel | kFieldTemp; }
  bool knows_platforms() const override { return false; }
  /// Host-clock time (Clock seconds) at which the sample stamped t_s was due: for latency figures.
  double host_time_of(double t_s) const { return t0_host_s_ + t_s + 1.0 / p_.sample_rate_hz; }

  Status configure() override;
  Status activate() override;
  ReadStatus read(Sample& out) override;
  Status reconnect() override;
  void deactivate() override;

  std::uint64_t samples_read() const { return samples_; }

 private:
  Status init_chip(std::uint8_t addr);
  ReadStatus poll_fifo();
  ReadStatus poll_burst();
  ReadStatus bus_error(I2cResult r, std::uint8_t addr, const char* what);
  ReadStatus reset_fifos(const std::string& why);
  void check_stall();
  void emit(const mpu6050::RawRecord& r1, const mpu6050::RawRecord& r2);
  /// Index of the sample the device produces next, from the host clock.
  std::uint64_t expected_index() const;
  double t_of(std::uint64_t n) const { return static_cast<double>(n) / p_.sample_rate_hz; }

  I2cTransport& bus_;
  Clock& clock_;
  I2cSourceParams p_;
  bool active_ = false;
  bool gone_ = false;
  double t0_host_s_ = 0.0;     // host time of sample index 0
  std::uint64_t n_next_ = 0;   // index of the next sample
  double last_data_host_s_ = 0.0;
  int errors_in_row_ = 0;
  std::deque<Sample> ready_;
  std::uint64_t samples_ = 0;
  SaturationTracker saturation_;
};

}  // namespace driftless::hil
