// Time for the live loop: the wall clock on hardware, a virtual clock in tests and emulated runs.
// Emulators and drivers take a Clock so an emulated run is deterministic and needs no sleeping.
#pragma once

#include <atomic>

namespace driftless::hil {

/// A monotonic clock in seconds that can be slept on.
class Clock {
 public:
  virtual ~Clock() = default;
  /// Seconds since an arbitrary epoch; never decreases.
  virtual double now_s() const = 0;
  /// Returns once now_s() >= t_s (at once when already past).
  virtual void sleep_until(double t_s) = 0;
  void sleep_for(double dt_s) { sleep_until(now_s() + dt_s); }
};

/// std::chrono::steady_clock; sleep_until really sleeps.
class SteadyClock final : public Clock {
 public:
  double now_s() const override;
  void sleep_until(double t_s) override;
};

/// Simulated time: sleep_until jumps forward at once. Thread-safe reads.
class VirtualClock final : public Clock {
 public:
  explicit VirtualClock(double start_s = 0.0) : t_s_(start_s) {}
  double now_s() const override { return t_s_.load(std::memory_order_acquire); }
  void sleep_until(double t_s) override;
  /// Moves time forward by dt_s (e.g. the duration of a bus transaction).
  void advance(double dt_s) { sleep_until(now_s() + dt_s); }

 private:
  std::atomic<double> t_s_;
};

}  // namespace driftless::hil
