// The attitude comparison of docs/estimator.md section 4 as a stream: three strapdown
// integrations (with DriftLess, bias fixed at the start, uncorrected) that start together from
// ref_q once the filter has locked on, and their errors against ref_q. `driftless estimate`
// (run_estimate) and the video overlay (renders/) both use it, so both say the same. Eigen + std.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "estimator/attitude.hpp"
#include "estimator/filter.hpp"

namespace driftless::est {

/// One attitude comparison point (deg), with and without the DriftLess correction.
struct AttitudePoint {
  double t_s = kNaN;
  AttitudeError corrected;  // with DriftLess: the filter's running bias estimate
  AttitudeError raw;        // no bias correction at all
  AttitudeError fixed;      // the bias estimate at the comparison's start, never updated again
  double corrected_accumulated_deg = kNaN;  // deg, unwrapped errors (ErrorAccumulator)
  double raw_accumulated_deg = kNaN;
  double fixed_accumulated_deg = kNaN;
};

/// Drift rates fitted to the unwrapped errors from the start, deg/h (NaN with < 2 points).
struct AttitudeDrifts {
  double corrected_deg_per_h = kNaN;
  double raw_deg_per_h = kNaN;
  double fixed_deg_per_h = kNaN;
};

/// True once the filter has locked on: it has made an update and every bias sigma is below
/// `start_sigma_dps` (deg/s); a start sigma <= 0 counts as locked from the first sample.
bool filter_locked(const DriftlessFilter& filter, double start_sigma_dps);

/// The three integrations of docs/estimator.md section 4 and their errors against ref_q.
class AttitudeComparison {
 public:
  /// latitude_deg: Earth rate (NaN: 0); start_sigma_dps: the lock level (filter_locked);
  /// interval_s: spacing of the comparison points, s.
  AttitudeComparison(double latitude_deg, double start_sigma_dps, double interval_s);

  /// Feeds a sample after `filter` has seen it. The comparison starts at the first finite ref_q
  /// once the filter is locked (then the filter's fixed bias is set to its estimate, for the
  /// 'bias fixed at start' rate of the next samples). Returns true, with `ap` filled, at a
  /// comparison point.
  bool push(const Sample& s, DriftlessFilter& filter, AttitudePoint& ap);

  bool started() const { return tracks_[kCorrected].att.initialized(); }
  /// When the comparison started (lock), s; NaN before.
  double start_s() const { return start_s_; }
  /// The bias the 'fixed' integration holds, deg/s (NaN before the start).
  const Vector6d& fixed_bias_dps() const { return fixed_bias_dps_; }
  std::size_t points() const { return t_.size(); }
  AttitudeDrifts drifts() const;

 private:
  void start(const Sample& s, DriftlessFilter& filter);
  void step(const Sample& s, const SampleOutput& out);
  bool compare(const Sample& s, AttitudePoint& ap);

  struct Track {
    AttitudeIntegrator att;
    ErrorAccumulator acc;
    std::vector<double> err_deg;
  };
  enum { kCorrected, kRaw, kFixed };
  std::array<Track, 3> tracks_;
  double start_sigma_dps_;
  double interval_s_;
  std::vector<double> t_;
  double next_t_ = kNaN;
  double start_s_ = kNaN;
  Vector6d fixed_bias_dps_ = Vector6d::Constant(kNaN);
};

}  // namespace driftless::est
