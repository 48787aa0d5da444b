// The filter's health verdict (docs/estimator.md section 6.1): did it lock, how many updates did the
// NIS gate reject, is the mean NIS inside its chi-square band, which bias components stayed
// unobservable, did it re-lock. Each finding carries its likely cause and the fix, so a run on data
// the configuration does not fit never ends silently. Eigen + std only.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "estimator/box_motion_check.hpp"
#include "estimator/clip_detector.hpp"
#include "estimator/filter.hpp"
#include "estimator/flip_check.hpp"
#include "estimator/gravity_source.hpp"
#include "estimator/lag_check.hpp"
#include "estimator/lock_state.hpp"
#include "estimator/reference_check.hpp"
#include "estimator/standstill_gyro.hpp"
#include "estimator/steady_state_watch.hpp"

namespace driftless::est {

/// ok: every check passed. degraded: the estimate exists but its sigma or its gate decisions
/// cannot be trusted (a cause is named). failed: there is no usable estimate (never locked).
enum class HealthVerdict { kOk, kDegraded, kFailed };
const char* to_string(HealthVerdict v);

/// What a finding is about (the text is made at the edge: cli/estimate_health.cpp).
enum class HealthCause {
  kNoUpdate,             // no standstill became an update
  kAllRejected,          // updates were made but the gate rejected every one
  kNeverLocked,          // updates accepted, yet some bias sigma never fell below the lock level
  kNoiseUnderstated,     // NIS mean above its band: the data are noisier than R and Q say (above the
                         // 95 % band but inside the degraded band: a note)
  kNoiseOverstated,      // NIS mean below its band: sigma too pessimistic (a note: verdict stays ok)
  kRejectionsAtPosition, // the gate rejects at one position pair: a position-dependent error
  kRejections,           // the gate rejects too often, spread over the positions
  kLoneRejection,        // at most HealthLimits::lone_rejections rejected: outliers the gate is for (a note)
  kUnobservable,         // some bias components kept (most of) their prior sigma
  kRelocks,              // the gate lost lock and re-locked
  kLateLock,             // locked, but too few accepted updates after the lock to check the NIS
  kSignalChainLag,       // the residual follows the box's angular acceleration: one sensor reads late
  kSaturation,           // a gyro channel repeats its largest reading in runs: it clips there
  kDeadAxis,             // a gyro channel empty in every row, or one value throughout (components:
                         // the channel; value: its value if stuck, NaN if empty; suggested: rows)
  kAttitudeWithheld,     // standstill: gyro: both platforms flipped at once, no sensor read the box
                         // rate (value: from when, s; suggested: how many such flips)
  kAttitudeWithheldNoRate,  // no platform rested with a known angle and none moved with its angle
                            // read (value: from when, s)
  kAttitudeWithheldGap,  // a time gap inside the comparison: the box's turn in it is unknown
                         // (value: the sample before it, s; sigma: its length, s)
  kGyroFlipAngle,        // standstill: gyro: the flips turned unlike 2 flip_angle_deg (value: the
                         // measured flip angle, deg; sigma: flip_angle_deg; count: such flips;
                         // suggested: all flips)
  kStampRate,            // the stamps step at another rate than sample_rate_hz states (value: the
                         // stamps' rate from the median interval, Hz; sigma: from the mean one, Hz;
                         // suggested: the stated rate, Hz)
  kParallelHinges,       // the hinge axes are within kParallelHingesDeg of parallel: the bias along
                         // the common hinge can never be observed (value: the angle between them, deg)
  kNeverFlipped,         // every update at one position pair: the platforms never moved
                         // (positions_deg: that pair; count: the updates)
  kAngleJitter,          // no standstill, and the angle columns move by small steps above
                         // angle_tolerance_deg most of the time (value: the largest step, deg; sigma:
                         // angle_tolerance_deg; suggested: the fraction of samples)
  kPriorRejected,        // the first update was rejected: its residual lies beyond the prior
                         // (value: its NIS; suggested: its time, s; sigma: the largest residual
                         // component, deg/s) - a note, the biases are larger than initial_sigma_dps
  kGyroGapPositions,     // standstill: gyro: a time gap, after which the positions were recovered
                         // (a note; count: 1 if a flip was lost in it) or not (degraded); value: the
                         // sample before the gap, s; sigma: its length, s; suggested: when recovered, s
  kSteadyStateAtLock,    // locked late (as kLateLock) because the correction sigma had settled at the
                         // lock level: a longer log gives the same sigma (value: the settled sigma,
                         // deg/s; sigma: the lock level, deg/s; suggested: the mean update
                         // interval, s; count: the updates it settled over; components: the
                         // component whose sigma it was; steady_state: the closed form)
  kLockUnreachable,      // the closed-form steady state of the bias sigma (steady_state.hpp) from the
                         // first updates' q, interval and noise is at or above the lock level: no
                         // longer log can lock (steady_state: the prediction; value: its sigma, deg/s;
                         // sigma: the lock level, deg/s)
  kGyroStartMidFlip,     // standstill: gyro: the log starts during a flip (a note; components: the
                         // platform; value: its hinge rate at the first sample, deg/s; sigma: the
                         // first sample, s; suggested: when the positions became known, s;
                         // positions_deg: the (plat1, plat2) pair from then on)
  kPaperRestAngles,      // paper mode: the platforms rest away from +-flip_angle_deg (eq. (5)'s H)
  kPaperSchedule,        // paper mode: the positions did not follow eq. (5)'s sequence
  kLockLost,             // locked once, then a re-lock widened P and it did not lock again
  // the flip-turn check (flip_check.hpp; components: the platforms, value: the median turn/Δθ,
  // count: such flips, suggested: the platforms' flips, sigma: the first one's time, s)
  kFlipGyroUnit,         // turn/Δθ ≈ 1/57.3: gyro columns in rad/s
  kFlipAngleUnit,        // turn/Δθ ≈ 57.3: angle columns in radians
  kFlipTimeUnit,         // turn/Δθ ≈ 1e3 or 1e6: stamps in ms or µs
  kFlipNotSeen,          // the gyro saw no turn where the angle column flipped: stuck platform
  kFlipAngleSign,        // turn/Δθ ≈ −1: the angle counts against the right-hand rule
  kFlipWrapped,          // one-way platform, angle wrapped at ±180: handled (Δθ modulo 360), a note
  kFlipSensorsSwapped,   // the resting sensor's column turned about the moving hinge
  kFlipAxis,             // the turn is about another axis than the header's hinge (measured_axis)
  kFlipTurnRatio,        // about the hinge by a ratio none of the above
  kFlipScale,            // 1 ± a few % beyond 3 sigma of the scale prior (value: the median ratio;
                         // sigma: its standard error from the flips' spread, NaN below 3 flips,
                         // and the g-sensitivity prior's change over a flip, in quadrature)
  kFlipsUnchecked,       // the platforms moved, but no flip could be measured: the hinge axes and
                         // angle signs were not checked (degraded; count: flips left out because a
                         // gyro clipped them beyond reading, suggested: motions between two rests)
  kFlipsTooSlow,         // flips longer than flip_max_s (value: the longest, s): no flip update
  kBoxNotAtRest,         // --box-at-rest, yet the box turned while both platforms rested
                         // (box_motion_check.hpp): value = ref_q's largest turn rate over a
                         // standstill (deg/s; NaN: no ref_q), sigma = the largest change of the fused
                         // rate within one (deg/s), suggested = when (s). (Box dwells need no such
                         // check: ref_q, where logged, refuses them while the box turns.)
  kBoxDwellsRejected,    // box dwell updates rejected by their gate: count = rejected, suggested =
                         // dwell updates, value = quiet stretches refused as moving (a note when
                         // at most a fifth were rejected, else degraded)
  kReferenceMismatch,    // ref_q does not turn with the gyros (reference_check.hpp): value = the
                         // misfit of the log's convention, sigma = the best misfit, suggested = the
                         // best RefConvention (as a number; kNoFit: NaN), count = turning windows,
                         // components = {the box axis of the example turn}, positions_deg =
                         // {{its end time s, its span s}, {gyro turn deg, ref_q turn deg about that axis}}
  // the accel columns at the standstills (accel_check.hpp; components = {the sensor, 1 or 2},
  // value = the median |f| in the column's numbers, count = the standstill samples)
  kAccelUnit,            // |f| reads g in another unit (suggested: the factor to m/s^2) or in none (NaN)
  kAccelEmpty,           // |f| far below g: the columns are empty (all zero, or not filled)
  kCalibUncertain,       // --calib without --selfcal, and the file's G/E sigma are not small against
                         // the values (a self-calibration's output): value = the largest sigma / |value|
  kVerticalUnobserved,   // --selfcal with box dwells on, none used (no pause), and the correction's
                         // sigma still above half the g-sensitivity prior's (1 g along the vertical):
                         // the bias both sensors share about the vertical is not observed. value =
                         // the largest correction sigma (deg/s), sigma = its prior (deg/s), suggested
                         // = ref_q's slowest turn over the quiet standstills (deg/s; NaN: no ref_q).
                         // Without --selfcal (stop 30; value NaN: not modelled): no G from --calib,
                         // no --box-at-rest, the box turned in every standstill, and a degraded
                         // gate or NIS finding shows an error a bias does not explain
  kClippedFlipsScale,    // --selfcal with flip updates: most flips skipped because a gyro clipped in
                         // them, and the box turned while the platforms rested: the scale along the
                         // hinges is not observed and enters every turn of the box about them.
                         // count = flips skipped, suggested = flip updates used, value = ref_q's
                         // largest turn rate over a standstill (deg/s; NaN: no ref_q)
                         // ... (accel_check.hpp: calib_uncertainty)
  kStandstillsTooShort,  // the platforms rested, but (nearly) every rest was shorter than
                         // min_standstill_s once settle_s and end_margin_s are taken off (failed;
                         // count: such rests, value: their longest usable part, s, sigma:
                         // min_standstill_s, suggested: the longest rest as logged, s)
  kNoDataRows,           // the log has a header and no data rows (failed)
  kStampUnit,            // no sample_rate_hz, and the stamps' median interval makes sense only in
                         // another unit (failed; value: the interval as read, "s"; suggested: the
                         // factor to seconds, 1e-3 / 1e-6 / 1e-9; count: rows)
};

/// One check that did not pass, with the numbers that describe() turns into text.
struct HealthFinding {
  HealthCause cause = HealthCause::kNoUpdate;
  HealthVerdict severity = HealthVerdict::kDegraded;  // kOk = a note that leaves the verdict
  double value = kNaN;        // the measured quantity (fraction, NIS mean, ...; kLoneRejection: its NIS)
  double suggested = kNaN;    // kNoUpdate: the fraction of rows without a gyro value (skipped);
                              // kNoiseUnder/Overstated: nis_mean / dof, the factor by which the
                              // innovation variance exceeds (or falls short of) what S predicts;
                              // kNeverLocked: the rejected fraction; kLoneRejection: its time, s;
                              // kLateLock: the accepted updates after the lock (value: lock time, s);
                              // kSignalChainLag: update_excess (value: the lag, s; sigma: its sigma);
                              // kLockLost: when the lock was lost, s (value: the largest bias sigma
                              // at the end, deg/s; sigma: the lock level, deg/s)
  double sigma = kNaN;
  // kRejectionsAtPosition: the (plat1, plat2) angle pairs (deg) where most updates were rejected;
  // kNeverLocked: the pairs that occurred, when both platforms rested on both sides but some
  // pair of sides never came (they flipped together); empty otherwise
  std::vector<std::array<double, 2>> positions_deg;
  // kLockUnreachable, kSteadyStateAtLock: the closed-form steady state of the run's schedule (for
  // kSteadyStateAtLock its interval_for_lock_s is scaled by the settled sigma over the closed form);
  // kNeverLocked: the same when lock_unreachable, or when the sigma had settled at 0.9 of the lock
  // level or above (available only then)
  SteadyStatePrediction steady_state;
  std::vector<int> components;  // kUnobservable: 0..5 = b1_x .. b2_z; kSaturation: the channel
                                // (0..5 = gyro1_x .. gyro2_z), value: the fraction of the rows
                                // clipped, suggested: the level in deg/s
  // kPaperRestAngles: value = the standstills off, suggested = a rest angle read (deg), sigma =
  // flip_angle_deg; kPaperSchedule: value = the standstills off; both: count = paper standstills
  std::uint64_t count = 0;
  // kFlipAxis: the turn axis measured, and the header's hinge, both in that sensor's axes
  std::array<double, 3> measured_axis{}, header_axis{};
};

/// Limits of the verdict (docs/estimator.md section 6.1).
struct HealthLimits {
  double lock_sigma_dps = 0.05;        // deg/s, locked once every bias sigma is below this
  double band_probability = 0.95;      // two-sided band of the NIS mean (reported; outside: a note)
  // two-sided band whose upper end makes a NIS mean "degraded": a consistent filter lands above
  // its 95 % band in 1 run of 40 by construction, above this one in 1 of 2000
  double degraded_band_probability = 0.999;
  double max_rejected_fraction = 0.02; // above: degraded (unless the rejections are lone ones)
  // this many rejections or fewer are a note however short the log: the gate removing a lone
  // outlier (one 28-update run rejecting 1 is 3.6 %; docs/estimator.md section 6.1)
  std::uint64_t lone_rejections = 1;
  double position_rejected_fraction = 0.5;  // position pairs rejecting more than this are named
                                            // when the others together reject under a quarter
                                            // as often
  double unobservable_ratio = 0.5;     // final sigma / prior sigma above this = unobservable
  // fewer accepted updates than this after the lock: the NIS mean is not checked (its band is
  // as wide as the chi-square of a few dof) and the attitude comparison has almost nothing to
  // compare: degraded, not ok (a log that locks at its last update said "ok" with NIS "nan")
  std::uint64_t min_updates_after_lock = 3;
};

/// The health block of summary.json.
struct HealthReport {
  HealthVerdict verdict = HealthVerdict::kOk;
  bool locked = false;
  double lock_t_s = kNaN;              // s, first update after which every bias sigma < lock level
  bool locked_at_end = false;          // every bias sigma < lock level after the last update
  double lock_lost_t_s = kNaN;         // s, the update after which it was last above the lock level
  std::uint64_t updates = 0, rejected = 0;
  double rejected_fraction = kNaN;
  std::uint64_t nis_updates = 0;       // accepted updates in the NIS mean: those after the lock
                                       // (all accepted ones if it never locked)
  double nis_dof_mean = kNaN;          // mean residual dimension of those updates
  double nis_mean = kNaN;              // mean NIS of the accepted updates
  double nis_mean_band_lo = kNaN, nis_mean_band_hi = kNaN;  // chi-square band of that mean
  double nis_mean_degraded_above = kNaN;  // upper end of the degraded_band_probability band
  std::uint64_t relocks = 0;
  std::uint64_t lock_losses = 0;       // the lock lost after it was gained (lock_state.hpp's hysteresis)
  SteadyStatePrediction steady_state;  // the closed form from the first updates (steady_state_watch.hpp)
  std::vector<int> unobservable;       // 0..5 = b1_x .. b2_z
  std::vector<HealthFinding> findings; // worst first
  LagCheckResult signal_chain;         // the residual against the angular acceleration (lag_check.hpp)
  // what drove the g-sensitivity states (self-calibration; kNone without it): the fix texts pick
  // their advice by it (cli/estimate_health.cpp)
  GravitySource gravity_source = GravitySource::kNone;
  // what the box did while both platforms rested (box_motion_check.hpp) and whether the log has
  // ref_q and accel columns: the fix texts pick their advice by them (cli/estimate_health.cpp)
  BoxMotion box_motion;
  bool ref_q_logged = false, accel_logged = false;
};

/// Limits of the saturation finding: clipped while both platforms rest in at least this fraction
/// of the rows is `failed` (the standstills through those samples carry the rail, not the rate),
/// in fewer `degraded`; clipped only while a platform turns (a fast flip) is a note.
inline constexpr double kSaturationFailedFraction = 0.01;

/// Puts a `saturation` finding for each suspected clipped channel ahead of the other findings (it
/// is their cause) and sets the verdict; `rows` is the log's row count.
void add_saturation_findings(HealthReport& h, const std::vector<ClippedChannel>& clipped, std::uint64_t rows);

/// Puts a failed `dead_axis` finding for each dead gyro channel ahead of the other findings (a
/// dead channel makes every row invalid, or every standstill wrong on that axis: it is their cause).
void add_dead_axis_findings(HealthReport& h, const std::vector<DeadChannel>& dead);

/// The stamps disagree with the stated sample_rate_hz: both their median and their mean interval
/// (log::LogReader::stamp_rate_*_hz) more than kStampRateTolerance off 1 / sample_rate_hz.
inline constexpr double kStampRateTolerance = 0.1;
bool stamp_rate_off(double stated_hz, double median_hz, double mean_hz);
/// Puts a `stamp_rate` finding first when stamp_rate_off(): durations, the noise per sample and the
/// gap threshold all use the stated rate. Failed beyond a factor 2 (a unit: ms or us stamps, or a
/// wrong key), degraded otherwise.
void add_stamp_rate_finding(HealthReport& h, double stated_hz, double median_hz, double mean_hz);

/// Stamps whose median interval no gyro log in seconds has: above kMaxPlausibleIntervalS (a box
/// sampled that slowly cannot resolve a flip of a second or two, and a bias-estimation log is not
/// sampled below 0.5 Hz) over at least kStampUnitMinRows rows. The likely unit is the first of
/// ms, us, ns that puts the interval at or below 1 s (1 Hz .. 1 GHz); ms stamps at 500 Hz or more
/// read 2 "s" or less and are not caught here (the flip-turn check's flip_time_unit is).
inline constexpr double kMaxPlausibleIntervalS = 2.0;
inline constexpr std::uint64_t kStampUnitMinRows = 1000;
/// The factor that takes such stamps to seconds (1e-3, 1e-6, 1e-9), or NaN when they are plausible.
double stamp_unit_to_s(double median_interval_s, std::uint64_t rows);
/// Puts a failed `stamp_unit` finding first when no rate is stated (`stated_hz` NaN) and
/// stamp_unit_to_s() names a unit (with a stated rate, `stamp_rate` says it; with a
/// `flip_time_unit` finding in h, that one).
void add_stamp_unit_finding(HealthReport& h, double stated_hz, double median_hz, std::uint64_t rows);

/// Hinges closer than this to parallel (deg) cannot observe the bias along their common line.
inline constexpr double kParallelHingesDeg = 10.0;
/// Two causes of `never_locked` that more flips cannot cure, put first (failed): parallel hinge
/// axes, and platforms that never moved (`positions_deg`: the position pairs of the `updates`).
void add_flip_setup_findings(HealthReport& h, const BoxGeometry& box,
                             const std::vector<std::array<double, 2>>& positions_deg, std::uint64_t updates);

/// Platform columns and no update: the angles moved by small steps (above angle_tolerance_deg,
/// at most StandstillDetector::kAngleJitterDeg) in more than half of the samples: their noise
/// hid every standstill. Put first (failed).
void add_angle_jitter_finding(HealthReport& h, const StandstillDetector::AngleJitter& j, double tolerance_deg);
/// The lone rejection was the filter's first update: not an outlier but biases beyond the prior.
/// `first` is that update; the lone_rejection note becomes a prior_rejected note.
void name_prior_rejection(HealthReport& h, const UpdateRecord& first);

/// Why the attitude comparison stopped (EstimateSummary::attitude_withheld_from_s).
enum class AttitudeWithheld : std::uint8_t {
  kNo,
  kBothFlipping,  // standstill: gyro: both platforms flipped at once
  kNoBoxRate,     // no sensor gave the box rate (no platform at rest with a known angle)
  kTimeGap,       // a time gap: the box's turn in it is unknown
};

/// The attitude from `t_s` on is withheld for `why` (degraded; the biases stand). `detail`: the
/// flips of both platforms at once (kBothFlipping) or the gap's length, s (kTimeGap).
void add_attitude_withheld_finding(HealthReport& h, AttitudeWithheld why, double t_s, double detail);

/// 'standstill: gyro': flips whose measured turn was unlike 2 flip_angle_deg (ahead of the others:
/// their positions were snapped to the wrong stops; failed when at least half of the flips), and a
/// time gap after which the positions were recovered (a note) or not (degraded).
void add_gyro_standstill_findings(HealthReport& h, const GyroFlipTracker& tracker, double flip_angle_deg);

/// --box-at-rest on a box that turned while the platforms rested (box_turned): `box_not_at_rest`
/// ahead of the other findings (their cause).
void add_box_motion_finding(HealthReport& h, const BoxMotion& m, bool box_at_rest);

/// Self-calibrating mode with box dwells, none used (the box never paused: ref_q turned, or |f|
/// was never 1 g), and the correction still near the g-sensitivity prior: `vertical_unobserved`
/// (degraded). `m`: ref_q's turn over the quiet standstills, the evidence where logged. Without
/// the self-calibration (G not modelled, none from --calib, no --box-at-rest): the same finding
/// when the box turned in every standstill and h already has a degraded rejections or NIS finding.
void add_vertical_finding(HealthReport& h, const DriftlessFilter& filter, const BoxMotion& m);

/// Flip updates on, most flips skipped for a clipping gyro (FilterCounters::flip_clipped), on a
/// box that turned (box_turned): `clipped_flips_scale` (degraded), the scale along the hinges
/// then being at its prior while the box's turns multiply it.
void add_clipped_flips_finding(HealthReport& h, const DriftlessFilter& filter, const BoxMotion& m);

/// ref_q in another convention than the log's, or fitting none (reference_check.hpp): a degraded
/// `reference_mismatch` finding (the attitude figures are withheld; the biases stand).
void add_reference_finding(HealthReport& h, const ReferenceFit& fit);

/// `first` ahead of h's findings (they are the others' cause); the verdict is the worst of all.
void put_findings_first(HealthReport& h, std::vector<HealthFinding> first);

/// Paper mode builds H from eq. (5)'s positions, +-flip_angle_deg in its fixed order: standstills
/// that rested elsewhere or out of that order are findings ahead of the others (their cause),
/// `failed` when at least half of the standstills are off (most updates used an H that is not the
/// box's), else `degraded`. `counters` are the filter's at the end of the pass.
void add_paper_mode_findings(HealthReport& h, const FilterCounters& counters, double flip_angle_deg);

/// The flip-turn check's findings (flip_check.hpp), ahead of the others (a wrong unit, a stuck
/// platform or a wrong hinge makes the updates wrong): `failed` when most of the flips of the
/// platform a finding names disagree with its angle column (both platforms' for a unit), else
/// `degraded`; a one-way platform's wrapped flips are a note (the flip updates take Δθ modulo 360,
/// flip_update.hpp); a scale error along a hinge beyond 3 sigma of the prior and flips slower than
/// flip_max_s are `degraded` with --selfcal (whose flip updates they defeat), notes without it.
/// No flip measured although the platforms moved (`platforms_moved`, or motion the check saw):
/// `flips_unchecked` (degraded), a wrong header never passes unchecked and unsaid.
void add_flip_check_findings(HealthReport& h, const FlipCheckResult& r, const EstimatorConfig& cfg,
                             bool platforms_moved = false);

/// Standstills too short to use: no update, or every update at one position pair while this many
/// rests or more were discarded as shorter than min_standstill_s: `standstills_too_short` (failed),
/// which replaces `no_update` / `never_flipped` (the platforms did move). `rests`: the detector's.
inline constexpr std::uint64_t kTooShortRests = 4;
void add_short_standstill_finding(HealthReport& h, const StandstillDetector::ShortRests& rests,
                                  double min_standstill_s, std::uint64_t updates, std::size_t positions);

/// A log with a header and no data rows: `no_data_rows` (failed) replaces every other finding.
void add_no_rows_finding(HealthReport& h);

/// Watches the updates of one pass and gives the verdict at the end.
class HealthMonitor {
 public:
  explicit HealthMonitor(const HealthLimits& limits = {}) : limits_(limits), lock_(limits.lock_sigma_dps), steady_(limits.lock_sigma_dps) {}
  /// Every update the filter made (accepted or rejected), with the filter after it.
  void on_update(const UpdateRecord& rec, const DriftlessFilter& filter);
  /// The verdict after the pass: `filter` is the filter at the end, `duration_s` the log's span,
  /// `lag` what the signal-chain check found (none: not checked).
  HealthReport finish(const DriftlessFilter& filter, double duration_s, const LagCheckResult& lag = {}) const;

 private:
  struct PositionCount {
    std::uint64_t updates = 0, rejected = 0;
  };
  void add_gate_findings(HealthReport& h) const;
  void add_nis_findings(HealthReport& h) const;
  void add_lock_findings(HealthReport& h, const DriftlessFilter& filter, double duration_s) const;
  void add_lock_lost_finding(HealthReport& h, const DriftlessFilter& filter) const;
  std::vector<std::array<double, 2>> positions_if_never_apart() const;
  bool settled_sigma(double& sigma_dps, double& interval_s) const;
  bool add_unreachable_finding(HealthReport& h) const;
  SteadyStatePrediction steady_at_settled(double settled_dps) const;

  HealthLimits limits_;
  LockState lock_;        // the lock now, with hysteresis
  bool locked_ = false;   // locked at some update
  std::uint64_t lock_losses_ = 0;
  SteadyStateWatch steady_;  // the closed-form steady state from the first updates' schedule
  double lock_t_s_ = kNaN, lost_t_s_ = kNaN;
  std::uint64_t updates_ = 0, rejected_ = 0;
  struct NisSums {
    std::uint64_t n = 0;
    double sum = 0.0, dof = 0.0;
  };
  NisSums nis_before_, nis_locked_;  // accepted updates before lock / from the lock on
  std::map<std::pair<long, long>, PositionCount> by_position_;  // key: positions in 0.1 deg
  double last_rejected_t_s_ = kNaN, last_rejected_nis_ = kNaN;
  // the last kSettleHistory updates before the lock: time (s) and the largest correction sigma
  // after each (deg/s), oldest first; whether it had settled (settled_sigma)
  static constexpr std::size_t kSettleHistory = 8;
  std::vector<std::array<double, 3>> before_lock_;  // ... and the component (0..5) of that sigma
};

}  // namespace driftless::est
