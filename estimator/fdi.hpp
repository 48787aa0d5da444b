// Fault detection and isolation (FDI) for the dual-gyro box: the paper's "future work" (sec. 5).
// Eigen + std only: this runs on hardware beside the DriftLess filter. Method and limits:
// docs/fdi.md.
//
// The detector watches the DriftLess residual, eq. (2): r = R1 y1 - R2 y2, and its innovation
// against the filter's bias estimate, nu = r - [R1 -R2] b_hat. A fault on sensor i, axis k adds
// f * g to nu with the signature g = +R1 e_k (sensor 1) or -R2 e_k (sensor 2). Across platform
// positions these signatures change differently (a platform flip reverses the two axes of its
// sensor that are not on the hinge), which is what isolates the sensor and the axis.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace driftless::est {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// What kind of fault was found.
enum class FaultKind : std::uint8_t { kNone, kStuck, kBiasStep, kNoiseBurst, kScaleChange };
const char* to_string(FaultKind k);

/// Tuning of the detector. Units: Hz, s, deg/s; dimensionless statistics say so.
struct FdiParams {
  double sample_rate_hz = 100.0;       // Hz, nominal sample rate of the stream
  double learn_s = 20.0;               // s of at-rest data used to learn the residual noise per axis
  double corr_window_s = 0.05;         // s, lag window of the long-run (zero-frequency) noise estimate;
                                       // covers the DLPF's correlation (a few ms, docs/fdi.md)
  double noise_floor_dps = 1e-4;       // deg/s, lower bound on the learned per-sample residual sigma
  double stuck_s = 0.3;                // s of bit-identical output on one axis that flags it stuck
  double mean_drift_sigma = 1.0;       // CUSUM allowance k of the mean test, residual sigmas
  double mean_threshold = 30.0;        // CUSUM threshold h of the mean test (dimensionless)
  double estimate_allowance = 3.0;     // extra allowance per sigma of the filter's own estimate
  double rate_allowance = 0.003;       // extra allowance per deg/s of box rate, deg/s per deg/s: the
                                       // residual a calibration leaves (misalignment, scale, stop
                                       // angles; 0.003 = 0.17 deg or 0.3 %) times the input rate
  double noise_ratio = 4.0;            // variance ratio the noise-burst CUSUM is designed for
  double noise_threshold = 40.0;       // CUSUM threshold of the noise test (log-likelihood units)
  double classify_s = 2.0;             // s of at-rest data after an alarm used to classify it
  double noise_class_ratio = 2.0;      // post-alarm difference-variance ratio that means "noise"
  double scale_z = 8.0;                // regression z-score on the body rate that means "scale"
  double scale_min_excitation_dps = 0.5;  // deg/s, box-rate spread needed to test for scale
  double noise_sign_z = 4.0;           // z-score of the noise-isolation covariance to decide
  double isolation_margin = 40.0;      // chi-square gap between best and second hypothesis
  int max_isolation_segments = 8;      // at-rest segments to wait before reporting a best guess
  double history_s = 5.0;              // s of samples kept to find the onset of a fault
  double lock_sigma_dps = 0.05;        // deg/s: the noise is learned only once the filter has locked,
                                       // its estimate's sigma in the residual, sqrt(diag(H P H^T)),
                                       // below this on every box axis (an unlocked filter's residual
                                       // carries its estimate error, not the noise)
  double quiet_rate_dps = 3.0;         // deg/s: box rate up to which an at-rest sample is "quiet": the
                                       // samples the noise is learned from and the position check
                                       // compares (a turning box adds misalignment x rate)
  double revisit_sigma_dps = 0.02;     // deg/s: how far the residual's mean at one platform-position
                                       // pair may move between visits without a fault (bias wander,
                                       // g-sensitivity under changing accelerations)
  /// Throws std::invalid_argument naming the field on a bad value.
  void validate() const;
};

/// One time step as the detector sees it. Frames: R_body_from_sensorI maps sensor-I axes to box
/// axes at the platform's current (assumed) angle.
struct FdiInput {
  double t_s = 0.0;
  Eigen::Vector3d gyro1_dps = Eigen::Vector3d::Zero();   // sensor-1 output, sensor-1 axes
  Eigen::Vector3d gyro2_dps = Eigen::Vector3d::Zero();   // sensor-2 output, sensor-2 axes
  Eigen::Matrix3d R_body_from_sensor1 = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d R_body_from_sensor2 = Eigen::Matrix3d::Identity();
  bool at_rest = false;   // both platforms at rest: the residual is valid
  Vector6d bias_dps = Vector6d::Zero();         // filter's bias estimate [b1; b2], deg/s
  Matrix6d bias_cov_dps2 = Matrix6d::Zero();    // its covariance, (deg/s)^2
};

/// A detected and isolated fault.
struct FaultReport {
  FaultKind kind = FaultKind::kNone;
  int sensor = 0;          // 1 or 2
  int axis = 0;            // 0 = x, 1 = y, 2 = z, in that sensor's axes
  double t_alarm_s = 0.0;  // s, first alarm (detection)
  double t_isolated_s = 0.0;  // s, when sensor and axis were decided
  double t_onset_s = 0.0;  // s, estimated onset (the CUSUM's last zero)
  double magnitude = 0.0;  // bias step: deg/s; scale: relative gain change; noise: variance ratio
  bool confident = true;   // false: reported at the isolation timeout as the best guess
  bool sensor_ambiguous = false;  // scale changes: see docs/fdi.md (+e on 1 == -e/(1+e) on 2)
  Vector6d bias_before_dps = Vector6d::Zero();  // filter estimate just before the onset, deg/s
  std::string describe() const;
};

/// An alarm the platform positions explain: the residual's offset after the alarm equals its mean
/// at the earlier visits of the same platform-position pair (a position-dependent error of
/// uncalibrated sensors: g-sensitivity, misalignment, scale), so no step-type fault is reported.
/// Over every explained alarm so far (the times are the latest one's).
struct UncalibratedReport {
  double t_alarm_s = 0.0;      // s, the latest alarm that was explained
  double t_decided_s = 0.0;    // s, when the position check decided it
  double offset_dps = 0.0;     // deg/s, largest |quiet innovation mean| of a checked segment (what alarmed)
  double change_dps = 0.0;     // deg/s, largest |change| of a checked segment against its earlier visits
  double step_chi2 = 0.0;      // largest gain of the best bias-step hypothesis over "no change"
                               // (chi-square units; each below isolation_margin)
  int segments = 0;            // post-alarm segments compared with earlier visits of their pair
  int while_turning = 0;       // of them: alarms whose offset the quiet samples did not carry (it came
                               // while the box turned: misalignment or scale x rate)
  int alarms = 0;              // alarms explained
  std::string describe() const;
};

/// Detector state as returned by push().
enum class FdiStatus : std::uint8_t {
  kLearning,   // learning the residual noise
  kOk,         // monitoring, no alarm
  kSkipped,    // sample not usable for the residual tests (moving or non-finite)
  kSuspect,    // an alarm is being classified / isolated
  kIsolated,   // a fault is isolated: see fault()
};

/// Streaming detector. One push() per sample; never throws per sample.
class FaultDetector {
 public:
  explicit FaultDetector(const FdiParams& params);

  /// Consumes one sample and returns the detector state after it.
  FdiStatus push(const FdiInput& in);
  const FdiParams& params() const { return p_; }
  /// The isolated fault, once status is kIsolated (latched: a single-fault detector).
  const std::optional<FaultReport>& fault() const { return fault_; }
  /// Time of the first alarm, if any (also for alarms later classified as faults).
  std::optional<double> first_alarm_s() const { return first_alarm_s_; }
  /// Learned per-sample residual sigma per box axis, deg/s (NaN while learning).
  Eigen::Vector3d residual_sigma_dps() const;
  /// Learned long-run residual sigma per box axis, deg/s per sample (sqrt of the zero-frequency
  /// spectral density times the sample rate): the scale of the mean test (NaN while learning).
  Eigen::Vector3d residual_sigma_longrun_dps() const;
  /// Forgets the fault and restarts monitoring (keeps the learned noise).
  void reset_alarm();
  /// The latest alarm the platform positions explained (not a fault; docs/fdi.md).
  const std::optional<UncalibratedReport>& uncalibrated() const { return uncalibrated_; }
  /// When the filter was first seen locked (learning starts then), s; NaN before.
  double t_filter_locked_s() const { return t_locked_s_; }
  /// Time of the first sample the noise is learned from, s; NaN before.
  double t_learn_start_s() const { return t_learn_start_s_; }
  /// Quiet at-rest samples and rest segments the noise was learned from (0 while learning).
  long learned_samples() const { return learned_samples_; }
  long learned_segments() const { return learned_segments_; }
  /// True when the noise was learned from quiet samples only (box rate <= quiet_rate_dps), false
  /// when the box was hardly ever quiet and every rest sample was used.
  bool learned_on_quiet() const { return learned_on_quiet_; }

 private:
  struct Record {           // one at-rest sample kept for onset search and isolation
    double t_s;
    long segment;
    Eigen::Vector3d r;      // eq. (2) residual, deg/s
    Eigen::Vector3d fused;  // fused box rate (R1 (y1-b1) + R2 (y2-b2)) / 2, deg/s
    Eigen::Matrix3d R1, R2;
    Vector6d bias;
    bool quiet;             // box rate <= quiet_rate_dps
  };
  // one rest segment's quiet residuals: the position check's memory of each visit
  struct Visit {
    long segment;
    Eigen::Matrix3d R1, R2;
    double n = 0;            // quiet samples
    double n_all = 0;        // all its samples
    Eigen::Vector3d sum_r = Eigen::Vector3d::Zero();
    // all samples: per box axis j, sums of the fused rate w_j and of w_j^2, r_j, w_j r_j (the
    // residual's slope on the rate at this visit: what a scale change would change)
    Eigen::Vector3d s_w = Eigen::Vector3d::Zero(), s_ww = Eigen::Vector3d::Zero(),
                    s_r = Eigen::Vector3d::Zero(), s_wr = Eigen::Vector3d::Zero();
  };
  struct PositionEvidence;
  PositionEvidence position_evidence() const;
  enum class PositionCheck : std::uint8_t { kDecided, kChange, kNoData };
  PositionCheck try_position_check(double t_s, bool timeout, std::array<double, 6>* change_mag);
  void remember_visit(const Record& rec);
  double scale_change_z(int j) const;
  void explain(double t_s, double offset_dps, double change_dps, double step_chi2, int segments, bool while_turning);
  void check_stuck(const FdiInput& in);
  void resume_monitoring();
  bool learn(const FdiInput& in, const Record& rec, const Eigen::Vector3d& nu, const Eigen::Vector3d& est_var);
  void alarm(double t_s, long onset_index);
  void feed_isolation(const Record& rec);
  void try_classify(double t_s);
  void try_isolate_mean(double t_s, bool timeout);
  void record_bias_step(int channel, double t_s, double magnitude, bool confident);

  FdiParams p_;
  int stuck_samples_;
  int classify_samples_;
  std::size_t history_len_;
  // stuck detector: run lengths of bit-identical values per sensor axis
  Eigen::Matrix<double, 6, 1> last_value_;
  Eigen::Matrix<int, 6, 1> run_;
  // learning: the at-rest innovations (with their segment) of the first learn_s
  bool finish_learning(const std::vector<std::pair<long, Eigen::Vector3d>>& pieces);
  std::vector<std::pair<long, Eigen::Vector3d>> learn_quiet_, learn_all_;  // (piece, innovation)
  double t_learn_quiet_s_ = std::nan(""), t_learn_all_s_ = std::nan("");
  bool learned_on_quiet_ = false;
  long learn_piece_ = 0;         // contiguous runs of quiet rest samples (the autocovariances' unit)
  bool learn_prev_in_ = false;
  long learn_segment_ = -1;
  double t_learn_start_s_ = std::nan("");
  Eigen::Vector3d sigma_ = Eigen::Vector3d::Constant(-1.0);     // of first differences / sqrt(2)
  Eigen::Vector3d sigma_sample_ = Eigen::Vector3d::Constant(-1.0);  // per sample
  Eigen::Vector3d sigma_lr_ = Eigen::Vector3d::Constant(-1.0);  // long-run (mean test, isolation)
  // segment bookkeeping
  long segment_ = 0;
  bool prev_rest_ = false;
  Eigen::Matrix3d prev_R1_ = Eigen::Matrix3d::Zero(), prev_R2_ = Eigen::Matrix3d::Zero();
  std::optional<Eigen::Vector3d> prev_nu_;
  // cusums per box axis: mean up/down, and their run lengths; noise cusum on differences
  Eigen::Vector3d g_up_ = Eigen::Vector3d::Zero(), g_dn_ = Eigen::Vector3d::Zero();
  Eigen::Vector3i n_up_ = Eigen::Vector3i::Zero(), n_dn_ = Eigen::Vector3i::Zero();
  Eigen::Vector3d g_var_ = Eigen::Vector3d::Zero();
  Eigen::Vector3i n_var_ = Eigen::Vector3i::Zero();
  long sample_index_ = 0;
  std::deque<std::pair<long, Record>> history_;
  // isolation state
  bool suspect_ = false;
  bool classified_ = false;
  bool scale_waiting_ = false;  // a scale change waits for an earlier visit of its positions that turned
  FaultKind kind_ = FaultKind::kNone;
  double t_alarm_ = 0.0, t_onset_ = 0.0;
  Vector6d bias_ref_ = Vector6d::Zero();
  std::vector<Record> post_;   // records since the onset, for classification and isolation
  std::optional<FaultReport> fault_;
  std::optional<double> first_alarm_s_;
  // learning after lock; the position check's visits (newest last, bounded)
  double t_locked_s_ = std::nan("");
  long learned_samples_ = 0, learned_segments_ = 0;
  std::deque<Visit> visits_;
  std::optional<UncalibratedReport> uncalibrated_;
  int explained_alarms_ = 0;
};

/// Degraded mode after isolation: the healthy sensor carries on alone with its last bias estimate
/// (DriftLess needs both sensors to observe the biases), its sigma growing with the bias random
/// walk: P(t) = P0 + q (t - t0) I.
class DegradedBias {
 public:
  /// Starts at t0_s with the filter's estimate; faulty_sensor is 1 or 2; q in (deg/s)^2/s.
  DegradedBias(int faulty_sensor, const Vector6d& bias_dps, const Matrix6d& cov_dps2, double t0_s,
               double bias_rw_dps2_per_s);
  int healthy_sensor() const { return healthy_; }
  /// The healthy sensor's held bias, deg/s, in its own axes.
  const Eigen::Vector3d& bias_dps() const { return bias_; }
  /// Its covariance at time t_s, (deg/s)^2.
  Eigen::Matrix3d cov_dps2(double t_s) const;
  /// Its 1-sigma per axis at t_s, deg/s.
  Eigen::Vector3d sigma_dps(double t_s) const;
  /// Box rate from the healthy sensor alone: R_body_from_sensor (y - b), deg/s.
  Eigen::Vector3d body_rate_dps(const FdiInput& in) const;

 private:
  int healthy_;
  Eigen::Vector3d bias_;
  Eigen::Matrix3d cov0_;
  double t0_s_, q_;
};

}  // namespace driftless::est
