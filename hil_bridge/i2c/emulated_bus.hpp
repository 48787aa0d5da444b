// An emulated I2C bus hosting MPU-6050 emulators, with fault injection for tests: NACKs, EIO and
// time-outs on chosen transactions, devices unplugged for a while (they come back in their
// power-on state), and the whole adapter vanishing. Each transaction costs bus time on a
// VirtualClock (400 kHz, 9 bits per byte) so emulated runs are deterministic.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "hil_bridge/clock.hpp"
#include "hil_bridge/i2c/mpu6050_emulator.hpp"
#include "hil_bridge/i2c/transport.hpp"

namespace driftless::hil {

class EmulatedI2cBus final : public I2cTransport {
 public:
  /// `virtual_clock`: when given, each transaction advances it by its duration on the wire.
  explicit EmulatedI2cBus(const Clock& clock, VirtualClock* virtual_clock = nullptr,
                          double bus_hz = 400e3);

  /// Puts a device on the bus at a 7-bit address (not owned).
  void attach(std::uint8_t addr, Mpu6050Emulator* device);

  // fault injection
  /// The next `count` transactions to `addr` (0: any) fail with `result` (kNack, kIoError, kTimeout).
  /// A time-out also costs `timeout_s` of clock time.
  void fail_next(std::uint8_t addr, int count, I2cResult result, double timeout_s = 0.02);
  /// `addr` does not answer (NACK) for t in [from_s, to_s); it comes back power-on reset.
  void unplug(std::uint8_t addr, double from_s, double to_s);
  /// The adapter itself is gone for t in [from_s, to_s): transfers give kNoAdapter, reopen() fails.
  void unplug_adapter(double from_s, double to_s);

  std::string name() const override { return "emulated-i2c"; }
  I2cResult transfer(std::uint8_t addr, const std::uint8_t* wr, std::size_t nwr, std::uint8_t* rd,
                     std::size_t nrd) override;
  bool reopen() override;

  std::uint64_t transactions() const { return transactions_; }
  std::uint64_t failed_transactions() const { return failed_; }

 private:
  struct Pending {
    std::uint8_t addr;
    int count;
    I2cResult result;
    double timeout_s;
  };
  struct Window {
    std::uint8_t addr;  // 0: the adapter
    double from_s, to_s;
    bool reset_done = false;
  };
  const Clock& clock_;
  VirtualClock* vclock_;
  double bus_hz_;
  std::map<std::uint8_t, Mpu6050Emulator*> devices_;
  std::vector<Pending> pending_;
  std::vector<Window> unplugged_;
  bool adapter_lost_ = false;  // latched until reopen() succeeds
  std::uint64_t transactions_ = 0;
  std::uint64_t failed_ = 0;
};

}  // namespace driftless::hil
