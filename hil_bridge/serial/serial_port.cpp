#include "hil_bridge/serial/serial_port.hpp"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>

namespace driftless::hil {

unsigned baud_constant(int baud) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 500000: return B500000;
    case 921600: return B921600;
    case 1000000: return B1000000;
    case 2000000: return B2000000;
    default: return 0;
  }
}

std::string SerialPort::open(const std::string& path, int baud) {
  close();
  const unsigned speed = baud_constant(baud);
  if (speed == 0) return "serial: " + std::to_string(baud) + " bit/s is not a standard baud rate (use 115200, 460800, 921600...)";
  fd_ = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) {
    const int err = errno;
    if (err == ENOENT) return path + ": no such serial device (is the box plugged in? list ttys with 'ls /dev/ttyACM* /dev/ttyUSB*')";
    if (err == EACCES) return path + ": permission denied (add yourself to the 'dialout' group)";
    return path + ": cannot open: " + std::strerror(err);
  }
  termios tio{};
  if (::tcgetattr(fd_, &tio) != 0) {
    const int err = errno;
    close();
    return path + ": not a terminal device (" + std::strerror(err) + ")";
  }
  ::cfmakeraw(&tio);
  tio.c_cflag |= CLOCAL | CREAD;
  tio.c_cflag &= ~static_cast<tcflag_t>(CRTSCTS | CSTOPB | PARENB);
  tio.c_cc[VMIN] = 0;
  tio.c_cc[VTIME] = 0;
  ::cfsetispeed(&tio, speed);
  ::cfsetospeed(&tio, speed);
  if (::tcsetattr(fd_, TCSANOW, &tio) != 0) {
    const int err = errno;
    close();
    return path + ": cannot set raw mode at " + std::to_string(baud) + " bit/s: " + std::strerror(err);
  }
  ::tcflush(fd_, TCIFLUSH);  // stale bytes from before we opened it
  return {};
}

void SerialPort::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

SerialPort::Io SerialPort::read(std::uint8_t* buf, std::size_t cap, double timeout_s, std::size_t& n) {
  n = 0;
  if (fd_ < 0) return Io::kHangup;
  pollfd p{fd_, POLLIN, 0};
  const int ms = static_cast<int>(std::ceil(timeout_s * 1000.0));
  const int r = ::poll(&p, 1, ms);
  if (r < 0) return errno == EINTR ? Io::kTimeout : Io::kHangup;
  if (r == 0) return Io::kTimeout;
  const ssize_t got = ::read(fd_, buf, cap);
  if (got > 0) {
    n = static_cast<std::size_t>(got);
    return Io::kOk;
  }
  if (got < 0 && (errno == EAGAIN || errno == EINTR)) return Io::kTimeout;
  // 0 bytes after POLLIN, EIO, or POLLHUP: the other end went away (USB unplugged, pty closed)
  return Io::kHangup;
}

SerialPort::Io SerialPort::write(const std::uint8_t* buf, std::size_t n, double timeout_s) {
  if (fd_ < 0) return Io::kHangup;
  std::size_t done = 0;
  while (done < n) {
    const ssize_t w = ::write(fd_, buf + done, n - done);
    if (w > 0) {
      done += static_cast<std::size_t>(w);
      continue;
    }
    if (w < 0 && errno != EAGAIN && errno != EINTR) return Io::kHangup;
    pollfd p{fd_, POLLOUT, 0};
    if (::poll(&p, 1, static_cast<int>(std::ceil(timeout_s * 1000.0))) <= 0) return Io::kTimeout;
  }
  return Io::kOk;
}

}  // namespace driftless::hil
