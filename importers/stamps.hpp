// Timestamps of a stream made by someone else: the step learned from the data, gaps, stamps that go
// backwards or repeat, and bursty stamps that record arrival rather than sampling (docs/import.md).
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

namespace driftless::importers {

/// What the stamps of a stream did.
struct StampReport {
  std::uint64_t rows = 0;
  double first_t_s = std::numeric_limits<double>::quiet_NaN();
  double last_t_s = std::numeric_limits<double>::quiet_NaN();
  double step_s = std::numeric_limits<double>::quiet_NaN();  // s, the learned regular step (median)
  bool bursty = false;              // median step < half the mean step: arrival stamps, not sampling
  std::uint64_t gaps = 0;           // steps longer than 1.5 regular steps (regular stamps only)
  std::uint64_t missing = 0;        // samples the gaps stand for (step / regular step - 1, rounded)
  double largest_step_s = 0.0;      // s
  std::uint64_t largest_step_loc = 0, first_gap_loc = 0;
  std::uint64_t backwards = 0, repeated = 0;  // stamps below / equal to the previous one
  std::uint64_t first_backwards_loc = 0, first_repeated_loc = 0;
  std::uint64_t regular_steps = 0;  // steps neither gaps, nor backwards, nor repeats
  double regular_sum_s = 0.0;       // s, their sum
  /// The mean rate over the record, (rows - 1) / span, Hz (NaN with fewer than 2 rows).
  double mean_rate_hz() const;
  /// The rate of the regular steps, regular_steps / regular_sum_s, Hz: the sampling rate when the
  /// stamps jitter (a loop timed in whole ms: steps of 10, 10, 11 ms is 96.8 Hz, not the median's
  /// 100 Hz), gaps left out. NaN without regular steps.
  double regular_rate_hz() const;
  /// The sentences a user reads: "3 gaps (120 samples missing), the largest 1.2 s at line 4410".
  std::vector<std::string> describe(const std::string& loc_word) const;
};

/// Watches the stamps of a stream as rows arrive.
class StampMonitor {
 public:
  /// How the step into a stamp looks.
  enum class Step { kFirst, kRegular, kGap, kBackwards, kRepeated };
  /// Learns the regular step (median) and burstiness from the first stamps of the stream.
  void learn(std::span<const double> first_stamps_s);
  /// Classifies the step into t_s (rows in order; `loc` locates it for messages).
  Step push(double t_s, std::uint64_t loc);
  const StampReport& report() const { return r_; }

 private:
  StampReport r_;
  double mean_step_s_ = 0.0;
  double prev_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace driftless::importers
