#include "hil_bridge/cpu_latency.hpp"

#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <unistd.h>

namespace driftless::hil {

namespace {
constexpr const char* kPmQosFile = "/dev/cpu_dma_latency";
}

CpuLatencyRequest::CpuLatencyRequest(std::int32_t max_exit_latency_us) : max_exit_latency_us_(max_exit_latency_us) {
  fd_ = ::open(kPmQosFile, O_WRONLY | O_CLOEXEC);
  if (fd_ < 0) {
    why_not_ = std::string(kPmQosFile) + ": " + std::strerror(errno);
    return;
  }
  // the interface takes the bound as a binary 32-bit value in microseconds
  if (::write(fd_, &max_exit_latency_us_, sizeof max_exit_latency_us_) != static_cast<ssize_t>(sizeof max_exit_latency_us_)) {
    why_not_ = std::string(kPmQosFile) + ": write: " + std::strerror(errno);
    ::close(fd_);
    fd_ = -1;
  }
}

CpuLatencyRequest::~CpuLatencyRequest() {
  if (fd_ >= 0) ::close(fd_);  // closing the file withdraws the request
}

}  // namespace driftless::hil
