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
  bool realigned = false;  // the point where the integrations were re-aligned on ref_q (errors 0)
};

/// Drift rates, deg/h: fitted to the unwrapped errors from the start or re-alignment (NaN with
/// < 2 points), and net (the error angle at the last ref_q over the hours since the start or
/// re-alignment; NaN when that span is not positive or a requested re-alignment never came).
struct AttitudeDrifts {
  double corrected_deg_per_h = kNaN;
  double raw_deg_per_h = kNaN;
  double fixed_deg_per_h = kNaN;
  double net_corrected_deg_per_h = kNaN;
  double net_raw_deg_per_h = kNaN;
  double net_fixed_deg_per_h = kNaN;
};

/// What the 'fixed' integration holds from the comparison's start.
enum class FixedBiasFrom {
  kEstimate,  // the filter's estimate there: a box calibrated once (docs/estimator.md section 4)
  kTruth,     // the true_bias columns there: a perfect turn-on calibration (the sweep's baseline)
};

/// How the comparison runs (docs/estimator.md section 4, docs/sweep.md).
struct AttitudeComparisonOptions {
  // deg/s: start at the first ref_q once every bias sigma is below this; <= 0: the first ref_q
  double start_sigma_dps = 0.05;
  double interval_s = 1.0;  // s, spacing of the comparison points
  FixedBiasFrom fixed_bias_from = FixedBiasFrom::kEstimate;
  // s: re-align the three integrations on ref_q at the first sample at or after this time, so the
  // drift is what accumulates after it (an offset left by the filter's convergence is fixed in the
  // body frame and would turn with the box in an ENU error, reading as drift); NaN: never
  double realign_at_s = kNaN;
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
  AttitudeComparison(double latitude_deg, const AttitudeComparisonOptions& opt);

  /// Feeds a sample after `filter` has seen it. The comparison starts at the first finite ref_q
  /// once the filter is locked (then the filter's fixed bias is set to its estimate, for the
  /// 'bias fixed at start' rate of the next samples; with FixedBiasFrom::kTruth it waits for a
  /// sample with finite true_bias columns and holds them). Returns true, with `ap` filled, at a
  /// comparison point.
  bool push(const Sample& s, DriftlessFilter& filter, AttitudePoint& ap);

  bool started() const { return tracks_[kCorrected].att.initialized(); }
  /// When the comparison started (lock), s; NaN before.
  double start_s() const { return start_s_; }
  /// When the integrations were re-aligned on ref_q (options.realign_at_s), s; NaN before.
  double realign_s() const { return realign_s_; }
  /// The bias the 'fixed' integration holds, deg/s (NaN before the start).
  const Vector6d& fixed_bias_dps() const { return fixed_bias_dps_; }
  std::size_t points() const { return t_.size(); }
  AttitudeDrifts drifts() const;

 private:
  void start(const Sample& s, DriftlessFilter& filter);
  void step(const Sample& s, const SampleOutput& out);
  void realign(const Sample& s, AttitudePoint& ap);
  bool compare(const Sample& s, AttitudePoint& ap);

  struct Track {
    AttitudeIntegrator att;
    ErrorAccumulator acc;
    std::vector<double> err_deg;
    Eigen::Quaterniond last_err = Eigen::Quaterniond::Identity();  // q_est q_ref^-1, last ref_q
  };
  enum { kCorrected, kRaw, kFixed };
  std::array<Track, 3> tracks_;
  AttitudeComparisonOptions opt_;
  std::vector<double> t_;
  double next_t_ = kNaN;
  double start_s_ = kNaN;
  double realign_s_ = kNaN;
  double aligned_s_ = kNaN;   // s, the start or the re-alignment: the net drift's origin
  double last_ref_s_ = kNaN;  // s, the last sample compared with ref_q
  Vector6d fixed_bias_dps_ = Vector6d::Constant(kNaN);
};

}  // namespace driftless::est
