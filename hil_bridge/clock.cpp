#include "hil_bridge/clock.hpp"

#include <chrono>
#include <thread>

namespace driftless::hil {

double SteadyClock::now_s() const {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}

void SteadyClock::sleep_until(double t_s) {
  using namespace std::chrono;
  const auto target = steady_clock::time_point(duration_cast<steady_clock::duration>(duration<double>(t_s)));
  std::this_thread::sleep_until(target);
}

void VirtualClock::sleep_until(double t_s) {
  double cur = t_s_.load(std::memory_order_acquire);
  while (t_s > cur && !t_s_.compare_exchange_weak(cur, t_s, std::memory_order_acq_rel)) {
  }
}

}  // namespace driftless::hil
