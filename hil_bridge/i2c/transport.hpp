// The I2C transport: combined write-then-read transactions on a bus, as Linux i2c-dev's
// I2C_RDWR ioctl does them. Two implementations: LinuxI2c (i2c/linux_i2c.hpp) and
// EmulatedI2cBus (i2c/emulated_bus.hpp), which hosts register-level MPU6050 emulators.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace driftless::hil {

/// Outcome of one I2C transaction.
enum class I2cResult {
  kOk,
  kNack,       // no acknowledge (device absent or busy): ENXIO / EREMOTEIO
  kIoError,    // EIO and other bus errors (arbitration lost, glitch)
  kTimeout,    // the adapter timed out (ETIMEDOUT): clock stretched or bus stuck
  kNoAdapter,  // the bus itself vanished (ENODEV; USB adapter unplugged) or is not open
};

const char* to_string(I2cResult r);

/// A bus with 7-bit addressed devices.
class I2cTransport {
 public:
  virtual ~I2cTransport() = default;
  /// Bus name for messages, e.g. "/dev/i2c-1".
  virtual std::string name() const = 0;
  /// Opens the bus. Returns an empty string on success, else an actionable message.
  virtual std::string open() { return {}; }
  /// One transaction: write `wr` (e.g. a register address), repeated start, read `nrd` bytes.
  /// nwr or nrd may be 0 (plain read or plain write). Never throws.
  virtual I2cResult transfer(std::uint8_t addr, const std::uint8_t* wr, std::size_t nwr,
                             std::uint8_t* rd, std::size_t nrd) = 0;
  /// Closes and reopens the bus (after kNoAdapter). Returns false while it is still gone.
  virtual bool reopen() = 0;

  /// Register read: `n` bytes from `reg` on (auto-increment, as MPU6050 does).
  I2cResult read_regs(std::uint8_t addr, std::uint8_t reg, std::uint8_t* out, std::size_t n) {
    return transfer(addr, &reg, 1, out, n);
  }
  /// Register write of one byte.
  I2cResult write_reg(std::uint8_t addr, std::uint8_t reg, std::uint8_t value) {
    const std::uint8_t buf[2] = {reg, value};
    return transfer(addr, buf, 2, nullptr, 0);
  }
};

}  // namespace driftless::hil
