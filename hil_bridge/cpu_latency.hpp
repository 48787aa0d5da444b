// Keeping the processors out of deep idle states while a live session runs. On an idle machine a
// sleeping core enters an idle state whose exit adds its latency to every wake-up of the polling
// driver (under a hypervisor's haltpoll a halted virtual CPU waits for the host to inject the timer:
// tens of microseconds, measured as p99 111-163 us on an idle machine against 76 us on a busy
// one). Linux's PM QoS interface (/dev/cpu_dma_latency, Documentation/power/pm_qos_interface.rst)
// lets a process ask for a bound on that exit latency for as long as it keeps the file open; real-
// time measurement tools (cyclictest) ask for 0 us. The cost is power: idle cores poll instead of
// halting while the request is held.
#pragma once

#include <cstdint>
#include <string>

namespace driftless::hil {

class CpuLatencyRequest {
 public:
  /// Asks for at most `max_exit_latency_us` of idle-state exit latency on every CPU, held until
  /// destruction. Never throws: when the request cannot be made (no such file, no permission),
  /// held() is false and why_not() says why.
  explicit CpuLatencyRequest(std::int32_t max_exit_latency_us = 0);
  ~CpuLatencyRequest();
  CpuLatencyRequest(const CpuLatencyRequest&) = delete;
  CpuLatencyRequest& operator=(const CpuLatencyRequest&) = delete;

  bool held() const { return fd_ >= 0; }
  const std::string& why_not() const { return why_not_; }
  std::int32_t max_exit_latency_us() const { return max_exit_latency_us_; }

 private:
  int fd_ = -1;
  std::int32_t max_exit_latency_us_;
  std::string why_not_;
};

}  // namespace driftless::hil
