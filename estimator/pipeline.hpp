// One pass over a log or any stream of samples: the DriftLess filter, strapdown attitude with and
// without the correction, and (evaluation only) errors against the samples' true_ columns. The
// CLI, the sweep (studies/), the benchmarks and the tests share it; file output is the caller's
// (EstimateSink). Eigen + std only.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "estimator/accel_check.hpp"
#include "estimator/attitude.hpp"
#include "estimator/attitude_comparison.hpp"
#include "estimator/box_motion_check.hpp"
#include "estimator/reference_check.hpp"
#include "estimator/filter.hpp"
#include "estimator/health.hpp"
#include "estimator/log.hpp"

namespace driftless::est {

/// Receives the pass's outputs as they happen (all optional).
class EstimateSink {
 public:
  virtual ~EstimateSink() = default;
  /// Every sample, after the filter saw it (out: corrected outputs and fused rate). `locked`: the
  /// correction applied to it is an estimate, i.e. every sigma of the correction is below the
  /// lock level (EstimateRunOptions::attitude_start_sigma_dps) after the latest update; false
  /// before the first lock and again after a gate re-lock widened P, until it shrinks again.
  virtual void on_sample(const Sample& /*s*/, const SampleOutput& /*out*/, bool /*locked*/) {}
  /// Every update; `s` is the sample whose push produced it (its true_ columns for evaluation);
  /// `locked` as in on_sample, after this update.
  virtual void on_update(const UpdateRecord& /*rec*/, const Matrix6d& /*P*/, const Sample& /*s*/,
                         bool /*locked*/) {}
  /// Attitude errors every `attitude_interval_s`.
  virtual void on_attitude(const AttitudePoint& /*p*/) {}
};

/// Where the samples come from when they are not a log file: fills the next sample, false at
/// the end (a simulator, the sweep's closed-form box, a replay).
using SampleSource = std::function<bool(Sample&)>;

struct EstimateRunOptions {
  double attitude_interval_s = 1.0;  // s, spacing of attitude comparison points
  // deg/s: the attitude comparison starts at the first ref_q once every bias sigma is below this
  // (the filter has locked on); <= 0 starts it at the log's first ref_q
  double attitude_start_sigma_dps = 0.05;
  // what the 'fixed' attitude integration holds: the estimate at the start (estimate) or the
  // true bias there, a perfect turn-on calibration (sweep; needs true_bias columns)
  FixedBiasFrom fixed_bias_from = FixedBiasFrom::kEstimate;
  // s: start of the evaluation window: per-sample truth statistics (WindowStats) from here; NaN:
  // no window
  double eval_start_s = kNaN;
  // re-align the attitude integrations on ref_q at eval_start_s: the net drift is what
  // accumulates inside the window
  bool realign_at_eval_start = false;
  double nees_band_probability = 0.95;  // two-sided chi-square band for the NEES statistics
  HealthLimits health;                  // limits of the health verdict (docs/estimator.md section 6.1)
  UpdateObserver* update_observer = nullptr;  // told of every accepted update (--smooth's smoother)
};

/// Statistics against the log's truth (filled when the log has true_bias columns).
struct TruthStats {
  bool available = false;
  std::size_t updates = 0;            // accepted updates evaluated
  double bias_error_rms_dps = kNaN;   // rms over updates and the 6 components
  double bias_error_rms_second_half_dps = kNaN;  // the same over the second half (converged)
  Vector6d final_error_dps = Vector6d::Constant(kNaN);
  double nees_mean = kNaN;            // mean of e^T P^-1 e (6 dof)
  double nees_mean_band_lo = kNaN;    // band of the mean at nees_band_probability
  double nees_mean_band_hi = kNaN;
  double nees_fraction_in_band = kNaN;  // fraction of single NEES values inside the 6-dof band
  double nees_band_lo = kNaN, nees_band_hi = kNaN;
  double within_3sigma_fraction = kNaN;  // component errors inside +-3 sigma
};

/// Per-sample statistics against the truth over the evaluation window (every sample with t >=
/// eval_start_s and finite true_bias columns counts, not only the updates, so the time a filter
/// spends converging inside the window shows). Errors are estimate minus truth, deg/s.
struct WindowStats {
  bool available = false;  // a window was asked for and held samples with truth
  double start_s = kNaN;   // s, eval_start_s
  std::size_t samples = 0;
  double bias_error_rms_dps = kNaN;                      // over samples and the 6 components
  Vector6d component_rms_dps = Vector6d::Constant(kNaN);  // per component (1x 1y 1z 2x 2y 2z)
  double bias_error_max_dps = kNaN;                      // largest |component error|
  Vector6d final_error_dps = Vector6d::Constant(kNaN);   // at the window's last sample
  double nees_per_dof_mean = kNaN;  // mean over the samples of e^T P^-1 e / 6
  double nis_per_dof_mean = kNaN;   // mean NIS / dim of the accepted updates at t >= eval_start_s
  std::size_t nis_updates = 0;
  double sigma_rms_final_dps = kNaN;  // sqrt(trace P / 6) at the pass's end
};

/// A gate re-lock (docs/estimator.md: gate_relock_after).
struct RelockEvent {
  double t_s = kNaN;  // s, time of the update taken by the re-lock
  double nis = kNaN;  // its NIS before P was widened
  // s, the first row after it whose correction is locked again (NaN: not before the end)
  double locked_again_t_s = kNaN;
};

/// The lock lost after it was gained (lock_state.hpp: a gate re-lock that widened P above the lock
/// level, or a sigma above kUnlockFactor times it; a sigma that only crosses the level is no loss).
struct LockLoss {
  double t_s = kNaN;        // s, the update after which it was lost
  double sigma_dps = kNaN;  // deg/s, the largest correction sigma after it
  bool relock = false;      // a gate re-lock widened P there
  double locked_again_t_s = kNaN;  // s, the first row locked again (NaN: not before the end)
};

/// What a pass produced.
struct EstimateSummary {
  std::uint64_t rows = 0;
  std::uint64_t rows_missing_gyro = 0;
  FilterCounters counters;
  Vector6d bias_dps = Vector6d::Constant(kNaN);
  Vector6d sigma_dps = Vector6d::Constant(kNaN);
  // the bias temperature coefficients [k1; k2] (deg/s per degC) and their sigma; states only
  // with temp_coef_sigma_dps_per_degc > 0, learned only from temperature changes
  bool temp_states = false;
  Vector6d temp_coef_dps_per_degc = Vector6d::Constant(kNaN);
  Vector6d temp_coef_sigma_dps_per_degc = Vector6d::Constant(kNaN);
  std::array<double, 2> temp_ref_c{kNaN, kNaN};  // degC, the temperatures bias_dps refers to
  // self-calibrating mode: each sensor's g-sensitivity (deg/s per g, sensor axes) and its sigma,
  // and the sigma of the correction b + G f the filter applies (what "locked" looks at)
  bool gsens_states = false;
  // what drove them: the accel columns, gravity from ref_q (no accel columns), none (accel_check.hpp)
  GravitySource gravity_source = GravitySource::kNone;
  std::array<Eigen::Matrix3d, 2> gsens_dps_per_g{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  std::array<Eigen::Matrix3d, 2> gsens_sigma_dps_per_g{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  Vector6d correction_sigma_dps = Vector6d::Constant(kNaN);
  // ... and its scale-factor and misalignment error E_i (fraction, sensor axes) with each
  // element's sigma (states with scale_misalign_sigma_frac > 0)
  bool scale_states = false;
  std::array<Eigen::Matrix3d, 2> scale_misalign_frac{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  std::array<Eigen::Matrix3d, 2> scale_misalign_sigma_frac{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  // the end-stop angle errors (deg; platform 1 at -, at +, platform 2 at -, at +) and their sigma
  bool stop_states = false;
  Eigen::Vector4d stop_angle_deg = Eigen::Vector4d::Zero(), stop_angle_sigma_deg = Eigen::Vector4d::Zero();
  double t_first_s = kNaN, t_last_s = kNaN;
  bool attitude_available = false;   // the log has ref_q
  double drift_corrected_deg_per_h = kNaN;
  double drift_raw_deg_per_h = kNaN;
  double drift_fixed_deg_per_h = kNaN;
  // deg/h: the error angle at the last ref_q over the hours since the start (or the re-alignment
  // at eval_start_s); NaN when a requested re-alignment never came
  double drift_net_corrected_deg_per_h = kNaN;
  double drift_net_raw_deg_per_h = kNaN;
  double drift_net_fixed_deg_per_h = kNaN;
  double attitude_start_s = kNaN;                  // s, where the comparison started
  double attitude_realign_s = kNaN;                // s, where it was re-aligned (NaN: not)
  // s, the comparison stopped here: no sensor read the box rate ('standstill: gyro' and a flip of
  // both platforms at once; no platform angle known), or a time gap hid the box's turn; the drifts
  // and final errors are withheld (NaN). NaN: not withheld
  double attitude_withheld_from_s = kNaN;
  AttitudeWithheld attitude_withheld_why = AttitudeWithheld::kNo;
  double attitude_withheld_gap_s = kNaN;  // s, the gap's length (kTimeGap)
  // does ref_q turn with the gyros (reference_check.hpp)? When another convention fits, or none,
  // the drifts and final errors are withheld (NaN) and health names reference_mismatch
  ReferenceFit reference;
  // did the box turn while both platforms rested (box_motion_check.hpp)?
  BoxMotion box_motion;
  Vector6d fixed_bias_dps = Vector6d::Constant(kNaN);  // deg/s, the bias held by `fixed`
  AttitudeError final_corrected = kAttitudeErrorUnknown, final_raw = kAttitudeErrorUnknown,
                final_fixed = kAttitudeErrorUnknown;  // NaN while no comparison was made
  TruthStats truth;
  WindowStats window;  // with EstimateRunOptions::eval_start_s
  bool log_complete = true;
  std::vector<RelockEvent> relocks;
  std::vector<LockLoss> lock_losses;  // each loss of the lock (with hysteresis) and when it came back
  // s, the first row whose correction was locked (the lock level of on_sample: the row that made
  // the locking update); NaN: never
  double locked_from_t_s = kNaN;
  std::uint64_t samples_locked = 0;  // rows whose correction was locked (corrected.csv locked = 1)
  HealthReport health;  // the verdict: lock, gate rejections, NIS against its band, observability
  std::vector<std::string> warnings;
};

/// Runs the filter over every row of `reader` (which it consumes). Throws log::LogError on a
/// malformed log (the reader's message names file and line); NaN rows are counted and skipped.
/// `should_stop` (optional) is polled every 4096 rows (Ctrl-C).
EstimateSummary run_estimate(log::LogReader& reader, const EstimatorConfig& cfg, EstimateSink* sink,
                             const EstimateRunOptions& opt = {}, bool (*should_stop)() = nullptr);

/// The pass over the rows of `reader` as `next` gives them (another pass reads the reader and
/// hands its rows on: `fields` says which column groups they fill; `meta` is the reader's header,
/// copied before the other pass began); the reader's findings (gaps, clipping, the stamp rate) are
/// added at the end, so the other pass must be done with the reader by then.
EstimateSummary run_estimate(const log::Metadata& meta, const log::LogReader& reader, std::uint32_t fields,
                             const SampleSource& next,
                             const EstimatorConfig& cfg, EstimateSink* sink, const EstimateRunOptions& opt = {},
                             bool (*should_stop)() = nullptr);

/// The same pass over a stream: `meta` describes it as a log header would (box geometry,
/// latitude, completeness), `fields` says which optional column groups its samples fill
/// (SampleField bits: true_bias, ref_q). Whatever `next` throws ends the pass and propagates.
EstimateSummary run_estimate(const log::Metadata& meta, std::uint32_t fields, const SampleSource& next,
                             const EstimatorConfig& cfg, EstimateSink* sink, const EstimateRunOptions& opt = {},
                             bool (*should_stop)() = nullptr);

}  // namespace driftless::est
