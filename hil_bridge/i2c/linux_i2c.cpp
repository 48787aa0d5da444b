#include "hil_bridge/i2c/linux_i2c.hpp"

#include <fcntl.h>
#include <linux/i2c-dev.h>
#include <linux/i2c.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace driftless::hil {

const char* to_string(I2cResult r) {
  switch (r) {
    case I2cResult::kOk: return "ok";
    case I2cResult::kNack: return "NACK";
    case I2cResult::kIoError: return "I/O error";
    case I2cResult::kTimeout: return "time-out";
    case I2cResult::kNoAdapter: return "adapter gone";
  }
  return "?";
}

LinuxI2c::LinuxI2c(std::string device_path, int timeout_ms, int retries)
    : path_(std::move(device_path)), timeout_ms_(timeout_ms), retries_(retries) {}

LinuxI2c::~LinuxI2c() { close(); }

std::string LinuxI2c::open() {
  close();
  fd_ = ::open(path_.c_str(), O_RDWR | O_CLOEXEC);
  if (fd_ < 0) {
    const int err = errno;
    if (err == ENOENT) {
      return path_ + ": no such I2C device (load the i2c-dev module: 'modprobe i2c-dev'; list buses "
                     "with 'ls /dev/i2c-*')";
    }
    if (err == EACCES) {
      return path_ + ": permission denied (add yourself to the 'i2c' group or run with access to the node)";
    }
    return path_ + ": cannot open: " + std::strerror(err);
  }
  unsigned long funcs = 0;
  if (::ioctl(fd_, I2C_FUNCS, &funcs) < 0 || (funcs & I2C_FUNC_I2C) == 0) {
    close();
    return path_ + ": not an I2C adapter with plain I2C transfers (I2C_FUNCS lacks I2C_FUNC_I2C)";
  }
  // the adapter time-out is in units of 10 ms
  ::ioctl(fd_, I2C_TIMEOUT, static_cast<unsigned long>((timeout_ms_ + 9) / 10));
  ::ioctl(fd_, I2C_RETRIES, static_cast<unsigned long>(retries_));
  return {};
}

void LinuxI2c::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

I2cResult LinuxI2c::transfer(std::uint8_t addr, const std::uint8_t* wr, std::size_t nwr,
                             std::uint8_t* rd, std::size_t nrd) {
  if (fd_ < 0) return I2cResult::kNoAdapter;
  i2c_msg msgs[2];
  int n = 0;
  if (nwr > 0) {
    msgs[n++] = i2c_msg{addr, 0, static_cast<__u16>(nwr), const_cast<__u8*>(wr)};
  }
  if (nrd > 0) {
    msgs[n++] = i2c_msg{addr, I2C_M_RD, static_cast<__u16>(nrd), rd};
  }
  if (n == 0) return I2cResult::kOk;
  i2c_rdwr_ioctl_data set{msgs, static_cast<__u32>(n)};
  if (::ioctl(fd_, I2C_RDWR, &set) == n) return I2cResult::kOk;
  switch (errno) {
    case ENXIO:
    case EREMOTEIO: return I2cResult::kNack;
    case ETIMEDOUT: return I2cResult::kTimeout;
    case ENODEV:
    case ENOENT:
    case EBADF: return I2cResult::kNoAdapter;
    default: return I2cResult::kIoError;
  }
}

bool LinuxI2c::reopen() { return open().empty(); }

}  // namespace driftless::hil
