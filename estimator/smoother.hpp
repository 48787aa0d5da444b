// Offline fixed-interval smoother (Rauch-Tung-Striebel) over the DriftLess filter's updates, for
// `driftless estimate --smooth` (docs/estimator.md section 6.3). The forward pass hands it, at every
// accepted update, the state and covariance just before and just after the gain; they go to a
// temporary binary file, so memory does not grow with the log. smooth() runs backwards over them
// and leaves one record per interval between two updates; at() then gives the smoothed state at any
// time of a second forward pass. Between two updates the smoothed state is linear in time (a random
// walk bias seen at both ends: the sigma-weighted interpolation), so the corrected rates have no
// steps. Eigen + std only.
#pragma once

#include <array>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <vector>

#include "estimator/filter.hpp"

namespace driftless::est {

/// The smoothed state at one time: the whole state (states without variance at their fixed
/// values), its bias referred to the temperatures temp_ref_c, and each state's variance.
struct SmoothedState {
  StateVector x = StateVector::Zero();
  StateVector var = StateVector::Zero();
  std::array<double, 2> temp_ref_c{kNaN, kNaN};  // degC
};

/// Fixed-size records of doubles in an unnamed temporary file (removed when closed).
class TempRecords {
 public:
  TempRecords();
  /// Sets the record size (doubles); before the first write.
  void set_size(std::size_t doubles) { size_ = doubles; }
  std::size_t size() const { return size_; }
  /// Writes/reads record `index`. Throw std::runtime_error saying what failed (a full disk).
  void write(std::uint64_t index, const double* rec);
  void read(std::uint64_t index, double* rec);

 private:
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file_;
  std::size_t size_ = 0;
  std::int64_t position_ = -1;  // the record index the file position is at (-1: unknown)
};

class FixedIntervalSmoother : public UpdateObserver {
 public:
  /// q_dps2_per_s: the bias random-walk rate (EstimatorConfig::q_dps2_per_s()), used after the
  /// last update.
  explicit FixedIntervalSmoother(double q_dps2_per_s);

  void on_accepted_update(const UpdateSnapshot& u) override;
  /// The backward pass; call once, after the forward pass ended. Throws std::runtime_error when a
  /// prior covariance cannot be factored (not expected: it is positive definite on its states).
  void smooth();
  /// The smoothed state at `t_s`; t_s must not decrease from call to call (the intervals are read
  /// forward). Before the first update: the smoothed state there; after the last: the filtered
  /// one, its bias variance growing by q per second.
  const SmoothedState& at(double t_s);
  std::uint64_t updates() const { return knots_; }
  bool smoothed() const { return smoothed_; }

 private:
  void read_interval(std::uint64_t k);

  double q_dps2_per_s_;
  std::vector<Eigen::Index> active_;  // states with variance (fixed at the first update)
  TempRecords knots_file_, intervals_file_;
  std::uint64_t knots_ = 0;
  bool smoothed_ = false;
  // the interval in use by at()
  std::int64_t current_ = -1;
  double t_k_ = kNaN, span_s_ = kNaN, t_next_ = kNaN;
  StateVector u_ = StateVector::Zero(), v_ = StateVector::Zero();
  StateVector a_ = StateVector::Zero(), b_ = StateVector::Zero(), c_ = StateVector::Zero();
  SmoothedState out_;
  std::vector<double> buf_;
};

/// --smooth's second pass: the filter again (same configuration and box) over the same samples,
/// each sample's outputs computed with the smoothed state at its time (the filter's standstill
/// tracking and updates run as in the first pass, so positions and status are the same); `out`
/// receives every sample and its outputs. `next` fills the next sample, false at the end.
void smoothed_outputs(const EstimatorConfig& cfg, const BoxGeometry& box, const std::function<bool(Sample&)>& next,
                      FixedIntervalSmoother& sm, const std::function<void(const Sample&, const SampleOutput&)>& out);

}  // namespace driftless::est
