// I2C through the Linux i2c-dev interface (/dev/i2c-N, I2C_RDWR ioctl).
#pragma once

#include <string>

#include "hil_bridge/i2c/transport.hpp"

namespace driftless::hil {

/// A Linux I2C adapter. Construction does not open it; open() does.
class LinuxI2c final : public I2cTransport {
 public:
  /// `timeout_ms`: adapter time-out per transaction (rounded to 10 ms); `retries`: adapter retries.
  explicit LinuxI2c(std::string device_path, int timeout_ms = 20, int retries = 1);
  ~LinuxI2c() override;
  LinuxI2c(const LinuxI2c&) = delete;
  LinuxI2c& operator=(const LinuxI2c&) = delete;

  /// Opens the device node. Returns an empty string on success, else an actionable message
  /// (missing node, no permission, not an I2C adapter).
  std::string open() override;
  void close();
  bool is_open() const { return fd_ >= 0; }

  std::string name() const override { return path_; }
  I2cResult transfer(std::uint8_t addr, const std::uint8_t* wr, std::size_t nwr, std::uint8_t* rd,
                     std::size_t nrd) override;
  bool reopen() override;

 private:
  std::string path_;
  int timeout_ms_;
  int retries_;
  int fd_ = -1;
};

}  // namespace driftless::hil
