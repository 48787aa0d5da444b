// The closed-form steady state (steady_state.hpp) of a run, from its first updates' schedule:
// known after two eq. (5) cycles, long before the filter settles, so a lock level the filter
// cannot reach with this q, update interval and noise is named up front (HealthMonitor; finding
// lock_unreachable, docs/estimator.md section 6.5). Eigen + std only.
#pragma once

#include <cstdint>

#include "estimator/filter.hpp"
#include "estimator/steady_state.hpp"

namespace driftless::est {

/// Collects the first updates' intervals, windows and sample counts, then predicts once.
class SteadyStateWatch {
 public:
  /// The updates the schedule is measured over: two cycles of four intervals.
  static constexpr std::uint64_t kScheduleUpdates = 9;
  explicit SteadyStateWatch(double lock_sigma_dps) : lock_sigma_dps_(lock_sigma_dps) {}
  /// Every update (accepted or not), with the filter after it.
  void on_update(const UpdateRecord& rec, const DriftlessFilter& filter);
  const SteadyStatePrediction& prediction() const { return pred_; }

 private:
  void predict(const DriftlessFilter& filter, double t_s);

  double lock_sigma_dps_;
  std::uint64_t n_ = 0;
  double t_first_s_ = kNaN, t_last_s_ = kNaN;
  double sum_window_s_ = 0.0, sum_samples_ = 0.0;
  SteadyStatePrediction pred_;
};

}  // namespace driftless::est
