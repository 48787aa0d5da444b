#include "estimator/pipeline.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include <Eigen/Cholesky>

#include "estimator/accel_check.hpp"
#include "estimator/flip_check.hpp"
#include "estimator/lock_state.hpp"
#include "estimator/stats.hpp"

namespace driftless::est {
namespace {

// normalised estimation error squared e^T P^-1 e (Cholesky solve, no inverse)
double nees(const Vector6d& e, const Matrix6d& P) { return e.dot(P.llt().solve(e)); }

// NEES and error statistics of the accepted updates against the log's true_bias columns
class TruthScore {
 public:
  explicit TruthScore(TruthStats& ts, double band_p) : ts_(ts), band_p_(band_p) {
    ts_.nees_band_lo = chi2_quantile(0.5 * (1.0 - band_p), 6.0);
    ts_.nees_band_hi = chi2_quantile(1.0 - 0.5 * (1.0 - band_p), 6.0);
  }

  void add(const DriftlessFilter& filter, const Sample& s) {
    if (!s.true_bias1_dps.allFinite() || !s.true_bias2_dps.allFinite()) return;
    Vector6d truth;
    truth << s.true_bias1_dps, s.true_bias2_dps;
    const Vector6d e = filter.bias_dps() - truth;
    const Matrix6d& P = filter.covariance_dps2();
    const double v = nees(e, P);
    nees_sum_ += v;
    nees_in_ += (v >= ts_.nees_band_lo && v <= ts_.nees_band_hi) ? 1 : 0;
    for (int i = 0; i < 6; ++i) {
      comp_in_ += std::fabs(e[i]) <= 3.0 * std::sqrt(P(i, i)) ? 1 : 0;
      ++comp_n_;
    }
    err2_per_update_.push_back(e.squaredNorm() / 6.0);
    ts_.final_error_dps = e;
  }

  void finish() {
    if (err2_per_update_.empty()) return;
    const std::size_t n = err2_per_update_.size();
    double a = 0.0, b = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      a += err2_per_update_[i];
      if (i >= n / 2) b += err2_per_update_[i];
    }
    ts_.updates = n;
    ts_.bias_error_rms_dps = std::sqrt(a / double(n));
    ts_.bias_error_rms_second_half_dps = std::sqrt(b / double(n - n / 2));
    ts_.nees_mean = nees_sum_ / double(n);
    ts_.nees_mean_band_lo = chi2_quantile(0.5 * (1.0 - band_p_), 6.0 * double(n)) / double(n);
    ts_.nees_mean_band_hi = chi2_quantile(1.0 - 0.5 * (1.0 - band_p_), 6.0 * double(n)) / double(n);
    ts_.nees_fraction_in_band = double(nees_in_) / double(n);
    ts_.within_3sigma_fraction = double(comp_in_) / double(comp_n_);
  }

 private:
  TruthStats& ts_;
  double band_p_;
  std::vector<double> err2_per_update_;  // mean squared component error per update
  double nees_sum_ = 0.0;
  std::size_t nees_in_ = 0, comp_in_ = 0, comp_n_ = 0;
};

// per-sample error statistics over the evaluation window (WindowStats)
class WindowScore {
 public:
  WindowScore(WindowStats& ws, double start_s) : ws_(ws), start_s_(start_s) { ws_.start_s = start_s; }

  void add(const DriftlessFilter& filter, const Sample& s) {
    if (!(s.t_s >= start_s_) || !s.true_bias1_dps.allFinite() || !s.true_bias2_dps.allFinite()) return;
    Vector6d truth;
    truth << s.true_bias1_dps, s.true_bias2_dps;
    const Vector6d e = filter.bias_dps() - truth;
    sum2_ += e.squaredNorm();
    comp2_ += e.cwiseAbs2();
    max_ = std::max(max_, e.cwiseAbs().maxCoeff());
    // P carried to this sample (it refers to the last update's time; the bias wanders on)
    nees_ += nees(e, filter.covariance_dps2_at(s.t_s)) / 6.0;
    last_ = e;
    ++n_;
  }

  void on_update(const UpdateRecord& u) {
    if (!u.accepted || !std::isfinite(u.nis) || !(u.t_s >= start_s_)) return;
    nis_ += u.nis / u.dim;
    ++n_nis_;
  }

  void finish(const DriftlessFilter& filter) {
    ws_.sigma_rms_final_dps = std::sqrt(filter.covariance_dps2().trace() / 6.0);
    ws_.nis_updates = n_nis_;
    if (n_nis_ > 0) ws_.nis_per_dof_mean = nis_ / double(n_nis_);
    if (n_ == 0) return;
    const double n = double(n_);
    ws_.available = true;
    ws_.samples = n_;
    ws_.bias_error_rms_dps = std::sqrt(sum2_ / (6.0 * n));
    for (int i = 0; i < 6; ++i) ws_.component_rms_dps[i] = std::sqrt(comp2_[i] / n);
    ws_.bias_error_max_dps = max_;
    ws_.final_error_dps = last_;
    ws_.nees_per_dof_mean = nees_ / n;
  }

 private:
  WindowStats& ws_;
  double start_s_;
  double sum2_ = 0.0, max_ = 0.0, nees_ = 0.0, nis_ = 0.0;
  Vector6d comp2_ = Vector6d::Zero(), last_ = Vector6d::Zero();
  std::size_t n_ = 0, n_nis_ = 0;
};

void add_reader_warnings(const log::LogReader& reader, EstimateSummary& sum) {
  sum.rows_missing_gyro = reader.rows_with_missing_gyro();
  if (sum.rows_missing_gyro > 0) {
    sum.warnings.push_back(std::to_string(sum.rows_missing_gyro) +
                           " rows had a missing or NaN gyro value and were skipped");
  }
  if (reader.dropped_truncated_row()) sum.warnings.push_back("the last row was cut off and dropped");
  if (reader.gap_count() > 0) {
    const auto& g = reader.gaps();
    const auto longest = std::max_element(g.begin(), g.end(), [](const log::Gap& a, const log::Gap& b) {
      return a.length_s < b.length_s;
    });
    sum.warnings.push_back(std::to_string(reader.gap_count()) + " time gap(s) longer than " +
                           std::to_string(reader.gap_threshold_s()) + " s in the log, the longest " +
                           std::to_string(longest->length_s) + " s after t = " + std::to_string(longest->t_before_s) +
                           " s (line " + std::to_string(longest->line) +
                           "): an attitude comparison stops at the first one after its start");
  }
  if (reader.rows_saturated() > 0) {
    sum.warnings.push_back(std::to_string(reader.rows_saturated()) +
                           " rows have a gyro value at the stated gyro_full_scale_dps (saturated)");
  }
}

void add_filter_warnings(const DriftlessFilter& filter, EstimateSummary& sum) {
  if (sum.counters.updates == 0 && sum.rows > 0) {
    sum.warnings.push_back("no filter update: no standstill of at least min_standstill_s was found");
  }
  // paper mode's schedule and rest-angle mismatches are health findings (add_paper_mode_findings)
  for (const auto& r : sum.relocks) {
    // the last of them is not counted as rejected: the re-lock widens P and takes it
    const int n = filter.config().gate_relock_after;
    sum.warnings.push_back("the NIS gate refused " + std::to_string(n) + " updates in a row (" +
                           std::to_string(n - 1) + " rejected; the last one taken after widening P); the filter "
                           "re-locked at t = " + std::to_string(r.t_s) +
                           " s (NIS " + std::to_string(r.nis) + "): a bias jump, a new sensor, or a model "
                           "that does not fit these sensors; " +
                           (std::isfinite(r.locked_again_t_s)
                                ? "locked again at t = " + std::to_string(r.locked_again_t_s) + " s"
                                : std::string("not locked again before the end (corrected.csv: locked = 0)")));
  }
}

void add_stream_warnings(const log::Metadata& meta, EstimateSummary& sum) {
  sum.log_complete = meta.complete();
  if (!sum.log_complete) {
    sum.warnings.push_back("the log says 'complete: false' (" +
                           meta.get("incomplete_reason").value_or("no reason given") +
                           "); results cover the rows present");
  }
  if (!std::isfinite(meta.latitude_deg())) {
    sum.warnings.push_back(
        "no latitude_deg in the log: the Earth rate is removed at latitude 0; the box dwells and --box-at-rest take "
        "the vertical Earth rate as unknown (0 +- 0.0024 deg/s, 1 sigma, for any latitude, on top of box_rest_rate_sigma_dps). "
        "Add '# latitude_deg: ...' to the header for both");
  }
}

AttitudeComparisonOptions comparison_options(const EstimateRunOptions& opt) {
  AttitudeComparisonOptions a;
  a.start_sigma_dps = opt.attitude_start_sigma_dps;
  a.interval_s = opt.attitude_interval_s;
  a.fixed_bias_from = opt.fixed_bias_from;
  a.realign_at_s = opt.realign_at_eval_start ? opt.eval_start_s : kNaN;
  return a;
}

void add_attitude_results(const AttitudeComparison& att, const DriftlessFilter& filter,
                          const EstimateRunOptions& opt, EstimateSummary& sum) {
  sum.attitude_start_s = att.start_s();
  sum.attitude_realign_s = att.realign_s();
  if (att.started()) sum.fixed_bias_dps = att.fixed_bias_dps();
  const AttitudeDrifts drift = att.drifts();
  sum.drift_corrected_deg_per_h = drift.corrected_deg_per_h;
  sum.drift_raw_deg_per_h = drift.raw_deg_per_h;
  sum.drift_fixed_deg_per_h = drift.fixed_deg_per_h;
  sum.drift_net_corrected_deg_per_h = drift.net_corrected_deg_per_h;
  sum.drift_net_raw_deg_per_h = drift.net_raw_deg_per_h;
  sum.drift_net_fixed_deg_per_h = drift.net_fixed_deg_per_h;
  if (att.points() < 2 && sum.attitude_available && !att.started() && sum.rows > 0) {
    // the lock level is the one filter_locked applies: the sigma of the correction b + G f + ...
    char text[320];
    if (std::isfinite(sum.locked_from_t_s)) {
      std::snprintf(text, sizeof text,
                    "no attitude comparison: the filter locked on only at t = %.6g s, too close to the end "
                    "of the log to compare; a longer log, or an attitude start sigma of 0 to compare "
                    "from the log's start",
                    sum.locked_from_t_s);
    } else {
      std::snprintf(text, sizeof text,
                    "no attitude comparison: the filter never locked on (lock: every sigma of the bias "
                    "correction below %.3g deg/s; the largest is %.3g deg/s at the end); an attitude start "
                    "sigma of 0 compares from the log's start",
                    opt.attitude_start_sigma_dps,
                    filter.has_update() ? filter.correction_sigma_dps().maxCoeff() : filter.sigma_dps().maxCoeff());
    }
    sum.warnings.emplace_back(text);
  }
}

// the comparison stopped (no box rate, or a time gap) after it began: the attitude from there on
// is not known; the figures that span it are withheld (the points before it, in attitude.csv, stand)
void withhold_attitude(const DriftlessFilter& filter, EstimateSummary& sum) {
  if (std::isnan(sum.attitude_withheld_from_s)) return;
  sum.drift_corrected_deg_per_h = sum.drift_raw_deg_per_h = sum.drift_fixed_deg_per_h = kNaN;
  sum.drift_net_corrected_deg_per_h = sum.drift_net_raw_deg_per_h = sum.drift_net_fixed_deg_per_h = kNaN;
  sum.final_corrected = sum.final_raw = sum.final_fixed = kAttitudeErrorUnknown;
  const std::string from = "attitude withheld from t = " + std::to_string(sum.attitude_withheld_from_s) + " s: ";
  const std::string tail = "; attitude.csv stops there and the drift figures are not given. ";
  switch (sum.attitude_withheld_why) {
    case AttitudeWithheld::kBothFlipping:
      sum.warnings.push_back(from + "with 'standstill: gyro' " + std::to_string(filter.counters().simultaneous_flips) +
                             " flip(s) moved both platforms at once, and while both turn neither sensor reads the box "
                             "rate" + tail + "Flip one platform at a time, or log the platform angles (plat1_deg, plat2_deg)");
      break;
    case AttitudeWithheld::kTimeGap:
      sum.warnings.push_back(from + "the log has no rows for " + std::to_string(sum.attitude_withheld_gap_s) +
                             " s there, and how far the box turned in that gap is unknown" + tail +
                             "Log without gaps, or compare the pieces between gaps as separate logs");
      break;
    case AttitudeWithheld::kNoBoxRate:
    case AttitudeWithheld::kNo:
      sum.warnings.push_back(from + "no platform rested with a known angle, and no moving one had its angle read, so no "
                             "sensor gave the box rate" + tail + "Log plat1_deg and plat2_deg while the platforms move");
      break;
  }
}

// the attitude comparison stops at the first sample after its start that follows a time gap, or
// where no sensor gave the box rate (a row the filter could not use at all is not one)
void check_attitude_input(const Sample& s, double prev_t_s, double gap_s, const DriftlessFilter& filter,
                          const AttitudeComparison& att, EstimateSummary& sum) {
  if (!att.started() || !std::isnan(sum.attitude_withheld_from_s)) return;
  if (s.t_s - prev_t_s > gap_s) {
    sum.attitude_withheld_from_s = prev_t_s;
    sum.attitude_withheld_why = AttitudeWithheld::kTimeGap;
    sum.attitude_withheld_gap_s = s.t_s - prev_t_s;
  } else if (!filter.output().rate_body_dps.allFinite() && filter.output().status != PushStatus::kInvalid) {
    // (a row without a gyro value is bridged as before: the integrator holds the last rate)
    sum.attitude_withheld_from_s = s.t_s;
    sum.attitude_withheld_why =
        filter.output().both_moving ? AttitudeWithheld::kBothFlipping : AttitudeWithheld::kNoBoxRate;
  }
}

// adds the pair to `seen` unless a pair within 0.1 deg is there (a handful of pairs per log)
void note_position(std::vector<std::array<double, 2>>& seen, double p1_deg, double p2_deg) {
  for (const auto& p : seen)
    if (std::fabs(p[0] - p1_deg) < 0.1 && std::fabs(p[1] - p2_deg) < 0.1) return;
  if (seen.size() < 16) seen.push_back({p1_deg, p2_deg});
}

// ref_q in another convention than the log's (or of another body): the errors against it say
// nothing of the drift, so the figures are withheld (attitude.csv stays, for a look)
void withhold_attitude_reference(EstimateSummary& sum) {
  const RefFitVerdict v = sum.reference.verdict;
  if (v != RefFitVerdict::kOtherConvention && v != RefFitVerdict::kNoFit) return;
  sum.drift_corrected_deg_per_h = sum.drift_raw_deg_per_h = sum.drift_fixed_deg_per_h = kNaN;
  sum.drift_net_corrected_deg_per_h = sum.drift_net_raw_deg_per_h = sum.drift_net_fixed_deg_per_h = kNaN;
  AttitudeError none;
  none.roll_deg = none.pitch_deg = none.heading_deg = none.angle_deg = kNaN;
  sum.final_corrected = sum.final_raw = sum.final_fixed = none;
}

// the flip-turn check (flip_check.hpp): one sample, the readings as logged (the check takes the
// biases from the rest before each flip); a flip that ended is measured in the frames of its start angles
void check_flip(FlipCheck& check, const DriftlessFilter& filter, const Sample& s) {
  const SampleOutput& o = filter.output();
  if (!check.push(o.t_s, s.gyro1_dps, s.gyro2_dps, o.plat1_deg, o.plat2_deg, o.at_rest)) return;
  const BoxGeometry& box = filter.geometry();
  check.close({filter.body_from_sensor(1, check.start_deg(1)), filter.body_from_sensor(2, check.start_deg(2)),
               box.hinge1_axis.normalized(), box.hinge2_axis.normalized()});
}

// after an update: is the correction locked (the lock level with lock_state.hpp's hysteresis)?
// Records the first lock, each gate re-lock, each loss of the lock and when it came back.
// `t_s` is the time of the sample whose push made the update: the first row it corrects.
bool lock_step(LockState& lock, const DriftlessFilter& filter, const UpdateRecord& u, double t_s,
               EstimateSummary& sum) {
  if (u.relocked) sum.relocks.push_back({u.t_s, u.relock_nis, kNaN});
  // the lock with hysteresis (lock_state.hpp): a sigma that only crosses the level keeps it
  if (lock.on_update(filter.correction_sigma_dps().maxCoeff(), u.relocked) == LockState::Change::kLost) {
    sum.lock_losses.push_back({u.t_s, filter.correction_sigma_dps().maxCoeff(), u.relocked, kNaN});
  }
  if (!lock.locked()) return false;
  if (!sum.lock_losses.empty() && !std::isfinite(sum.lock_losses.back().locked_again_t_s)) {
    sum.lock_losses.back().locked_again_t_s = t_s;
  }
  if (!std::isfinite(sum.locked_from_t_s)) sum.locked_from_t_s = t_s;
  if (!sum.relocks.empty() && !std::isfinite(sum.relocks.back().locked_again_t_s)) {
    sum.relocks.back().locked_again_t_s = t_s;
  }
  return true;
}

// the findings about the input, each ahead of those it causes (the last put first leads): the
// paper schedule, the flip set-up, the gyro tracker's, then the reader's (a dead axis leads), and
// the attitude withheld last
void add_input_findings(const log::Metadata& meta, const log::LogReader* reader, const EstimatorConfig& cfg,
                        const DriftlessFilter& filter, const std::vector<std::array<double, 2>>& positions,
                        EstimateSummary& sum) {
  if (cfg.mode == FilterMode::kPaper) add_paper_mode_findings(sum.health, filter.counters(), filter.geometry().flip_angle_deg);
  if (sum.health.verdict != HealthVerdict::kOk) {
    add_flip_setup_findings(sum.health, filter.geometry(), positions, sum.counters.updates);
  }
  // rests shorter than min_standstill_s: the cause of no update, or of updates at one position only
  add_short_standstill_finding(sum.health, filter.standstill().short_rests(), cfg.min_standstill_s,
                               sum.counters.updates, positions.size());
  if (cfg.standstill == StandstillSource::kPlatformColumns && sum.counters.updates == 0) {
    add_angle_jitter_finding(sum.health, filter.standstill().angle_jitter(), cfg.angle_tolerance_deg);
  }
  if (cfg.standstill == StandstillSource::kGyroSignal) {
    add_gyro_standstill_findings(sum.health, filter.standstill().gyro_tracker(), filter.geometry().flip_angle_deg);
  }
  if (reader != nullptr) {
    add_stamp_rate_finding(sum.health, meta.sample_rate_hz(), reader->stamp_rate_median_hz(),
                           reader->stamp_rate_mean_hz());
    add_stamp_unit_finding(sum.health, meta.sample_rate_hz(), reader->stamp_rate_median_hz(), reader->rows_read());
    add_saturation_findings(sum.health, reader->suspected_clipping(), reader->rows_read());
    add_dead_axis_findings(sum.health, reader->dead_channels());
  }
  add_attitude_withheld_finding(sum.health, sum.attitude_withheld_why, sum.attitude_withheld_from_s,
                                sum.attitude_withheld_why == AttitudeWithheld::kTimeGap
                                    ? sum.attitude_withheld_gap_s
                                    : double(sum.counters.simultaneous_flips));
}

// what drove the g-sensitivity states when the log has no accel columns
void add_gravity_source_warning(const DriftlessFilter& filter, EstimateSummary& sum) {
  if (!filter.has_gsens_states() || sum.rows == 0) return;
  if (sum.gravity_source == GravitySource::kRefQ) {
    const EstimatorConfig& c = filter.config();
    sum.warnings.push_back(gravity_from_ref_q_note(c.ref_gravity_accel_sigma_g, c.ref_gravity_speed_mps));
  } else if (sum.gravity_source == GravitySource::kNone) {
    sum.warnings.push_back(
        "g-sensitivity cannot be estimated without accel columns or ref_q: log them (accel1_*/accel2_*, or "
        "ref_qw..ref_qz); the g-sensitivity states keep their prior sigma, the flip updates were made without "
        "them (their prior variance in R) and the box dwells not at all");
  }
}

// the pass itself; `reader` (optional) adds the log reader's findings to the warnings
EstimateSummary run_pass(const log::Metadata& meta, std::uint32_t fields, const SampleSource& next,
                         const log::LogReader* reader, const EstimatorConfig& cfg, EstimateSink* sink,
                         const EstimateRunOptions& opt, bool (*should_stop)()) {
  EstimateSummary sum;
  // no accel columns but ref_q: the self-calibration takes gravity from ref_q (accel_check.hpp)
  sum.gravity_source = cfg.self_calibration ? gravity_source(fields) : GravitySource::kNone;
  EstimatorConfig run_cfg = cfg;
  run_cfg.gravity_from_ref_q = sum.gravity_source == GravitySource::kRefQ;
  DriftlessFilter filter(run_cfg, box_geometry_from_metadata(meta));
  filter.set_update_observer(opt.update_observer);
  add_stream_warnings(meta, sum);
  const bool have_truth = (fields & kFieldTrueBias) != 0;
  sum.attitude_available = (fields & kFieldRefQ) != 0;
  sum.truth.available = have_truth;
  AttitudeComparison att(meta.latitude_deg(), comparison_options(opt));
  TruthScore score(sum.truth, opt.nees_band_probability);
  WindowScore window(sum.window, opt.eval_start_s);
  const bool use_window = have_truth && std::isfinite(opt.eval_start_s);
  HealthMonitor health(opt.health);
  LagCheck lag(filter.geometry().sample_rate_hz);
  FlipCheck flips(cfg.flip_max_s, cfg.settle_s);
  ReferenceCheck ref_check;
  BoxMotionCheck box_motion;
  AccelCheck accel_check;
  const bool check_accel = (fields & kFieldAccel) != 0;

  // the lock state changes only at updates (P shrinks there; a gate re-lock widens it)
  bool locked = false;
  LockState lock(opt.attitude_start_sigma_dps);
  std::vector<std::array<double, 2>> positions;  // the position pairs of the updates (to 0.1 deg)
  UpdateRecord first_update;
  auto on_update = [&](PushStatus st, const Sample& s) {
    if (st != PushStatus::kUpdated && st != PushStatus::kRejected) return;
    const UpdateRecord& u = filter.last_update();
    note_position(positions, u.plat1_deg, u.plat2_deg);
    if (u.index == 0) first_update = u;
    locked = lock_step(lock, filter, u, s.t_s, sum);
    if (sink != nullptr) sink->on_update(u, filter.covariance_dps2(), s, locked);
    health.on_update(u, filter);
    if (have_truth && st == PushStatus::kUpdated) score.add(filter, s);
    if (use_window) window.on_update(u);
  };

  const double gap_s = gap_threshold_s(1.0 / filter.geometry().sample_rate_hz);
  double prev_t_s = kNaN;
  Sample s;
  while (next(s)) {
    if (should_stop != nullptr && (sum.rows & 4095u) == 0 && should_stop()) {
      sum.warnings.push_back("stopped early at t = " + std::to_string(s.t_s) + " s (interrupted)");
      break;
    }
    ++sum.rows;
    if (!std::isfinite(sum.t_first_s)) sum.t_first_s = s.t_s;
    sum.t_last_s = s.t_s;
    if (run_cfg.gravity_from_ref_q) gravity_from_ref_q(filter, s);
    const PushStatus st = filter.push(s);
    if (check_accel) accel_check.push(s, filter.output().at_rest);
    on_update(st, s);  // first: the row that made an update carries the state after it
    lag.push(s, filter);
    check_flip(flips, filter, s);
    if (sum.attitude_available) ref_check.push(s, filter);
    box_motion.push(s, filter.output());
    sum.samples_locked += locked ? 1 : 0;
    if (sink != nullptr) sink->on_sample(s, filter.output(), locked);
    if (use_window) window.add(filter, s);

    // attitude: the comparison starts at the first finite ref_q once the filter has locked on
    // (every bias sigma below attitude_start_sigma_dps); it stops where no sensor reads the box
    // rate or after a time gap
    check_attitude_input(s, prev_t_s, gap_s, filter, att, sum);
    prev_t_s = s.t_s;
    AttitudePoint ap;
    if (std::isnan(sum.attitude_withheld_from_s) && att.push(s, filter, ap)) {
      sum.final_corrected = ap.corrected;
      sum.final_raw = ap.raw;
      sum.final_fixed = ap.fixed;
      if (sink != nullptr) sink->on_attitude(ap);
    }
  }
  // a log that ends at rest (or never moved) still gives its last standstill
  if (sum.rows > 0) on_update(filter.finish(), s);

  if (reader != nullptr) add_reader_warnings(*reader, sum);
  if (sum.rows == 0) sum.warnings.push_back("the log holds no rows");
  add_gravity_source_warning(filter, sum);
  sum.counters = filter.counters();
  add_filter_warnings(filter, sum);
  sum.bias_dps = filter.bias_dps();
  sum.sigma_dps = filter.sigma_dps();
  sum.temp_states = filter.has_temp_states();
  sum.temp_coef_dps_per_degc = filter.temp_coef_dps_per_degc();
  sum.temp_coef_sigma_dps_per_degc = filter.temp_coef_sigma_dps_per_degc();
  sum.temp_ref_c = filter.temperature_ref_c();
  sum.gsens_states = filter.has_gsens_states();
  sum.scale_states = filter.has_scale_states();
  for (int i = 0; i < 2; ++i) {
    sum.gsens_dps_per_g[static_cast<std::size_t>(i)] = filter.g_sensitivity_dps_per_g(i + 1);
    sum.gsens_sigma_dps_per_g[static_cast<std::size_t>(i)] = filter.g_sensitivity_sigma_dps_per_g(i + 1);
    sum.scale_misalign_frac[static_cast<std::size_t>(i)] = filter.scale_misalign(i + 1);
    sum.scale_misalign_sigma_frac[static_cast<std::size_t>(i)] = filter.scale_misalign_sigma(i + 1);
  }
  sum.correction_sigma_dps = filter.correction_sigma_dps();
  sum.stop_states = filter.has_stop_states();
  sum.stop_angle_deg = filter.stop_angle_deg();
  sum.stop_angle_sigma_deg = filter.stop_angle_sigma_deg();
  add_attitude_results(att, filter, opt, sum);
  withhold_attitude(filter, sum);
  sum.reference = ref_check.finish();
  withhold_attitude_reference(sum);
  score.finish();
  if (use_window) window.finish(filter);
  sum.health = health.finish(filter, sum.rows > 0 ? sum.t_last_s - sum.t_first_s : 0.0, lag.finish());
  sum.health.gravity_source = sum.gravity_source;
  name_prior_rejection(sum.health, first_update);
  // the flip check's findings first: the input findings put first lead them (a clipping gyro or
  // rests away from the stops make the flip turns disagree with the angles)
  // (a fixed schedule of positions has no motion in it to check: not "unchecked" there)
  add_flip_check_findings(sum.health, flips.finish(), cfg,
                          positions.size() > 1 && cfg.standstill != StandstillSource::kSchedule);
  add_input_findings(meta, reader, cfg, filter, positions, sum);
  add_reference_finding(sum.health, sum.reference);
  sum.box_motion = box_motion.finish();
  sum.health.box_motion = sum.box_motion;
  sum.health.ref_q_logged = (fields & kFieldRefQ) != 0;
  sum.health.accel_logged = (fields & kFieldAccel) != 0;
  add_box_motion_finding(sum.health, sum.box_motion, cfg.box_at_rest);
  add_vertical_finding(sum.health, filter, sum.box_motion);
  add_clipped_flips_finding(sum.health, filter, sum.box_motion);
  // accel columns in another unit, or empty: ahead of everything they spoil
  if (check_accel) add_accel_findings(sum.health, accel_check.finish(), cfg.self_calibration);
  // an uncertain calibration applied as exact (no self-calibration to refine it) leads them all
  if (!cfg.self_calibration) add_calib_finding(sum.health, cfg.calibration);
  // a header and no data: nothing else can be said
  if (sum.rows == 0) add_no_rows_finding(sum.health);
  return sum;
}

}  // namespace

EstimateSummary run_estimate(log::LogReader& reader, const EstimatorConfig& cfg, EstimateSink* sink,
                             const EstimateRunOptions& opt, bool (*should_stop)()) {
  return run_pass(reader.metadata(), reader.fields(), [&reader](Sample& s) { return reader.next(s); }, &reader,
                  cfg, sink, opt, should_stop);
}

EstimateSummary run_estimate(const log::Metadata& meta, const log::LogReader& reader, std::uint32_t fields,
                             const SampleSource& next, const EstimatorConfig& cfg, EstimateSink* sink,
                             const EstimateRunOptions& opt, bool (*should_stop)()) {
  return run_pass(meta, fields, next, &reader, cfg, sink, opt, should_stop);
}

EstimateSummary run_estimate(const log::Metadata& meta, std::uint32_t fields, const SampleSource& next,
                             const EstimatorConfig& cfg, EstimateSink* sink, const EstimateRunOptions& opt,
                             bool (*should_stop)()) {
  return run_pass(meta, fields, next, nullptr, cfg, sink, opt, should_stop);
}

}  // namespace driftless::est
