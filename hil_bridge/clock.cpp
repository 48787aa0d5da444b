#include "hil_bridge/clock.hpp"

#include <chrono>
#include <thread>

#include <sys/prctl.h>

namespace driftless::hil {

double SteadyClock::now_s() const {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}

void SteadyClock::sleep_until(double t_s) {
  using namespace std::chrono;
  // Linux lets a sleeping thread wake up to its timer slack late (50 us by default), which alone is
  // half of a 1 kHz loop's latency budget: ask for 1 us, once per thread that sleeps on this clock
  thread_local const bool slack_set = prctl(PR_SET_TIMERSLACK, 1000UL, 0, 0, 0) == 0;
  (void)slack_set;
  const auto target = steady_clock::time_point(duration_cast<steady_clock::duration>(duration<double>(t_s)));
  std::this_thread::sleep_until(target);
}

void VirtualClock::sleep_until(double t_s) {
  double cur = t_s_.load(std::memory_order_acquire);
  while (t_s > cur && !t_s_.compare_exchange_weak(cur, t_s, std::memory_order_acq_rel)) {
  }
}

}  // namespace driftless::hil
