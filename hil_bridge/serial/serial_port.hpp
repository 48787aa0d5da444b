// A tty in raw mode through termios (USB-serial adapters, pseudo-terminals).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace driftless::hil {

class SerialPort {
 public:
  enum class Io { kOk, kTimeout, kHangup };
  SerialPort() = default;
  ~SerialPort() { close(); }
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  /// Opens `path` raw, 8N1, no flow control, at `baud` (bit/s). Returns "" on success, else an
  /// actionable message naming the path.
  std::string open(const std::string& path, int baud);
  void close();
  bool is_open() const { return fd_ >= 0; }
  /// Waits up to timeout_s for bytes and reads what is there into buf (n = bytes read).
  Io read(std::uint8_t* buf, std::size_t cap, double timeout_s, std::size_t& n);
  /// Writes all bytes (waits up to timeout_s for room).
  Io write(const std::uint8_t* buf, std::size_t n, double timeout_s);

 private:
  int fd_ = -1;
};

/// The termios speed constant for a baud rate; 0 when the rate is not a standard one.
unsigned baud_constant(int baud);

}  // namespace driftless::hil
