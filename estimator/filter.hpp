// The DriftLess bias filter (paper section 2): a streaming Kalman filter on the state [b1; b2]
// (deg/s) fed one Sample at a time. The same object runs on a log, on a replay and live in the
// HIL bridge; it survives a source switch (on_source_switch()). Eigen + std only.
#pragma once

#include <array>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "estimator/log.hpp"
#include "estimator/sample.hpp"

namespace driftless::est {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// A named slice of the state vector (like PX4's State::gyro_bias.idx).
struct StateSlice {
  Eigen::Index start;
  Eigen::Index size;
};
inline constexpr StateSlice kBias1{0, 3};  // b1, deg/s, sensor-1 axes
inline constexpr StateSlice kBias2{3, 3};  // b2, deg/s, sensor-2 axes
inline constexpr int kStateDim = 6;

/// paper: H_k switches by k mod 4 as in eq. (5), 6-dim stacked residuals of consecutive
/// standstills. general: H from the platform attitudes in force (or calibrated matrices), one
/// 3-dim residual per standstill (or per sample).
enum class FilterMode { kPaper, kGeneral };

/// Where standstills (both platforms at rest relative to the box) come from.
enum class StandstillSource {
  kPlatformColumns,  // plat1_deg / plat2_deg: at rest when both are finite and unchanged
  kGyroSignal,       // the gyros alone (hardware without angle read-back): flips show as a
                     // rate difference between the sensors; positions tracked from the flips
  kSchedule,         // a fixed clock: one standstill every standstill_period_s (the paper's
                     // static Fig. 5 run, where the platforms never moved)
};

/// How P is updated after a gain: the paper's printed (I - W H)(P + Q), or Joseph form.
enum class CovarianceUpdate { kPrinted, kJoseph };

/// One calibrated matrix M of one sensor at one platform position (paper section 4):
/// y = M^-1 x + b, so M replaces R (and M^-1 replaces R^T) in eqs. (1), (2) and (5).
struct CalibratedPosition {
  double plat_deg = 0.0;                                        // deg, the platform angle
  Eigen::Matrix3d M_body_from_sensor = Eigen::Matrix3d::Identity();  // includes scale, misalignment
};

/// Calibrated matrices per sensor. An empty list means "use Rot(hinge axis, angle)".
struct Calibration {
  std::vector<CalibratedPosition> sensor1;
  std::vector<CalibratedPosition> sensor2;
  double match_tolerance_deg = 10.0;  // deg, a platform angle this close uses that position's M
  /// g-sensitivity per sensor, deg/s per g of specific force (sensor axes): push() subtracts
  /// G f / g from the gyros of samples whose accel columns are finite. Zero = none.
  std::array<Eigen::Matrix3d, 2> G_dps_per_g{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  bool empty() const { return sensor1.empty() && sensor2.empty(); }
  bool has_g_sensitivity() const { return !G_dps_per_g[0].isZero(0.0) || !G_dps_per_g[1].isZero(0.0); }
  /// Throws std::invalid_argument when a matrix is singular or not finite.
  void validate() const;
};

/// Filter configuration: plain values with units; defaults are MPU6050-like (paper section 4).
struct EstimatorConfig {
  FilterMode mode = FilterMode::kGeneral;
  CovarianceUpdate covariance_update = CovarianceUpdate::kJoseph;  // paper mode: kPrinted
  bool per_sample_updates = false;  // general mode: update on every standstill sample

  // standstill detection
  StandstillSource standstill = StandstillSource::kPlatformColumns;
  double settle_s = 0.5;               // s, samples skipped after the platforms come to rest
  double min_standstill_s = 1.0;       // s, shorter standstills are discarded
  double max_standstill_s = 0.0;       // s, split longer standstills into updates (0 = never)
  double end_margin_s = 0.1;           // s, samples dropped before motion is seen (its onset
                                       // hides below angle_tolerance_deg for a sample or two)
  double angle_tolerance_deg = 0.001;  // deg, platform angle change between samples = motion
  double gyro_motion_threshold_dps = 5.0;  // deg/s, | |y1| - |y2| | above this = a flip
  double standstill_period_s = 10.0;   // s, kSchedule: length of one standstill
  double flip_angle_deg = 90.0;        // deg, positions +-flip_angle (paper mode, gyro/schedule)
  double initial_plat1_deg = 90.0;     // deg, kGyroSignal / kSchedule start positions
  double initial_plat2_deg = 90.0;     // deg

  // tuning. R: per-axis white noise of one sample = noise_density^2 * sample rate
  double noise_density_dps_rthz = 0.005;   // deg/s/sqrt(Hz), MPU6050 data sheet (paper sec. 4)
  // Q: the bias wanders like a random walk that reaches the bias-instability level B at tau_B:
  // K = 0.664 B sqrt(3 / tau_B), Q = K^2 dt per axis
  double bias_instability_dps = 0.01;      // deg/s (36 deg/h)
  double bias_instability_tau_s = 100.0;   // s, where the Allan minimum lies (paper: ~100 s)
  double q_override_dps2_per_s = 0.0;      // (deg/s)^2/s, > 0 replaces the spec-derived Q rate
  double r_override_dps2 = 0.0;            // (deg/s)^2 per sample and axis, > 0 replaces R
  double initial_bias_dps = 0.0;           // deg/s, every component of x0
  double initial_sigma_dps = 20.0;         // deg/s, sqrt of P0's diagonal (MPU6050 turn-on +-20)
  double variance_floor_dps2 = 1e-14;      // (deg/s)^2, P's diagonal never drops below this
  double nis_gate_probability = 0.9999;    // chi-square probability of the NIS gate (1 = off)
  /// after this many consecutive gate rejections the filter re-locks: P is widened by the
  /// innovation and the update is taken (a real bias jump or a switch to other hardware,
  /// not an outlier). 0 = never re-lock.
  int gate_relock_after = 3;

  Calibration calibration;  // optional calibrated matrices (issue 4); empty = rotations

  /// Throws std::invalid_argument naming the field on a bad value.
  void validate() const;
  /// Q rate per axis, (deg/s)^2/s, from the spec (or the override).
  double q_dps2_per_s() const;
  /// White-noise variance of one sample per axis, (deg/s)^2, at `sample_rate_hz`.
  double sample_variance_dps2(double sample_rate_hz) const;
};

/// Paper-mode defaults: printed recursion, platform columns.
EstimatorConfig paper_config();

/// Reads a `key: value` configuration (a flat YAML subset: '#' comments, blank lines) on top of
/// `base`. Keys are the EstimatorConfig field names; enums as text (mode: paper|general, ...).
/// Keys may use another unit of the field's quantity (`bias_instability_dph: 36`). Throws
/// driftless::InputError naming `name`, the line and the key on a bad line or a key given twice.
EstimatorConfig parse_estimator_config(std::istream& in, const std::string& name,
                                       EstimatorConfig base = {});
/// The same, applied to one key (for the CLI and YAML front ends).
void set_config_value(EstimatorConfig& cfg, const std::string& key, const std::string& value);
/// Writes every field as `key: value` lines (parse_estimator_config reads it back).
void write_estimator_config(std::ostream& out, const EstimatorConfig& cfg);

/// What push() did with a sample. It never throws per sample.
enum class PushStatus {
  kInvalid,       // NaN/missing gyro value or time: the sample did not enter the state
  kTimeNotIncreasing,  // t <= previous t: dropped (call on_source_switch() for a new timeline)
  kMoving,        // a platform is moving (or its angle unknown): no residual
  kSettling,      // both at rest, inside the settle margin
  kAccumulating,  // added to the current standstill
  kUpdated,       // a standstill (or sample) update was accepted
  kRejected,      // an update was rejected by the NIS gate (reported in last_update())
};
const char* to_string(PushStatus s);

/// One measurement update.
struct UpdateRecord {
  std::uint64_t index = 0;    // 0-based count of updates (accepted and rejected)
  double t_s = kNaN;          // s, time of the update (last sample of the standstill)
  double t_start_s = kNaN;    // s, first sample used
  std::size_t samples = 0;    // samples averaged into the residual
  double plat1_deg = kNaN;    // deg, positions used for H
  double plat2_deg = kNaN;
  int dim = 0;                // residual dimension: 3, or 6 (paper stacking)
  Vector6d bias_dps = Vector6d::Zero();   // estimate after the update
  Vector6d sigma_dps = Vector6d::Zero();  // sqrt(diag P) after the update
  Vector6d innovation_dps = Vector6d::Zero();  // r - H x (first `dim` entries)
  double nis = kNaN;          // innovation^T S^-1 innovation
  double nis_gate = kNaN;     // chi-square gate at nis_gate_probability and `dim`
  bool accepted = false;
};

/// Outputs for the sample last pushed.
struct SampleOutput {
  double t_s = kNaN;
  Eigen::Vector3d y1c_dps = Eigen::Vector3d::Constant(kNaN);  // y1 - b1_hat, sensor-1 axes
  Eigen::Vector3d y2c_dps = Eigen::Vector3d::Constant(kNaN);  // y2 - b2_hat, sensor-2 axes
  // fused inertial body rate in box axes (Earth rate included): the mean of M_i y_ic over the
  // sensors whose platform is at rest with a known angle; NaN when none is
  Eigen::Vector3d rate_body_dps = Eigen::Vector3d::Constant(kNaN);
  Eigen::Vector3d rate_body_raw_dps = Eigen::Vector3d::Constant(kNaN);  // the same, uncorrected
  // the same, corrected by the fixed bias of set_fixed_bias_dps() (the uncorrected rate until set)
  Eigen::Vector3d rate_body_fixed_dps = Eigen::Vector3d::Constant(kNaN);
  int sensors_fused = 0;  // 0, 1 or 2
  PushStatus status = PushStatus::kInvalid;
};

/// Counters since construction.
struct FilterCounters {
  std::uint64_t samples = 0;
  std::uint64_t invalid = 0;
  std::uint64_t time_not_increasing = 0;
  std::uint64_t updates = 0;
  std::uint64_t rejected = 0;
  std::uint64_t standstills_too_short = 0;
  std::uint64_t schedule_mismatches = 0;  // paper mode: measured positions differ from eq. (5)
  std::uint64_t source_switches = 0;
  std::uint64_t relocks = 0;  // gate re-locks after gate_relock_after consecutive rejections
};

/// The streaming DriftLess filter.
class DriftlessFilter {
 public:
  /// Builds the filter; hinge axes, sample rate and latitude come from `meta` (defaults if absent).
  /// Throws std::invalid_argument on a bad config.
  DriftlessFilter(const EstimatorConfig& cfg, const log::Metadata& meta);

  /// Feeds one sample; returns what happened. Never throws; NaN samples never touch the state.
  PushStatus push(const Sample& s);
  /// A new source takes over (HIL switch-over, a gap): the standstill in progress is dropped and
  /// paper-mode stacking restarts; the estimate and P are kept. `meta` (optional) may change the
  /// hinge axes and sample rate; time may restart.
  void on_source_switch(const log::Metadata* meta = nullptr);

  /// A bias [b1; b2] (deg/s) held fixed for the comparison output rate_body_fixed_dps: what a box
  /// whose gyros were calibrated once and never again would use. Zero until set; the filter's
  /// own state is not touched.
  void set_fixed_bias_dps(const Vector6d& b) { fixed_bias_ = b; }

  /// Bias estimate [b1; b2], deg/s (b_i in sensor-i axes).
  const Vector6d& bias_dps() const { return x_; }
  Eigen::Vector3d bias1_dps() const { return x_.segment<3>(kBias1.start); }
  Eigen::Vector3d bias2_dps() const { return x_.segment<3>(kBias2.start); }
  /// Its covariance, (deg/s)^2.
  const Matrix6d& covariance_dps2() const { return P_; }
  Vector6d sigma_dps() const { return P_.diagonal().cwiseSqrt(); }
  /// The latest update (has_update() false before the first).
  const UpdateRecord& last_update() const { return last_update_; }
  bool has_update() const { return counters_.updates > 0; }
  /// Corrected outputs and fused body rate of the sample last pushed.
  const SampleOutput& output() const { return out_; }
  const FilterCounters& counters() const { return counters_; }
  const EstimatorConfig& config() const { return cfg_; }

  /// M_body_from_sensor for sensor 1 or 2 at platform angle `plat_deg` (Rot(a_i, angle) or the
  /// calibrated matrix). For tests and diagnosis.
  Eigen::Matrix3d body_from_sensor(int sensor, double plat_deg) const;

 private:
  PushStatus push_corrected(const Sample& s);
  struct Standstill;  // running sums of one standstill
  void set_metadata(const log::Metadata& meta);
  bool classify(const Sample& s, double& p1, double& p2, bool& p1_rest, bool& p2_rest);
  void start_segment(double t_s, double p1, double p2, std::int64_t tag);
  int end_standstill();
  int close_segment();
  void predict_to(double t_s);
  template <int D>
  bool update(const Eigen::Matrix<double, D, 1>& r, const Eigen::Matrix<double, D, 6>& H,
              const Eigen::Matrix<double, D, D>& R, UpdateRecord& rec);
  void emit_update(const UpdateRecord& rec, bool accepted);
  void accumulate(const Sample& s, PushStatus& status, int& result);
  void commit(const Eigen::Vector3d& y1, const Eigen::Vector3d& y2, double t_s, int& result);
  void fuse_rate(const Sample& s, double p1, double p2, bool p1_rest, bool p2_rest);
  bool track_gyro_positions(const Sample& s, double dt_s);
  int pattern_of(double p1, double p2) const;
  double pattern_angle(int pattern, int sensor) const;

  EstimatorConfig cfg_;
  Eigen::Vector3d hinge1_ = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d hinge2_ = Eigen::Vector3d::UnitX();
  double meta_rate_hz_ = kNaN;
  double q_rate_dps2_per_s_ = 0.0;

  Vector6d x_ = Vector6d::Zero();
  Vector6d fixed_bias_ = Vector6d::Zero();  // deg/s, for rate_body_fixed_dps only
  Matrix6d P_ = Matrix6d::Identity();
  int consecutive_rejections_ = 0;
  double t_filter_s_ = kNaN;  // time P and x refer to

  // standstill tracking
  struct Segment {
    bool active = false;
    double t_rest_s = kNaN;   // when rest began
    double t_first_s = kNaN;  // first sample used
    double t_last_s = kNaN;
    double p1 = kNaN, p2 = kNaN;  // deg
    std::int64_t tag = 0;         // schedule slot (kSchedule)
    std::size_t n = 0;
    Eigen::Vector3d sum1 = Eigen::Vector3d::Zero();
    Eigen::Vector3d sum2 = Eigen::Vector3d::Zero();
  } seg_;
  // samples of the current standstill not yet committed (the end margin), a fixed ring
  struct Pending {
    Eigen::Vector3d y1, y2;
    double t_s;
  };
  std::vector<Pending> ring_;
  std::size_t ring_head_ = 0, ring_count_ = 0, ring_capacity_ = 0;
  double last_t_s_ = kNaN;
  double prev_p1_ = kNaN, prev_p2_ = kNaN, prev_t_plat_s_ = kNaN;
  double sched_start_s_ = kNaN;
  std::uint64_t sched_index_ = 0;
  // gyro-only position tracking
  struct GyroTracker {
    double p1 = 90.0, p2 = 90.0;           // deg, tracked positions
    bool moving = false;
    bool have_base = false;
    double d_base = 0.0;                   // deg/s, rest level of |y1| - |y2|
    double h1_base = 0.0, h2_base = 0.0;   // deg/s, rest level of y_i . a_i
    double turn1_deg = 0.0, turn2_deg = 0.0;
    double prev_d = 0.0;
    int quiet = 0;
  } gyro_;
  double gate3_ = 0.0, gate6_ = 0.0;
  // cached M_body_from_sensor of the last angle asked for, per sensor
  mutable std::array<double, 2> cache_deg_{kNaN, kNaN};
  mutable std::array<Eigen::Matrix3d, 2> cache_M_{Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity()};

  // paper mode: the previous standstill (for the 6-dim stack) and the eq. (5) counter
  struct Residual3 {
    bool valid = false;
    Eigen::Vector3d r = Eigen::Vector3d::Zero();
    Eigen::Matrix<double, 3, 6> H = Eigen::Matrix<double, 3, 6>::Zero();
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    int pattern = 0;  // position index 0..3 of eq. (5)'s sequence
  } prev_res_;
  std::int64_t paper_k_ = -1;   // k of eq. (5); -1 until the phase is known
  Eigen::Vector3d last_rate_body_dps_ = Eigen::Vector3d::Constant(kNaN);

  UpdateRecord last_update_;
  SampleOutput out_;
  FilterCounters counters_;
};

}  // namespace driftless::est
