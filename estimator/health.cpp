#include "estimator/health.hpp"

#include <algorithm>
#include <cmath>

#include "estimator/stats.hpp"

namespace driftless::est {
namespace {

long tenth_deg(double deg) { return std::isfinite(deg) ? std::lround(deg * 10.0) : 1L << 40; }

// a finding of severity ok is a note: it does not change the verdict
void add(HealthReport& h, HealthFinding f) {
  if (f.severity == HealthVerdict::kFailed) h.verdict = HealthVerdict::kFailed;
  else if (f.severity == HealthVerdict::kDegraded && h.verdict == HealthVerdict::kOk) h.verdict = HealthVerdict::kDegraded;
  h.findings.push_back(std::move(f));
}

// `first`'s findings ahead of h's (they are the others' cause); the verdict is the worse of both
void put_first(HealthReport& h, HealthReport&& first) {
  if (h.verdict == HealthVerdict::kFailed || (h.verdict == HealthVerdict::kDegraded && first.verdict == HealthVerdict::kOk))
    first.verdict = h.verdict;
  for (HealthFinding& f : h.findings) first.findings.push_back(std::move(f));
  h.findings = std::move(first.findings);
  h.verdict = first.verdict;
}

}  // namespace

void add_paper_mode_findings(HealthReport& h, const FilterCounters& counters, double flip_angle_deg) {
  const std::uint64_t n = counters.paper_standstills;
  if (n == 0) return;
  const auto severity = [n](std::uint64_t off) {
    return 2 * off >= n ? HealthVerdict::kFailed : HealthVerdict::kDegraded;
  };
  HealthReport first;
  if (counters.rest_angle_mismatches > 0) {
    HealthFinding f;
    f.cause = HealthCause::kPaperRestAngles;
    f.severity = severity(counters.rest_angle_mismatches);
    f.value = double(counters.rest_angle_mismatches);
    f.suggested = counters.rest_angle_mismatch_deg;
    f.sigma = flip_angle_deg;
    f.count = n;
    add(first, std::move(f));
  }
  if (counters.schedule_mismatches > 0) {
    HealthFinding f;
    f.cause = HealthCause::kPaperSchedule;
    f.severity = severity(counters.schedule_mismatches);
    f.value = double(counters.schedule_mismatches);
    f.count = n;
    add(first, std::move(f));
  }
  put_first(h, std::move(first));
}

void add_saturation_findings(HealthReport& h, const std::vector<ClippedChannel>& clipped, std::uint64_t rows) {
  if (clipped.empty() || rows == 0) return;
  HealthReport first;
  for (const ClippedChannel& c : clipped) {
    HealthFinding f;
    f.cause = HealthCause::kSaturation;
    f.value = double(c.samples) / double(rows);
    f.suggested = c.level_dps;
    f.components = {c.channel};
    // a clip while a platform turns (a fast flip) leaves the standstills, which the bias updates
    // average, untouched: a note; inside them the rail enters the biases
    const double at_rest = double(c.samples_at_rest) / double(rows);
    f.severity = c.samples_at_rest < ClipDetector::kMinSamples ? HealthVerdict::kOk
                 : at_rest >= kSaturationFailedFraction       ? HealthVerdict::kFailed
                                                              : HealthVerdict::kDegraded;
    add(first, std::move(f));
  }
  put_first(h, std::move(first));
}

namespace {

HealthCause flip_cause(FlipTurn k) {
  switch (k) {
    case FlipTurn::kGyroRadPerS: return HealthCause::kFlipGyroUnit;
    case FlipTurn::kAngleRadians: return HealthCause::kFlipAngleUnit;
    case FlipTurn::kTimeMs:
    case FlipTurn::kTimeUs: return HealthCause::kFlipTimeUnit;
    case FlipTurn::kStuck: return HealthCause::kFlipNotSeen;
    case FlipTurn::kSign: return HealthCause::kFlipAngleSign;
    case FlipTurn::kWrapped: return HealthCause::kFlipWrapped;
    case FlipTurn::kSwapped: return HealthCause::kFlipSensorsSwapped;
    case FlipTurn::kAxis: return HealthCause::kFlipAxis;
    case FlipTurn::kAgrees:
    case FlipTurn::kOther: break;
  }
  return HealthCause::kFlipTurnRatio;
}

// failed when most of the flips of `platforms` that show `kind` disagree with their angle columns:
// a wrong unit, hinge or sign on one platform makes every estimate wrong, whatever the other
// platform's flips say; a note when at most one in kLoneFlipsPer of at least kLoneFlipsMin
// disagree (no header or unit error shows in so few: a jolt of the box or a clip during that
// flip; the twin's Fig. 9 pan/tilt, 1 of 42); else degraded (a platform that stuck half-way)
constexpr std::uint64_t kLoneFlipsMin = 10, kLoneFlipsPer = 20;
HealthVerdict disagree_severity(const FlipCheckResult& r, FlipTurn kind, const std::vector<int>& platforms) {
  std::uint64_t flips = 0, bad = 0;
  for (int p : platforms) {
    const PlatformFlipSummary& s = r.platform[static_cast<std::size_t>(p - 1)];
    if (s.of(kind) == 0) continue;
    flips += s.flips;
    bad += s.flips - s.of(FlipTurn::kAgrees) - s.of(FlipTurn::kWrapped);
  }
  if (2 * bad > flips) return HealthVerdict::kFailed;
  return flips >= kLoneFlipsMin && bad * kLoneFlipsPer <= flips ? HealthVerdict::kOk : HealthVerdict::kDegraded;
}

// one finding for the flips of `kind` on the platforms that had any (a unit error shows on both);
// `note`: a note whatever the count, else disagree_severity()
void add_flip_kind(HealthReport& first, const FlipCheckResult& r, FlipTurn kind, const std::vector<int>& platforms,
                   bool note = false) {
  HealthFinding f;
  f.cause = flip_cause(kind);
  f.severity = note ? HealthVerdict::kOk : disagree_severity(r, kind, platforms);
  f.sigma = kNaN;
  const int k = static_cast<int>(kind);
  std::uint64_t most = 0;
  for (int p : platforms) {
    const PlatformFlipSummary& s = r.platform[static_cast<std::size_t>(p - 1)];
    if (s.count[k] == 0) continue;
    f.components.push_back(p);
    f.count += s.count[k];
    f.suggested = (std::isnan(f.suggested) ? 0.0 : f.suggested) + double(s.flips);
    if (!(f.sigma <= s.first_t_s[k])) f.sigma = s.first_t_s[k];
    if (s.count[k] > most) {  // the ratio of the platform with most such flips
      most = s.count[k];
      f.value = s.median_ratio[k];
      for (int i = 0; i < 3; ++i) {
        f.measured_axis[static_cast<std::size_t>(i)] = s.axis_sensor[i];
        f.header_axis[static_cast<std::size_t>(i)] = s.hinge_sensor[i];
      }
    }
  }
  if (f.count > 0) add(first, std::move(f));
}

// a scale error along platform p's hinge beyond 3 sigma of its prior (its unclipped agreeing flips)
void add_flip_scale(HealthReport& first, const PlatformFlipSummary& s, int p, const EstimatorConfig& cfg,
                    HealthVerdict severity) {
  const double ratio = s.median_ratio[static_cast<int>(FlipTurn::kAgrees)];
  if (s.scale_flips < 2 || !(std::fabs(ratio - 1.0) > 3.0 * cfg.scale_misalign_sigma_frac)) return;
  HealthFinding f;
  f.cause = HealthCause::kFlipScale;
  f.severity = severity;
  f.value = ratio;
  // the spread's standard error and what the rest before each flip cannot take out: the
  // g-sensitivity's change as the platform turns (its prior x 1 g over the window), in quadrature
  f.sigma = std::hypot(s.median_ratio_sigma[static_cast<int>(FlipTurn::kAgrees)],
                       cfg.gsens_sigma_dps_per_g * s.rate_to_ratio_s_per_deg);
  f.components = {p};
  f.count = s.scale_flips;
  f.suggested = double(s.flips);
  add(first, std::move(f));
}

}  // namespace

void add_flip_check_findings(HealthReport& h, const FlipCheckResult& r, const EstimatorConfig& cfg,
                             bool platforms_moved) {
  HealthReport first;
  // nothing measured although the platforms moved: the hinge axes and angle signs went unchecked,
  // and a wrong one makes every estimate wrong (degraded: the estimate may yet be right)
  if (r.flips == 0) {
    if (!platforms_moved && r.windows == 0 && r.clipped == 0) return;
    HealthFinding f;
    f.cause = HealthCause::kFlipsUnchecked;
    f.count = r.clipped_unusable;
    f.suggested = double(r.windows);
    add(first, std::move(f));
    put_first(h, std::move(first));
    return;
  }
  const bool flip_updates = cfg.self_calibration && cfg.flip_updates;
  const HealthVerdict selfcal = flip_updates ? HealthVerdict::kDegraded : HealthVerdict::kOk;
  for (FlipTurn k : {FlipTurn::kGyroRadPerS, FlipTurn::kAngleRadians, FlipTurn::kTimeMs, FlipTurn::kTimeUs}) {
    add_flip_kind(first, r, k, {1, 2});
  }
  const bool unit_error = !first.findings.empty();
  // by kind, then platform: a stuck platform's wrong angle also spoils the resting frame in the
  // other platform's flips (the box's rate leaks into their turn: kOther), so the causes go first
  for (FlipTurn k : {FlipTurn::kSwapped, FlipTurn::kStuck, FlipTurn::kSign, FlipTurn::kAxis, FlipTurn::kOther}) {
    for (int p = 1; p <= 2; ++p) add_flip_kind(first, r, k, {p});
  }
  for (int p = 1; p <= 2; ++p) {
    // the flip updates take Δθ modulo 360 with the turn the gyros saw: wrapped flips are used, a note
    add_flip_kind(first, r, FlipTurn::kWrapped, {p}, true);
    // a scale error along the hinge beyond 3 sigma of its prior: the flip gate rejects its flips
    if (!unit_error) add_flip_scale(first, r.platform[static_cast<std::size_t>(p - 1)], p, cfg, selfcal);
  }
  // flips longer than flip_max_s never become flip updates
  const std::uint64_t slow = r.platform[0].slower_than_max + r.platform[1].slower_than_max;
  if (flip_updates && !unit_error && slow > 0) {
    HealthFinding f;
    f.cause = HealthCause::kFlipsTooSlow;
    f.severity = 2 * slow >= r.flips ? HealthVerdict::kDegraded : HealthVerdict::kOk;
    f.value = std::max(r.platform[0].longest_s, r.platform[1].longest_s);
    f.count = slow;
    f.suggested = double(r.flips);
    add(first, std::move(f));
  }
  put_first(h, std::move(first));
}

void add_dead_axis_findings(HealthReport& h, const std::vector<DeadChannel>& dead) {
  if (dead.empty()) return;
  HealthReport first;
  for (const DeadChannel& d : dead) {
    HealthFinding f;
    f.cause = HealthCause::kDeadAxis;
    f.severity = HealthVerdict::kFailed;
    f.value = d.kind == DeadChannel::Kind::kStuck ? d.value_dps : kNaN;
    f.suggested = double(d.rows);
    f.components = {d.channel};
    add(first, std::move(f));
  }
  for (HealthFinding& f : h.findings) first.findings.push_back(std::move(f));
  h.findings = std::move(first.findings);
  h.verdict = HealthVerdict::kFailed;
}

void add_attitude_withheld_finding(HealthReport& h, AttitudeWithheld why, double t_s, double detail) {
  if (why == AttitudeWithheld::kNo || !std::isfinite(t_s)) return;
  HealthFinding f;
  f.cause = why == AttitudeWithheld::kBothFlipping ? HealthCause::kAttitudeWithheld
            : why == AttitudeWithheld::kTimeGap    ? HealthCause::kAttitudeWithheldGap
                                                   : HealthCause::kAttitudeWithheldNoRate;
  f.value = t_s;
  if (why == AttitudeWithheld::kBothFlipping) f.suggested = detail;
  if (why == AttitudeWithheld::kTimeGap) f.sigma = detail;
  add(h, std::move(f));
}

void add_flip_setup_findings(HealthReport& h, const BoxGeometry& box,
                             const std::vector<std::array<double, 2>>& positions_deg, std::uint64_t updates) {
  HealthReport first;
  const double sin_apart = box.hinge1_axis.normalized().cross(box.hinge2_axis.normalized()).norm();
  if (sin_apart < std::sin(kParallelHingesDeg * kRadPerDeg)) {
    HealthFinding f;
    f.cause = HealthCause::kParallelHinges;
    f.severity = HealthVerdict::kFailed;
    f.value = std::asin(std::min(1.0, sin_apart)) * kDegPerRad;
    add(first, std::move(f));
  }
  if (updates > 0 && positions_deg.size() == 1) {
    HealthFinding f;
    f.cause = HealthCause::kNeverFlipped;
    f.severity = HealthVerdict::kFailed;
    f.positions_deg = positions_deg;
    f.count = updates;
    add(first, std::move(f));
  }
  put_first(h, std::move(first));
}

void add_short_standstill_finding(HealthReport& h, const StandstillDetector::ShortRests& rests,
                                  double min_standstill_s, std::uint64_t updates, std::size_t positions) {
  if (rests.count < kTooShortRests || (updates > 0 && positions > 1)) return;
  // the platforms did rest and move: "never rested" and "never moved" would point the wrong way
  std::erase_if(h.findings, [](const HealthFinding& f) {
    return f.cause == HealthCause::kNoUpdate || f.cause == HealthCause::kNeverFlipped;
  });
  HealthFinding f;
  f.cause = HealthCause::kStandstillsTooShort;
  f.severity = HealthVerdict::kFailed;
  f.count = rests.count;
  f.value = rests.longest_usable_s;
  f.sigma = min_standstill_s;
  f.suggested = rests.longest_logged_s;
  f.positions_deg = {{rests.mean_logged_s(), rests.longest_logged_s}};
  HealthReport first;
  add(first, std::move(f));
  put_first(h, std::move(first));
  h.verdict = HealthVerdict::kFailed;
}

void add_no_rows_finding(HealthReport& h) {
  HealthFinding f;
  f.cause = HealthCause::kNoDataRows;
  f.severity = HealthVerdict::kFailed;
  h.findings.clear();
  h.findings.push_back(std::move(f));
  h.verdict = HealthVerdict::kFailed;
}

void add_angle_jitter_finding(HealthReport& h, const StandstillDetector::AngleJitter& j, double tolerance_deg) {
  if (j.samples == 0 || 2 * j.jittery <= j.samples) return;
  HealthFinding f;
  f.cause = HealthCause::kAngleJitter;
  f.severity = HealthVerdict::kFailed;
  f.value = j.max_change_deg;
  f.sigma = tolerance_deg;
  f.suggested = double(j.jittery) / double(j.samples);
  HealthReport first;
  add(first, std::move(f));
  put_first(h, std::move(first));
}

void name_prior_rejection(HealthReport& h, const UpdateRecord& first) {
  if (first.accepted || first.index != 0) return;
  for (HealthFinding& f : h.findings) {
    if (f.cause != HealthCause::kLoneRejection || f.suggested != first.t_s) continue;
    f.cause = HealthCause::kPriorRejected;
    f.sigma = first.innovation_dps.head(first.dim).cwiseAbs().maxCoeff();
  }
}

bool stamp_rate_off(double stated_hz, double median_hz, double mean_hz) {
  const auto off = [stated_hz](double hz) { return std::fabs(hz / stated_hz - 1.0) > kStampRateTolerance; };
  return std::isfinite(stated_hz) && std::isfinite(median_hz) && std::isfinite(mean_hz) && off(median_hz) &&
         off(mean_hz);
}

double stamp_unit_to_s(double median_interval_s, std::uint64_t rows) {
  if (!(median_interval_s > kMaxPlausibleIntervalS) || rows < kStampUnitMinRows) return kNaN;
  for (double f : {1e-3, 1e-6, 1e-9}) {
    if (median_interval_s * f <= 1.0) return f;
  }
  return kNaN;  // beyond a nanosecond clock's: not a unit mistake that can be named
}

void add_stamp_unit_finding(HealthReport& h, double stated_hz, double median_hz, std::uint64_t rows) {
  if (std::isfinite(stated_hz) || !(median_hz > 0.0)) return;
  // the flip-turn check measured the unit already (flip_time_unit): one finding says it
  for (const HealthFinding& g : h.findings) {
    if (g.cause == HealthCause::kFlipTimeUnit) return;
  }
  const double to_s = stamp_unit_to_s(1.0 / median_hz, rows);
  if (std::isnan(to_s)) return;
  HealthFinding f;
  f.cause = HealthCause::kStampUnit;
  f.severity = HealthVerdict::kFailed;
  f.value = 1.0 / median_hz;
  f.suggested = to_s;
  f.count = rows;
  HealthReport first;
  add(first, std::move(f));
  put_first(h, std::move(first));
}

void add_stamp_rate_finding(HealthReport& h, double stated_hz, double median_hz, double mean_hz) {
  if (!stamp_rate_off(stated_hz, median_hz, mean_hz)) return;
  HealthFinding f;
  f.cause = HealthCause::kStampRate;
  const double ratio = median_hz / stated_hz;
  f.severity = ratio < 0.5 || ratio > 2.0 ? HealthVerdict::kFailed : HealthVerdict::kDegraded;
  f.value = median_hz;
  f.sigma = mean_hz;
  f.suggested = stated_hz;
  HealthReport first;
  add(first, std::move(f));
  put_first(h, std::move(first));
}

void add_gyro_standstill_findings(HealthReport& h, const GyroFlipTracker& tracker, double flip_angle_deg) {
  HealthReport first;
  const GyroFlipTracker::FlipAngleRecord& a = tracker.flip_angles();
  if (a.unlike > 0) {
    HealthFinding f;
    f.cause = HealthCause::kGyroFlipAngle;
    f.severity = 2 * a.unlike >= a.flips ? HealthVerdict::kFailed : HealthVerdict::kDegraded;
    f.value = a.measured_flip_angle_deg;
    f.sigma = flip_angle_deg;
    f.count = a.unlike;
    f.suggested = double(a.flips);
    add(first, std::move(f));
  }
  const GyroFlipTracker::GapRecord& g = tracker.gaps();
  if (g.count > 0) {
    HealthFinding f;
    f.cause = HealthCause::kGyroGapPositions;
    const bool lost = tracker.motion() == GyroFlipTracker::Motion::kUnknown;
    f.severity = lost ? HealthVerdict::kDegraded : HealthVerdict::kOk;
    f.value = g.t_s;
    f.sigma = g.length_s;
    f.suggested = lost ? kNaN : g.recovered_t_s;
    f.count = g.changed;
    add(first, std::move(f));
  }
  const GyroFlipTracker::StartRecord& st = tracker.start();
  if (st.mid_flip) {  // handled: no standstill before the flip ended, then the stop it turned towards
    HealthFinding f;
    f.cause = HealthCause::kGyroStartMidFlip;
    f.severity = HealthVerdict::kOk;
    f.components = {st.platform};
    f.value = st.rate_dps;
    f.sigma = st.t_first_s;
    f.suggested = st.t_known_s;
    f.positions_deg = {st.positions_deg};
    add(first, std::move(f));
  }
  put_first(h, std::move(first));
}

void add_box_motion_finding(HealthReport& h, const BoxMotion& m, bool box_at_rest) {
  // --box-at-rest claims every standstill (a box dwell only a stretch that ref_q, where logged,
  // saw still: the filter refuses the others itself)
  if (!box_at_rest || !box_turned(m)) return;
  HealthFinding f;
  f.cause = HealthCause::kBoxNotAtRest;
  f.value = m.ref_rate_dps;
  f.sigma = m.gyro_change_dps;
  f.suggested = f.value > BoxMotionLimits{}.ref_rate_dps ? m.ref_rate_t_s : m.gyro_change_t_s;
  HealthReport first;
  add(first, std::move(f));
  put_first(h, std::move(first));
}

namespace {

// without --selfcal: G is not modelled; when the updates show an error a bias does not explain and
// the box never paused, its part both sensors share about the vertical is in neither the estimate
// nor its sigma, and nothing in the log observes it
void add_vertical_unmodelled_finding(HealthReport& h, const EstimatorConfig& cfg, const BoxMotion& m) {
  if (cfg.box_at_rest || cfg.calibration.has_g_sensitivity() || !box_turned(m) || m.still_standstills > 0) return;
  const bool misfit = std::any_of(h.findings.begin(), h.findings.end(), [](const HealthFinding& f) {
    return f.severity != HealthVerdict::kOk &&
           (f.cause == HealthCause::kRejections || f.cause == HealthCause::kRejectionsAtPosition ||
            f.cause == HealthCause::kNoiseUnderstated || f.cause == HealthCause::kAllRejected);
  });
  if (!misfit) return;
  HealthFinding f;
  f.cause = HealthCause::kVerticalUnobserved;
  f.value = kNaN;  // not modelled: no sigma
  f.sigma = cfg.gsens_sigma_dps_per_g;
  f.suggested = m.quiet_ref_rate_dps;
  add(h, std::move(f));
}

}  // namespace

void add_vertical_finding(HealthReport& h, const DriftlessFilter& filter, const BoxMotion& m) {
  if (!filter.config().self_calibration) {
    add_vertical_unmodelled_finding(h, filter.config(), m);
    return;
  }
  if (!filter.uses_box_dwells() || !filter.has_gsens_states() || filter.counters().box_dwell_updates > 0) return;
  // a g-sensitivity element times the 1 g along the box vertical: the shared bias's prior
  const double prior_dps = filter.config().gsens_sigma_dps_per_g;
  const double sigma_dps = filter.correction_sigma_dps().maxCoeff();
  if (!(sigma_dps > 0.5 * prior_dps)) return;
  HealthFinding f;
  f.cause = HealthCause::kVerticalUnobserved;
  f.value = sigma_dps;
  f.sigma = prior_dps;
  f.suggested = m.quiet_ref_rate_dps;
  add(h, std::move(f));
}

void add_clipped_flips_finding(HealthReport& h, const DriftlessFilter& filter, const BoxMotion& m) {
  const FilterCounters& c = filter.counters();
  if (!filter.uses_flips() || !(c.flip_clipped > c.flip_updates) || !box_turned(m)) return;
  HealthFinding f;
  f.cause = HealthCause::kClippedFlipsScale;
  f.count = c.flip_clipped;
  f.suggested = double(c.flip_updates);
  f.value = m.ref_rate_dps;
  add(h, std::move(f));
}

void add_reference_finding(HealthReport& h, const ReferenceFit& fit) {
  if (fit.verdict != RefFitVerdict::kOtherConvention && fit.verdict != RefFitVerdict::kNoFit) return;
  HealthFinding f;
  f.cause = HealthCause::kReferenceMismatch;
  f.value = fit.misfit[0];
  f.sigma = fit.misfit[static_cast<std::size_t>(fit.best)];
  f.suggested = fit.verdict == RefFitVerdict::kOtherConvention ? double(static_cast<int>(fit.best)) : kNaN;
  f.count = fit.windows;
  int axis = 0;
  fit.example_gyro_deg.cwiseAbs().maxCoeff(&axis);
  f.components = {axis};
  f.positions_deg = {{fit.example_t_s, fit.example_span_s}, {fit.example_gyro_deg[axis], fit.example_ref_deg[axis]}};
  add(h, std::move(f));
}

void put_findings_first(HealthReport& h, std::vector<HealthFinding> first) {
  if (first.empty()) return;
  HealthReport front;
  for (HealthFinding& f : first) add(front, std::move(f));
  put_first(h, std::move(front));
}

const char* to_string(HealthVerdict v) {
  switch (v) {
    case HealthVerdict::kOk: return "ok";
    case HealthVerdict::kDegraded: return "degraded";
    case HealthVerdict::kFailed: return "failed";
  }
  return "?";
}

void HealthMonitor::on_update(const UpdateRecord& rec, const DriftlessFilter& filter) {
  ++updates_;
  // the lock now, with the hysteresis of lock_state.hpp (a gate re-lock widens P inside a rejected
  // or an accepted update alike)
  int widest = 0;
  const double sigma_dps = filter.correction_sigma_dps().maxCoeff(&widest);
  const LockState::Change change = lock_.on_update(sigma_dps, rec.relocked);
  const bool now = lock_.locked();
  if (!locked_ && !now) {
    if (before_lock_.size() == kSettleHistory) before_lock_.erase(before_lock_.begin());
    before_lock_.push_back({rec.t_s, sigma_dps, double(widest)});
  }
  if (change == LockState::Change::kLost) {
    lost_t_s_ = rec.t_s;
    ++lock_losses_;
  }
  steady_.on_update(rec, filter);
  PositionCount& pc = by_position_[{tenth_deg(rec.plat1_deg), tenth_deg(rec.plat2_deg)}];
  ++pc.updates;
  if (!rec.accepted) {
    ++rejected_;
    ++pc.rejected;
    last_rejected_t_s_ = rec.t_s;
    last_rejected_nis_ = rec.nis;
    return;
  }
  // the NIS of accepted updates: under a consistent model each is chi-square with `dim` dof.
  // Before lock S is dominated by P0, a spec bound rather than a statistical sigma, so those
  // updates are kept apart and only used when the filter never locks.
  if (std::isfinite(rec.nis)) {
    NisSums& sums = locked_ ? nis_locked_ : nis_before_;
    sums.sum += rec.nis;
    sums.dof += rec.dim;
    ++sums.n;
  }
  if (!locked_ && now) {
    locked_ = true;
    lock_t_s_ = rec.t_s;
  }
}

// too many gate rejections: concentrated on some position pairs (a position-dependent sensor
// error the constant-bias model cannot absorb) or spread over all of them
void HealthMonitor::add_gate_findings(HealthReport& h) const {
  if (!(h.rejected_fraction > limits_.max_rejected_fraction) || h.rejected == h.updates) return;
  HealthFinding f;
  if (h.rejected <= limits_.lone_rejections) {
    f.cause = HealthCause::kLoneRejection;
    f.severity = HealthVerdict::kOk;
    f.value = last_rejected_nis_;
    f.suggested = last_rejected_t_s_;
    add(h, f);
    return;
  }
  f.cause = HealthCause::kRejections;
  f.value = h.rejected_fraction;
  PositionCount in, out;
  std::vector<std::array<double, 2>> pairs;
  for (const auto& [key, pc] : by_position_) {
    const bool bad = pc.updates >= 3 && double(pc.rejected) > limits_.position_rejected_fraction * double(pc.updates);
    PositionCount& c = bad ? in : out;
    c.updates += pc.updates;
    c.rejected += pc.rejected;
    if (bad) pairs.push_back({double(key.first) / 10.0, double(key.second) / 10.0});
  }
  if (!pairs.empty() && out.updates > 0) {
    const double fin = double(in.rejected) / double(in.updates), fout = double(out.rejected) / double(out.updates);
    if (fout < 0.25 * fin) {
      f.cause = HealthCause::kRejectionsAtPosition;
      f.value = fin;
      f.positions_deg = pairs;
    }
  }
  add(h, f);
}

// the mean NIS against its chi-square band, and its ratio to the dof
void HealthMonitor::add_nis_findings(HealthReport& h) const {
  if (h.nis_updates == 0) return;
  const bool high = h.nis_mean > h.nis_mean_band_hi, low = h.nis_mean < h.nis_mean_band_lo;
  if (!high && !low) return;
  HealthFinding f;
  f.cause = high ? HealthCause::kNoiseUnderstated : HealthCause::kNoiseOverstated;
  // sigma too large is safe (the estimate is trusted less than it deserves): a note, not degraded
  // above the 95 % band but inside the degraded band: a note (1 consistent run in 40 lands there)
  if (low || !(h.nis_mean > h.nis_mean_degraded_above)) f.severity = HealthVerdict::kOk;
  f.value = h.nis_mean;
  f.suggested = h.nis_mean / h.nis_dof_mean;
  add(h, f);
}

// the position pairs of the updates, when each platform rested on both sides yet some pair of
// sides never occurred (both platforms flipped together): eq. (2) then never separates the
// components that one platform's flip alone would; empty otherwise
std::vector<std::array<double, 2>> HealthMonitor::positions_if_never_apart() const {
  bool seen[2][2] = {{false, false}, {false, false}};  // [plat1 >= 0][plat2 >= 0]
  std::vector<std::array<double, 2>> pairs;
  for (const auto& [key, pc] : by_position_) {
    const double p1 = double(key.first) / 10.0, p2 = double(key.second) / 10.0;
    if (!std::isfinite(p1) || !std::isfinite(p2) || std::fabs(p1) > 1e6 || std::fabs(p2) > 1e6) continue;
    seen[p1 >= 0.0][p2 >= 0.0] = true;
    pairs.push_back({p1, p2});
  }
  const bool both_sides1 = (seen[0][0] || seen[0][1]) && (seen[1][0] || seen[1][1]);
  const bool both_sides2 = (seen[0][0] || seen[1][0]) && (seen[0][1] || seen[1][1]);
  const bool all = seen[0][0] && seen[0][1] && seen[1][0] && seen[1][1];
  if (!both_sides1 || !both_sides2 || all) pairs.clear();
  return pairs;
}

// the correction sigma before the lock had settled: after each of the last four updates it was
// within 2 % of its value one position cycle (eq. (5): four updates) earlier. Then the filter sits
// at its steady state, where the bias's wander between updates balances what each update pins
// down; sigma_dps: its largest value over the last cycle, interval_s: the mean update interval
bool HealthMonitor::settled_sigma(double& sigma_dps, double& interval_s) const {
  constexpr std::size_t kCycle = 4;
  constexpr double kSettledFraction = 0.02;
  if (before_lock_.size() < 2 * kCycle) return false;
  const std::size_t n = before_lock_.size();
  sigma_dps = 0.0;
  for (std::size_t k = n - kCycle; k < n; ++k) {
    const double s = before_lock_[k][1], s_cycle_ago = before_lock_[k - kCycle][1];
    if (!(std::fabs(s - s_cycle_ago) <= kSettledFraction * s)) return false;
    sigma_dps = std::max(sigma_dps, s);
  }
  interval_s = (before_lock_[n - 1][0] - before_lock_[0][0]) / double(n - 1);
  return std::isfinite(interval_s) && interval_s > 0.0;
}

// locked once, then lost it and did not lock again before the end: the estimates at the end carry
// the widened sigma of the re-lock, not a bias a script may use (failed, as never locked)
void HealthMonitor::add_lock_lost_finding(HealthReport& h, const DriftlessFilter& filter) const {
  if (h.locked_at_end) return;
  HealthFinding f;
  f.cause = HealthCause::kLockLost;
  f.severity = HealthVerdict::kFailed;
  f.value = filter.correction_sigma_dps().maxCoeff();
  f.suggested = lost_t_s_;
  f.sigma = limits_.lock_sigma_dps;
  add(h, std::move(f));
}

// the bias alone settles at or above the lock level (the closed form of the first updates'
// schedule): named as the cause, ahead of the lock findings it explains; true if given
bool HealthMonitor::add_unreachable_finding(HealthReport& h) const {
  const SteadyStatePrediction& p = steady_.prediction();
  if (!p.lock_unreachable()) return false;
  HealthFinding f;
  f.cause = HealthCause::kLockUnreachable;
  f.value = p.closed.sigma_dps;
  f.sigma = p.lock_sigma_dps;
  f.steady_state = p;
  add(h, std::move(f));
  return true;
}

// the prediction with the advised interval scaled to a settled sigma the closed form does not
// reach (the self-calibration and temperature states add to it): the interval at which the
// closed form is the margin's share of the lock level divided by settled / closed
SteadyStatePrediction HealthMonitor::steady_at_settled(double settled_dps) const {
  SteadyStatePrediction p = steady_.prediction();
  if (!p.available || !(settled_dps > 0.0)) return p;
  const double ratio = std::max(1.0, settled_dps / p.closed.sigma_dps);
  p.interval_for_lock_s = interval_for_sigma_s(p.schedule, kSteadyStateLockMargin * p.lock_sigma_dps / ratio);
  return p;
}

// never locked (failed) and the components that kept their prior sigma
void HealthMonitor::add_lock_findings(HealthReport& h, const DriftlessFilter& filter, double duration_s) const {
  const EstimatorConfig& cfg = filter.config();
  // the sigma a component would have without any measurement: P0 grown by the random walk
  const double T = std::isfinite(duration_s) ? std::max(duration_s, 0.0) : 0.0;
  const double prior_sigma = std::sqrt(cfg.initial_sigma_dps * cfg.initial_sigma_dps + cfg.q_dps2_per_s() * T);
  const Vector6d sigma = filter.sigma_dps();
  for (int i = 0; i < 6; ++i) {
    if (sigma[i] > limits_.unobservable_ratio * prior_sigma) h.unobservable.push_back(i);
  }
  if (h.updates == 0 || h.rejected == h.updates || !h.locked) {
    HealthFinding f;
    f.severity = HealthVerdict::kFailed;
    f.cause = h.updates == 0 ? HealthCause::kNoUpdate
              : h.rejected == h.updates ? HealthCause::kAllRejected : HealthCause::kNeverLocked;
    f.value = filter.correction_sigma_dps().maxCoeff();  // what locking waits for
    f.suggested = h.rejected_fraction;  // rejections may be why the flips did not observe them
    if (f.cause == HealthCause::kNeverLocked) f.positions_deg = positions_if_never_apart();
    if (f.cause == HealthCause::kNeverLocked) {
      // the cause when the closed form says so; else whether the sigma settled at the level
      double settled_dps = kNaN, interval_s = kNaN;
      if (add_unreachable_finding(h)) f.steady_state = steady_.prediction();
      else if (settled_sigma(settled_dps, interval_s) && settled_dps >= 0.9 * limits_.lock_sigma_dps)
        f.steady_state = steady_at_settled(settled_dps);
    }
    if (f.cause == HealthCause::kNoUpdate) {
      // rows skipped for a missing gyro value come before "the platforms never rested"
      const FilterCounters& c = filter.counters();
      f.suggested = c.samples > 0 ? double(c.invalid) / double(c.samples) : 0.0;
    }
    f.components = h.unobservable;
    add(h, f);
    return;
  }
  add_lock_lost_finding(h, filter);
  if (add_unreachable_finding(h)) return;
  if (h.nis_updates < limits_.min_updates_after_lock) {
    HealthFinding f;
    f.cause = HealthCause::kLateLock;
    f.value = h.lock_t_s;
    f.suggested = double(h.nis_updates);
    // settled at (or within a tenth of) the lock level: the lock came by chance, a longer log
    // gives the same sigma; say that, not "record a longer log"
    double settled_dps = kNaN, interval_s = kNaN;
    if (settled_sigma(settled_dps, interval_s) && settled_dps >= 0.9 * limits_.lock_sigma_dps) {
      f.cause = HealthCause::kSteadyStateAtLock;
      f.value = settled_dps;
      f.sigma = limits_.lock_sigma_dps;
      f.suggested = interval_s;
      f.count = before_lock_.size();
      f.steady_state = steady_at_settled(settled_dps);
      f.components = {static_cast<int>(before_lock_.back()[2])};  // the component that settled
    }
    add(h, f);
  }
  if (!h.unobservable.empty()) {
    HealthFinding f;
    f.cause = HealthCause::kUnobservable;
    f.value = sigma.maxCoeff();
    f.components = h.unobservable;
    add(h, f);
  }
}

namespace {

// box dwells the gate rejected: the box was not at rest in them (each rejection is a 1e-4 chance
// at rest); they are apart from the standstill updates and their rejection rate
void add_box_dwell_finding(HealthReport& h, const FilterCounters& c) {
  if (c.box_dwell_rejected == 0) return;
  HealthFinding f;
  f.cause = HealthCause::kBoxDwellsRejected;
  f.severity = 5 * c.box_dwell_rejected > c.box_dwell_updates ? HealthVerdict::kDegraded : HealthVerdict::kOk;
  f.count = c.box_dwell_rejected;
  f.suggested = double(c.box_dwell_updates);
  f.value = double(c.box_dwell_moving);
  add(h, f);
}

}  // namespace

HealthReport HealthMonitor::finish(const DriftlessFilter& filter, double duration_s, const LagCheckResult& lag) const {
  HealthReport h;
  h.signal_chain = lag;
  h.locked = locked_;
  h.lock_t_s = lock_t_s_;
  h.locked_at_end = locked_ && lock_.locked();
  h.lock_lost_t_s = h.locked_at_end ? kNaN : lost_t_s_;
  h.updates = updates_;
  h.rejected = rejected_;
  h.rejected_fraction = updates_ > 0 ? double(rejected_) / double(updates_) : kNaN;
  h.relocks = filter.counters().relocks;
  h.lock_losses = lock_losses_;
  h.steady_state = steady_.prediction();
  const NisSums& nis = locked_ ? nis_locked_ : nis_before_;
  h.nis_updates = nis.n;
  if (nis.n > 0) {
    // the sum of independent chi-square NIS values is chi-square with the summed dof
    const double n = double(nis.n), tail = 0.5 * (1.0 - limits_.band_probability);
    h.nis_mean = nis.sum / n;
    h.nis_dof_mean = nis.dof / n;
    h.nis_mean_band_lo = chi2_quantile(tail, nis.dof) / n;
    h.nis_mean_band_hi = chi2_quantile(1.0 - tail, nis.dof) / n;
    h.nis_mean_degraded_above = chi2_quantile(0.5 * (1.0 + limits_.degraded_band_probability), nis.dof) / n;
  }
  add_lock_findings(h, filter, duration_s);
  add_gate_findings(h);
  add_nis_findings(h);
  if (lag.significant) {
    // no noise density describes it: --tune auto would take it for noise and say "ok"
    HealthFinding f;
    f.cause = HealthCause::kSignalChainLag;
    f.value = lag.lag_s;
    f.sigma = lag.lag_sigma_s;
    f.suggested = lag.update_excess;
    add(h, f);
  }
  if (h.relocks > 0) {
    HealthFinding f;
    f.cause = HealthCause::kRelocks;
    f.value = double(h.relocks);
    add(h, f);
  }
  add_box_dwell_finding(h, filter.counters());
  return h;
}

}  // namespace driftless::est
