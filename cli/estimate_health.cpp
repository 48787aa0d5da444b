#include "cli/estimate_health.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "cli/estimate_health_accel.hpp"
#include "cli/estimate_health_flip.hpp"
#include "estimator/log.hpp"
#include "estimator/numbers.hpp"
#include "report/json.hpp"

namespace driftless::cli {
namespace {

constexpr const char* kComponentNames[6] = {"b1_x", "b1_y", "b1_z", "b2_x", "b2_y", "b2_z"};

using report::json_number;
using report::json_string;

}  // namespace

const char* cause_key(est::HealthCause c) {
  switch (c) {
    case est::HealthCause::kNoUpdate: return "no_update";
    case est::HealthCause::kAllRejected: return "all_rejected";
    case est::HealthCause::kNeverLocked: return "never_locked";
    case est::HealthCause::kNoiseUnderstated: return "noise_understated";
    case est::HealthCause::kNoiseOverstated: return "noise_overstated";
    case est::HealthCause::kRejectionsAtPosition: return "rejections_at_position";
    case est::HealthCause::kRejections: return "rejections";
    case est::HealthCause::kLoneRejection: return "lone_rejection";
    case est::HealthCause::kUnobservable: return "unobservable";
    case est::HealthCause::kRelocks: return "relocks";
    case est::HealthCause::kLateLock: return "late_lock";
    case est::HealthCause::kSteadyStateAtLock: return "steady_state_at_lock";
    case est::HealthCause::kLockUnreachable: return "lock_unreachable";
    case est::HealthCause::kSignalChainLag: return "signal_chain_lag";
    case est::HealthCause::kSaturation: return "saturation";
    case est::HealthCause::kAttitudeWithheld: return "attitude_withheld";
    case est::HealthCause::kAttitudeWithheldNoRate: return "attitude_withheld_no_rate";
    case est::HealthCause::kAttitudeWithheldGap: return "attitude_withheld_gap";
    case est::HealthCause::kGyroFlipAngle: return "gyro_flip_angle";
    case est::HealthCause::kGyroGapPositions: return "gyro_gap_positions";
    case est::HealthCause::kGyroStartMidFlip: return "gyro_start_mid_flip";
    case est::HealthCause::kStampRate: return "stamp_rate";
    case est::HealthCause::kParallelHinges: return "parallel_hinges";
    case est::HealthCause::kNeverFlipped: return "never_flipped";
    case est::HealthCause::kAngleJitter: return "angle_jitter";
    case est::HealthCause::kPriorRejected: return "prior_rejected";
    case est::HealthCause::kDeadAxis: return "dead_axis";
    case est::HealthCause::kPaperRestAngles: return "paper_rest_angles";
    case est::HealthCause::kPaperSchedule: return "paper_schedule";
    case est::HealthCause::kLockLost: return "lock_lost";
    case est::HealthCause::kBoxDwellsRejected: return "box_dwells_rejected";
    case est::HealthCause::kReferenceMismatch: return "reference_mismatch";
    case est::HealthCause::kBoxNotAtRest: return "box_not_at_rest";
    case est::HealthCause::kAccelUnit: return "accel_unit";
    case est::HealthCause::kAccelEmpty: return "accel_empty";
    case est::HealthCause::kCalibUncertain: return "calib_uncertain";
    case est::HealthCause::kVerticalUnobserved: return "vertical_unobserved";
    case est::HealthCause::kClippedFlipsScale: return "clipped_flips_scale";
    case est::HealthCause::kStandstillsTooShort: return "standstills_too_short";
    case est::HealthCause::kNoDataRows: return "no_data_rows";
    case est::HealthCause::kStampUnit: return "stamp_unit";
    default: if (is_flip_cause(c)) return flip_cause_key(c);
  }
  return "?";
}

std::string stamp_unit_text(double interval_s, double to_s) {
  const char* unit = to_s == 1e-3 ? "milliseconds" : to_s == 1e-6 ? "microseconds" : "nanoseconds";
  return fmt::format("the time stamps step {:.6g} \"s\" (median interval) and the header states no sample_rate_hz: "
                     "no gyro log in seconds is sampled that slowly, so t is in {}? ({:.6g} s, {:.6g} Hz, in "
                     "seconds). The log wants seconds: divide t by {:g} (or state sample_rate_hz); every duration, "
                     "gap and noise figure of this run is off by that factor",
                     interval_s, unit, interval_s * to_s, 1.0 / (interval_s * to_s), 1.0 / to_s);
}

namespace {

// the stamps against sample_rate_hz: what they step at, and the likely unit mistake
std::string stamp_rate_text(const est::HealthFinding& f) {
  const double ratio = f.suggested / f.value;  // stated / stamps: 1000 for ms stamps read as s
  const std::string unit = std::fabs(ratio / 1000.0 - 1.0) < 0.2  ? " (stamps in milliseconds?)"
                           : std::fabs(ratio / 1e6 - 1.0) < 0.2   ? " (stamps in microseconds?)"
                           : std::fabs(ratio * 1000.0 - 1.0) < 0.2 ? " (a rate in kHz, or stamps in ks?)"
                                                                   : "";
  return fmt::format("sample_rate_hz says {:g} Hz, but the stamps step {:.6g} s ({:.6g} Hz; {:.6g} Hz from their "
                     "mean interval){}: standstill durations, the noise per sample and the gap threshold use the "
                     "stated rate{}; fix the sample_rate_hz line, or convert t to seconds",
                     f.suggested, 1.0 / f.value, f.value, f.sigma, unit,
                     f.severity == est::HealthVerdict::kFailed ? ", so the results of this run are not the sensors'"
                                                               : "");
}

// "(90, -90) and (-90, 90) deg" (plat1, plat2)
std::string position_text(const std::vector<std::array<double, 2>>& pairs) {
  std::string o;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    o += fmt::format("{}({:g}, {:g})", i == 0 ? "" : i + 1 == pairs.size() ? " and " : ", ", pairs[i][0], pairs[i][1]);
  }
  return o + " deg";
}

// what to do with ref_q's columns when they were written in convention `c`
std::string reference_fix(est::RefConvention c) {
  switch (c) {
    case est::RefConvention::kBodyFromEnuWxyz:
      return "conjugate it (negate ref_qx, ref_qy, ref_qz)";
    case est::RefConvention::kEnuFromBodyXyzw:
      return "write the scalar first (the columns ref_qw, ref_qx, ref_qy, ref_qz hold x, y, z, w: move the 4th to the 1st)";
    case est::RefConvention::kBodyFromEnuXyzw:
      return "write the scalar first and conjugate it (the columns hold x, y, z, w of q_body_from_enu: w, -x, -y, -z)";
    case est::RefConvention::kEnuFromBodyWxyz: break;
  }
  return "nothing";
}

std::string describe_box_motion(const est::HealthFinding& f) {
  std::string seen;
  if (f.value > est::BoxMotionLimits{}.ref_rate_dps) {
    seen = fmt::format("ref_q turned at up to {:.3g} deg/s over a standstill", f.value);
  }
  if (f.sigma > est::BoxMotionLimits{}.gyro_change_dps) {
    seen += fmt::format("{}the fused rate changed by up to {:.3g} deg/s within one (the bias cannot)",
                        seen.empty() ? "" : " and ", f.sigma);
  }
  return fmt::format("the box was not at rest while both platforms rested: {} (e.g. t = {:.1f} s); --box-at-rest "
                     "claims the box turns at the Earth rate only while the platforms rest, and the turn entered "
                     "the biases and the g-sensitivity as if it were theirs. Drop --box-at-rest (a box in a "
                     "vehicle, on a ship or a turntable turns)",
                     seen, f.suggested);
}

// flips skipped for clipping on a turning box: the hinges' scale stays at its prior (section 1f)
std::string describe_clipped_flips(const est::HealthFinding& f, const RunUsed& u) {
  const std::string turned =
      std::isfinite(f.value) && f.value > est::BoxMotionLimits{}.ref_rate_dps
          ? fmt::format(" (ref_q turned at up to {:.3g} deg/s over a standstill)", f.value)
          : std::string(" (the fused rate changed within a standstill)");
  return fmt::format(
      "{} of the flips were skipped because a gyro clipped in them ({:.0f} flip updates used): no flip measured "
      "the scale along the hinges, which stays at its prior, and the box turned{}: a scale error along a hinge "
      "is that fraction of every turn of the box about it, in the heading too (navgen's car, uncalibrated "
      "MPU6050: 32-46 deg/h with 1 s flips, 0-5 with 2 s flips). Flip slower, so that the hinge rate stays "
      "inside the range, or record with a larger full scale (MPU6050: FS_SEL), or {}",
      f.count, f.suggested, turned,
      u.calib ? "calibrate the scale again with 'driftless calibrate'"
              : "calibrate the scale with 'driftless calibrate' and pass --calib");
}

// what showed the box turning while both platforms rested (RunUsed; empty when nothing did)
std::string box_turn_evidence(const RunUsed& u) {
  if (!u.box_turned) return "";
  if (u.box_ref_rate_dps > est::BoxMotionLimits{}.ref_rate_dps) {
    return fmt::format("ref_q turned at up to {:.3g} deg/s over a standstill{}", u.box_ref_rate_dps,
                       u.box_still == 0 ? " and was still in none" : "");
  }
  return fmt::format("the fused rate changed by up to {:.3g} deg/s within a standstill (the bias cannot)",
                     u.box_gyro_change_dps);
}

// what observes the vertical rate both sensors share, by what the run saw (section 1d): a box seen
// turning at every rest needs pauses or a calibration; assuming it at rest is advice only for a
// box nothing showed turning
std::string vertical_fix(const RunUsed& u, const est::EstimatorConfig& cfg) {
  const double pause_s = cfg.box_dwell_min_s + 2.0 * cfg.box_dwell_margin_s;
  const std::string calib = u.calib ? "or self-calibrate these sensors once on a run with pauses and use that calib.yaml instead"
                                    : "or pass --calib with a calib.yaml from a self-calibrated run with pauses (--calib-out)";
  const std::string pause = fmt::format("Let the box pause now and then (both platforms resting and the box not turning "
                                        "for {:g} s or more: a vehicle's stop, or a straight run with ref_q logged){}",
                                        pause_s, u.selfcal ? "" : " and use --selfcal, whose box dwells observe it there");
  if (!u.box_turned) {
    return fmt::format("{}, {}, or add --box-at-rest if the box stands still", pause, calib);
  }
  return fmt::format("{}, {}: the box turned while the platforms rested ({}), so assuming it at rest is no fix",
                     pause, calib, box_turn_evidence(u));
}

// no pause of the box: the shared vertical bias stays near its g-sensitivity prior (section 1d);
// without --selfcal (value NaN) G is not modelled and the same part is in no sigma
std::string describe_vertical(const est::HealthFinding& f, const est::EstimatorConfig& cfg, const RunUsed& u) {
  if (!std::isfinite(f.value)) {
    return fmt::format(
        "the g-sensitivity is not modelled without --selfcal, and the updates show an error a bias does not explain "
        "(the findings above); its part that keeps its sign about the box vertical (the 1 g along it) looks like a "
        "bias both sensors share to eq. (2), and nothing in this log observes that (below). It is in neither the "
        "estimate nor its sigma: up to {:.0f} deg/h of heading drift for a g-sensitivity of {:.3g} deg/s/g "
        "(navgen's rocking MPU6050 without --selfcal: 203 deg/h, 195 with the bias fixed). {}",
        f.sigma * 3600.0, f.sigma, vertical_fix(u, cfg));
  }
  const std::string turned =
      std::isfinite(f.suggested) ? fmt::format(": ref_q turned at up to {:.3g} deg/s over the quiet standstills", f.suggested)
                                 : std::string();
  return fmt::format(
      "the bias both sensors share about the vertical was not observed: no box dwell was used (the box never "
      "paused{}), and a g-sensitivity that keeps its sign about the box vertical (the 1 g along it) looks like that "
      "shared bias to eq. (2). The correction is known to +-{:.3g} deg/s against its prior {:.3g} deg/s: up to {:.0f} "
      "deg/h of heading drift. {}",
      turned, f.value, f.sigma, f.value * 3600.0, vertical_fix(u, cfg));
}

// the box dwells' rejections: what would witness them, by the columns the log had (section 1d)
std::string box_dwells_fix(const RunUsed& u) {
  const std::string off = "set box_dwell_updates: false in the configuration if the box never truly stops";
  if (!u.ref_q) {
    return "Log ref_q (the box's attitude from a reference): it witnesses each pause and refuses the stretches in "
           "which the box turned, where now only the accel columns' |f| near 1 g decides; or " + off;
  }
  if (!u.accel) {
    return "Log the accel columns (accel1_*, accel2_*): a dwell row then takes the measured specific force, where "
           "now (gravity from ref_q) the box's acceleration in a pause is only bounded (0.05 g); or " + off;
  }
  return "ref_q witnessed these pauses and the accel columns were measured, so the box moved in them below what "
         "ref_q shows (0.01 deg/s): " + off;
}

std::string describe_box_dwells(const est::HealthFinding& f, const RunUsed& u) {
  const std::string refused =
      f.value > 0.0 ? fmt::format(" ({:.0f} more quiet stretches were refused: the box rate trended through them)", f.value)
                    : std::string();
  return fmt::format("{} of {:.0f} box dwell updates were rejected by their gate{}: in those pauses the box still "
                     "turned (a slow steady turn, a vehicle creeping), so the vertical rate was not the Earth's; the "
                     "accepted ones may carry part of it into the shared bias and g-sensitivity. {}",
                     f.count, f.suggested, refused,
                     f.severity == est::HealthVerdict::kOk
                         ? "A few are expected on a box that sometimes moves slowly: the rest stand"
                         : box_dwells_fix(u));
}

std::string describe_reference(const est::HealthFinding& f) {
  constexpr const char* kAxes = "xyz";
  const int axis = f.components.empty() ? 0 : f.components[0];
  const auto& ex = f.positions_deg;
  const std::string example =
      ex.size() < 2 ? std::string()
                    : fmt::format(" (at t = {:.1f} s the fused gyros turned the box {:+.1f} deg about {} in {:.2g} s, "
                                  "ref_q {:+.1f} deg)",
                                  ex[0][0], ex[1][0], kAxes[axis], ex[0][1], ex[1][1], kAxes[axis]);
  const std::string head = fmt::format(
      "ref_q does not turn with the gyros{}: over {} turning windows its misfit is {:.3g} (0 = the same turns, "
      "4 = turning the other way; a fit is below 0.1)",
      example, f.count, f.value);
  if (std::isfinite(f.suggested)) {
    const auto c = static_cast<est::RefConvention>(static_cast<int>(f.suggested));
    return fmt::format("{}; the data fit ref_q as {} (misfit {:.3g}), where the log format wants q_enu_from_body, "
                       "scalar first: {}. The attitude drift and final errors are withheld (attitude.csv holds the "
                       "errors against ref_q as written); the biases are not affected",
                       head, est::to_string(c), f.sigma, reference_fix(c));
  }
  return fmt::format("{}; no convention fits (conjugate or scalar last: the best misfit is {:.3g}): ref_q is the "
                     "attitude of another body (a reference IMU mounted turned on the box?), or the gyro columns are "
                     "not in deg/s. The attitude drift and final errors are withheld; check ref_q against the box axes",
                     head, f.sigma);
}

}  // namespace

std::string component_names(const std::vector<int>& components) {
  std::string o;
  for (int c : components) o += (o.empty() ? "" : " + ") + std::string(kComponentNames[c]);
  return o;
}

RunUsed run_used(const est::EstimatorConfig& cfg, est::GravitySource gravity) {
  const est::Calibration& c = cfg.calibration;
  RunUsed u;
  u.selfcal = cfg.self_calibration;
  u.tune_auto = cfg.noise_from_log;
  u.calib = !c.empty() || c.has_g_sensitivity() || c.has_g_sigma || c.has_scale_misalign || c.has_end_stops ||
            c.has_temp_coef;
  u.box_at_rest = cfg.box_at_rest;
  u.gravity = gravity;
  return u;
}

RunUsed run_used(const est::EstimatorConfig& cfg, const est::HealthReport& h) {
  RunUsed u = run_used(cfg, h.gravity_source);
  u.box_turned = est::box_turned(h.box_motion);
  u.box_still = h.box_motion.still_standstills;
  u.box_ref_rate_dps = h.box_motion.ref_rate_dps;
  u.box_gyro_change_dps = h.box_motion.gyro_change_dps;
  u.ref_q = h.ref_q_logged;
  u.accel = h.accel_logged;
  for (const auto& f : h.findings) u.short_rests = u.short_rests || f.cause == est::HealthCause::kStandstillsTooShort;
  return u;
}

std::string calibrate_fix(const RunUsed& u) {
  return u.calib ? "recalibrate with 'driftless calibrate' (the calibration given does not describe these sensors now)"
                 : "calibrate with 'driftless calibrate' and pass --calib";
}

std::string model_error_fix(const RunUsed& u) {
  if (!u.selfcal) {
    return fmt::format("estimate it with --selfcal (g-sensitivity, scale and misalignment states{}), or {}",
                       u.box_at_rest || u.box_turned ? "" : "; add --box-at-rest for a box standing still",
                       calibrate_fix(u));
  }
  if (u.gravity == est::GravitySource::kNone) {
    return "g-sensitivity cannot be estimated without accel columns or ref_q: log them (accel1_*/accel2_*, or "
           "ref_qw..ref_qz), or " + calibrate_fix(u);
  }
  return "the self-calibration in this run did not absorb it: see the findings above (an accel column's unit, the "
         "end stops), widen its priors (gsens_sigma_dps_per_g, scale_misalign_sigma_frac) in the configuration, "
         "or " + calibrate_fix(u);
}

std::string noise_fix(const RunUsed& u) {
  if (!u.tune_auto) return "use --tune auto";
  return u.selfcal ? "the noise and the wander were measured from this log, so the excess is not white noise: a "
                     "sensor error the self-calibration does not model, or a signal-chain mismatch between the "
                     "sensors ('driftless diagnose')"
                   : "the noise and the wander were measured from this log, so the excess is not white noise: a "
                     "sensor error the model lacks (g-sensitivity, scale or misalignment on a moving box: --selfcal) "
                     "or a signal-chain mismatch between the sensors";
}

namespace {

// for noise or wander smaller than configured (NIS below its band): measure them, unless the run did
std::string quiet_fix(const RunUsed& u) {
  if (!u.tune_auto) return "use --tune auto to measure the noise density and the bias random walk from this log";
  return "the noise and the wander were measured from this log already, so what stays too large is a bound: the "
         "random walk's upper bound where the revisits show no wander above the noise, or a sensor-error prior";
}

// the lock: whether the filter locked, kept it, and what stayed unobserved
// the closed form next to a settled sigma: the same (the bias's wander sets it) or below it (the
// self-calibration or temperature states add the rest); empty without a prediction
std::string closed_form_text(const est::SteadyStatePrediction& p, double settled_dps) {
  if (!p.available) return "";
  if (p.closed.sigma_dps >= 0.9 * settled_dps) {
    return fmt::format(" (the closed-form steady state of this q, T and R is {:.3f} deg/s)", p.closed.sigma_dps);
  }
  return fmt::format(" (the closed-form steady state of this q, T and R is {:.3f} deg/s for the bias alone; the "
                     "self-calibration or temperature states' uncertainty adds the rest)",
                     p.closed.sigma_dps);
}

// what would reach the lock level: the update interval of the prediction, or none
std::string flip_period_fix(const est::SteadyStatePrediction& p) {
  if (!p.available) return "flip more often (shorter rests between flips)";
  if (!std::isfinite(p.interval_for_lock_s)) {
    return "no flip period reaches it with this noise: a quieter sensor (or averaging both more often) is needed";
  }
  if (p.interval_for_lock_s > p.schedule.interval_s) {
    return fmt::format("rest longer between flips: one flip every {:.1f} s (now {:.1f} s) brings it to {:.2g} of the "
                       "lock level",
                       p.interval_for_lock_s, p.schedule.interval_s, est::kSteadyStateLockMargin);
  }
  return fmt::format("flip more often: one flip every {:.1f} s (now {:.1f} s, the flips' {:.1f} s kept) brings it "
                     "to {:.2g} of the lock level",
                     p.interval_for_lock_s, p.schedule.interval_s, p.schedule.interval_s - p.schedule.window_s,
                     est::kSteadyStateLockMargin);
}

// steady_state_at_lock's fix: the flip period when the bias's own steady state sets the settled
// sigma; when the closed form is well below it, the flip rate does not set it, the other states do
std::string settled_fix(const est::HealthFinding& f, const RunUsed& u) {
  const est::SteadyStatePrediction& p = f.steady_state;
  if (!p.available || p.closed.sigma_dps >= 0.9 * f.value) return flip_period_fix(p);
  const std::string who = f.components.empty() ? std::string("the correction") : component_names(f.components);
  return fmt::format("{}{}",
                     std::isfinite(p.interval_for_lock_s)
                         ? fmt::format("flipping more often lowers only the bias's part of {}'s sigma: one flip every "
                                       "{:.1f} s would reach {:.2g} of the lock level only if the rest shrank with it",
                                       who, p.interval_for_lock_s, est::kSteadyStateLockMargin)
                         : fmt::format("flipping more often does not lower {}'s sigma (no flip period brings even the "
                                       "bias's part low enough)",
                                       who),
                     u.selfcal && !u.box_at_rest
                         ? std::string(": with --selfcal the g-sensitivity both sensors share about the box vertical is "
                                       "seen only while the box rests (box dwells, docs/estimator.md section 1d): ") +
                               (u.box_turned ? "let the box stop now and then (it turned while the platforms rested)"
                                             : "let the box stop now and then, or add --box-at-rest if it stands still")
                         : "");
}

std::string describe_lock(const est::HealthFinding& f, const est::EstimatorConfig& cfg, const RunUsed& u) {
  switch (f.cause) {
    case est::HealthCause::kNoUpdate:
      if (f.suggested > 0.5) {
        return fmt::format("no standstill became an update: {:.1f} % of the rows lack a gyro value and were "
                           "skipped (a dead axis or an empty column: see the findings above, or 'driftless check')",
                           100.0 * f.suggested);
      }
      return "no standstill became an update: the platforms never rested for min_standstill_s "
             "(or the angle columns are empty); check plat1_deg/plat2_deg or set standstill: gyro";
    case est::HealthCause::kAllRejected:
      return fmt::format("the NIS gate rejected every update: the sensors do not fit the configured noise or "
                         "model; {}, or check the hinge axes in the log header",
                         u.tune_auto ? "the noise measured from this log does not explain it: check the gyro "
                                       "columns' units ('driftless check')"
                                     : "try --tune auto");
    case est::HealthCause::kNeverLocked:
      return fmt::format("never locked: the largest sigma of the bias correction is {:.3g} deg/s{}{}; {}", f.value,
                         f.components.empty() ? std::string() : ", unobservable: " + component_names(f.components),
                         f.steady_state.available && !f.steady_state.lock_unreachable()
                             ? ", where it had settled (within 2 % of itself one position cycle earlier over the last "
                               "8 updates), so a longer log gives the same sigma" +
                                   closed_form_text(f.steady_state, f.value)
                             : std::string(),
                         f.steady_state.lock_unreachable()
                             ? "the steady state of the bias sigma is above the lock level (lock_unreachable above): "
                               "a longer log or more flips of the same kind cannot lock it"
                         : f.suggested > 0.02 ? fmt::format("the gate rejected {:.0f} % of the updates, so the flips "
                                                          "that observe them were not used (see below)",
                                                          100.0 * f.suggested)
                                            : !f.positions_deg.empty()
                                                  ? fmt::format("the platforms only rested at {}: each flipped "
                                                                "with the other, so the positions between never "
                                                                "occurred; flip one platform at a time (eq. (5): "
                                                                "(+,+) (+,-) (-,-) (-,+))",
                                                                position_text(f.positions_deg))
                                            : u.selfcal && u.gravity == est::GravitySource::kNone
                                                  ? "g-sensitivity cannot be estimated without accel columns or "
                                                    "ref_q: log them (a g-sensitivity along the box vertical looks "
                                                    "like a bias common to both sensors)"
                                            : u.selfcal && !u.box_at_rest
                                                  ? "in self-calibrating mode a g-sensitivity that keeps its sign "
                                                    "about the box vertical looks like a bias common to both "
                                                    "sensors, which only a pause of the box observes. " +
                                                        vertical_fix(u, cfg)
                                            : u.short_rests
                                                  ? "the rests between flips are too short to use "
                                                    "(standstills_too_short above): rest longer, not more flips"
                                                  : "record more flips (both platforms, both directions) or a longer log");
    case est::HealthCause::kUnobservable:
      return fmt::format("{} kept most of the prior sigma (largest sigma {:.3g} deg/s): the flips in this "
                         "log do not observe them; flip both platforms",
                         component_names(f.components), f.value);
    case est::HealthCause::kLockLost:
      return fmt::format("the filter locked, then lost the lock at t = {:.1f} s (a gate re-lock widened its sigma) and "
                         "did not lock again before the end: the largest bias sigma at the end is {:.3g} deg/s, above "
                         "the lock level {:g} deg/s, so the final biases are not usable (corrected.csv: locked = 0 from "
                         "there). The findings above name why the updates stopped fitting; {} are the common causes",
                         f.suggested, f.value, f.sigma,
                         u.tune_auto ? "a bias jump, or a sensor error the model lacks (the noise was measured from "
                                       "this log),"
                                     : "a bias jump, or noise and bias wander larger than configured (--tune auto),");
    case est::HealthCause::kRelocks:
      return fmt::format("the filter lost lock and re-locked {:g} time(s) (see relocks): a bias jump, a new "
                         "sensor, or a model that does not fit; check the log around those times",
                         f.value);
    case est::HealthCause::kLateLock:
      return fmt::format("locked only at t = {:.1f} s, with {:g} accepted update(s) after it: too few to check "
                         "the NIS against its band or to compare the attitude; record a longer log or more "
                         "flips after the lock",
                         f.value, f.suggested);
    case est::HealthCause::kSteadyStateAtLock: {
      // the wander between two updates, and a start level above the settled sigma
      const double q = cfg.q_dps2_per_s(), wander_dps = std::sqrt(q * f.suggested);
      const double start_dps = std::ceil(1.5 * f.value * 100.0) / 100.0;
      return fmt::format("the correction sigma settled at {:.3f} deg/s over the last {} updates before the lock "
                         "(within 2 % of itself one position cycle earlier), at the lock level {:.3g} deg/s: the "
                         "bias wanders (q {:.2g} (deg/s)^2/s) by sqrt(q T) = {:.3f} deg/s between updates T = "
                         "{:.1f} s apart, as much as the updates pin down, so a longer log gives the same sigma and "
                         "the lock came by chance{}; {}, or compare the attitude anyway with --attitude-start-sigma {:.2f}",
                         f.value, f.count, f.sigma, q, wander_dps, f.suggested, closed_form_text(f.steady_state, f.value),
                         settled_fix(f, u), start_dps);
    }
    case est::HealthCause::kLockUnreachable: {
      const est::SteadyStatePrediction& p = f.steady_state;
      const double start_dps = std::ceil(1.25 * f.value * 100.0) / 100.0;
      return fmt::format("the lock level {:.3g} deg/s cannot be reached: the steady state of the bias sigma in closed "
                         "form (the periodic Riccati fixed point) is {:.3f} deg/s, from q {:.2g} (deg/s)^2/s, updates "
                         "T = {:.1f} s apart and standstills of {:.1f} s (R {:.2g} (deg/s)^2 per sensor), known from "
                         "the first {} updates at t = {:.1f} s: the bias wanders by sqrt(q T) = {:.3f} deg/s between "
                         "updates, more than they pin down, and a longer log gives the same sigma{}; {}, or compare the "
                         "attitude anyway with --attitude-start-sigma {:.2f}",
                         f.sigma, f.value, p.schedule.q_dps2_per_s, p.schedule.interval_s, p.schedule.window_s,
                         p.schedule.meas_var_dps2, est::SteadyStateWatch::kScheduleUpdates, p.known_at_t_s,
                         p.closed.walk_per_update_dps,
                         p.other_states ? " (for the bias alone: the self-calibration or temperature states add to it)"
                                        : "",
                         flip_period_fix(p), start_dps);
    }
    default: break;
  }
  return "?";
}

// how the updates fit the model: the NIS, the gate's rejections, the signal chain
std::string describe_fit(const est::HealthFinding& f, const est::EstimatorConfig& cfg, const RunUsed& u) {
  switch (f.cause) {
    case est::HealthCause::kNoiseUnderstated:
      return fmt::format("NIS mean {:.3g} above its 95 % band{}: the innovations are {:.2g}x larger than the "
                         "filter expects, its sigma too small (data noisier or bias wandering more than "
                         "noise_density_dps_rthz {:.3g} and the bias instability say); {}",
                         f.value,
                         f.severity == est::HealthVerdict::kOk
                             ? " (inside the 99.9 % band: one consistent run in 40 lands here)"
                             : " and its 99.9 % band",
                         std::sqrt(f.suggested), cfg.noise_density_dps_rthz, noise_fix(u));
    case est::HealthCause::kNoiseOverstated: {
      // S is too large by 1 / (NIS per dof): the sigma the configuration gives (noise and wander
      // together) by its square root
      const double over = 1.0 / std::sqrt(std::max(f.suggested, 1e-12));
      return fmt::format("NIS mean {:.3g} below its 95 % band: the innovations are {:.2g}x the size the filter "
                         "expects, so the configured noise is {:.2g}x too large as a sigma ({:.3g}x as a variance; "
                         "noise_density_dps_rthz {:.3g}, bias random walk {:.3g} (deg/s)^2/s): the data are quieter "
                         "or the bias steadier than configured; safe, but the estimates are trusted less than they "
                         "deserve (slower lock, a looser gate); {}",
                         f.value, std::sqrt(f.suggested), over, over * over, cfg.noise_density_dps_rthz,
                         cfg.q_dps2_per_s(), quiet_fix(u));
    }
    case est::HealthCause::kRejectionsAtPosition:
      return fmt::format("{:.0f} % of the updates at platform angles {} were rejected, few elsewhere: an error "
                         "that depends on the position and that a constant bias cannot absorb (g-sensitivity "
                         "on a horizontal hinge, misalignment, an end-stop angle error); {}",
                         100.0 * f.value, position_text(f.positions_deg), model_error_fix(u));
    case est::HealthCause::kRejections:
      return fmt::format("{:.1f} % of the updates were rejected by the NIS gate: noise or bias wander "
                         "larger than configured ({}), or a model that does not fit{}",
                         100.0 * f.value, noise_fix(u),
                         u.selfcal && u.gravity != est::GravitySource::kNone
                             ? std::string()
                             : " (an uncalibrated MEMS gyro on a moving box: g-sensitivity, scale and misalignment; " +
                                   model_error_fix(u) + ")");
    case est::HealthCause::kLoneRejection:
      return fmt::format("one update rejected by the NIS gate (t = {:.2f} s, NIS {:.3g}): a lone outlier, "
                         "which the gate is there to remove; the estimate is unaffected. Repeated rejections "
                         "would mean noise or bias wander larger than configured{}",
                         f.suggested, f.value,
                         u.tune_auto ? " (than the noise measured from this log)" : " (--tune auto)");
    case est::HealthCause::kSignalChainLag:
      return fmt::format("the residual follows the box's angular acceleration: sensor {} reads the rate {:.2f} ms "
                         "(+-{:.2f}) later than sensor {}, which adds {:.2g}x the white noise's variance to the "
                         "standstill updates. No noise density describes that ({}): "
                         "a signal-chain mismatch (a sample delay, or a slower low-pass filter on one sensor); "
                         "align the two sensors' time stamps and filters, or run 'driftless diagnose' on this log "
                         "to measure each sensor's chain",
                         f.value > 0.0 ? 2 : 1, 1e3 * std::fabs(f.value), 1e3 * f.sigma, f.value > 0.0 ? 1 : 2,
                         f.suggested,
                         u.tune_auto ? "the density measured from this log took part of it for noise"
                                     : "--tune auto would take it for noise");
    default: break;
  }
  return "?";
}

// what the log itself holds against the model: paper mode's positions, clipping, dead axes,
// the attitude withheld
std::string describe_input(const est::HealthFinding& f) {
  switch (f.cause) {
    case est::HealthCause::kPaperRestAngles:
      return fmt::format("the platforms rested {:g} deg from the paper's positions in {:g} of {} standstills "
                         "(plat*_deg read {:g} deg), while paper mode builds H from +-{:g} deg (flip_angle_deg){}; "
                         "use --mode general (H from the angles read), or set flip_angle_deg: {:g} in the log "
                         "header if every rest is at that angle",
                         std::fabs(std::fabs(f.suggested) - f.sigma), f.value, f.count, f.suggested, f.sigma,
                         f.severity == est::HealthVerdict::kFailed
                             ? ": the biases and their sigma from this run are not the box's"
                             : ": the updates from those standstills used an H the box did not have",
                         std::fabs(f.suggested));
    case est::HealthCause::kPaperSchedule:
      return fmt::format("the platforms did not follow eq. (5)'s position sequence in {:g} of {} standstills "
                         "(paper mode builds H from that sequence, not from the angles read){}; use --mode general",
                         f.value, f.count,
                         f.severity == est::HealthVerdict::kFailed
                             ? ": the biases and their sigma from this run are not the box's"
                             : ": the updates from those standstills used positions the box was not in");
    case est::HealthCause::kSaturation: {
      const int c = f.components.empty() ? 0 : f.components.front();
      return fmt::format("{} reads exactly +-{:.6g} deg/s, its largest value, in runs over {:.3g} % of the "
                         "rows: the sensor clips there (its range){}; record with a larger full scale (MPU6050: "
                         "FS_SEL) or slower motion, and state the range as gyro_full_scale_dps in the log header",
                         log::gyro_column_name(c), f.suggested, 100.0 * f.value,
                         f.severity == est::HealthVerdict::kOk
                             ? ", only while a platform turns: the standstills that the bias updates average are "
                               "untouched, a flip's measured turn falls short (flip updates)"
                         : f.severity == est::HealthVerdict::kFailed
                             ? ", also while the platforms rest: those standstills measure the rail, not the rate, "
                               "and the biases from this log cannot be trusted"
                             : ", also in a few standstills, which measure the rail there");
    }
    case est::HealthCause::kDeadAxis: {
      const int c = f.components.empty() ? 0 : f.components.front();
      const std::string name(log::gyro_column_name(c));
      if (std::isnan(f.value)) {
        return fmt::format("{} is empty (no value) in all {:g} rows: a dead axis, or a column the logger did not "
                           "fill; every row was skipped. Check the sensor and the column names in the header",
                           name, f.suggested);
      }
      return fmt::format("{} reads {} deg/s in every one of the {:g} rows while the other axes of its sensor "
                         "move: a dead or stuck axis, whose standstills measure that value, not the rate; the "
                         "biases from this log cannot be trusted. Check the sensor",
                         name, exact_number(f.value), f.suggested);
    }
    case est::HealthCause::kAttitudeWithheld:
      return fmt::format("attitude withheld from t = {:.2f} s: {:g} flip(s) moved both platforms at once, and with "
                         "'standstill: gyro' no sensor then reads the box rate alone (the biases are not affected); "
                         "flip one platform at a time, or log the platform angles (plat1_deg, plat2_deg) and use "
                         "'standstill: platform'",
                         f.value, f.suggested);
    default: break;
  }
  return "?";
}

// the inputs' findings of stop 27: the attitude withheld, the gyro tracker's, the stamps, the
// flip set-up, the angle columns' jitter, a rejected first update
std::string describe_input_checks(const est::HealthFinding& f, const est::EstimatorConfig& cfg) {
  switch (f.cause) {
    case est::HealthCause::kAttitudeWithheldNoRate:
      return fmt::format("attitude withheld from t = {:.2f} s: no platform rested with a known angle there and no "
                         "moving one had its angle read, so no sensor gave the box rate (the biases are not "
                         "affected); log plat1_deg and plat2_deg while the platforms move, or flip one at a time",
                         f.value);
    case est::HealthCause::kAttitudeWithheldGap:
      return fmt::format("attitude withheld from t = {:.2f} s: the log has no rows for {:.3g} s there (a time gap), "
                         "and how far the box turned in it is unknown; log without gaps, or compare the pieces "
                         "between gaps as separate logs",
                         f.value, f.sigma);
    case est::HealthCause::kGyroFlipAngle:
      return fmt::format("with 'standstill: gyro' the first flip turned {:.1f} deg ({} of {:g} flips were unlike "
                         "the configured turn), but flip_angle_deg is {:g}, which makes a flip turn {:g} deg: the "
                         "platforms rest at about +-{:.1f} deg, not +-{:g}, so their positions were snapped to the "
                         "wrong stops{}; set flip_angle_deg to the rest angle (about {:.1f}) in the log header, and "
                         "initial_plat1_deg/initial_plat2_deg to the start positions in the configuration",
                         2.0 * f.value, f.count, f.suggested, f.sigma, 2.0 * f.sigma, f.value, f.sigma,
                         f.severity == est::HealthVerdict::kFailed ? " and the updates used an H the box did not have"
                                                                  : "",
                         f.value);
    case est::HealthCause::kStampRate:
      return stamp_rate_text(f);
    case est::HealthCause::kStampUnit:
      return stamp_unit_text(f.value, f.suggested);
    case est::HealthCause::kNoDataRows:
      return "the log has no data rows (a header only): there is nothing to estimate; check that the logger "
             "wrote its samples (a run stopped before the first row, or a file cut after the header)";
    case est::HealthCause::kStandstillsTooShort:
      return fmt::format("all {} rests of the platforms were too short to use: they last {:.2g} s on average "
                         "({:.2g} s at most) as logged, of which {:.2g} s at most is left once settle_s {:g} s and "
                         "end_margin_s {:g} s are taken off, below min_standstill_s {:g} s; rest at least {:.2g} s "
                         "between flips, or lower min_standstill_s (and settle_s) in the configuration (a shorter "
                         "standstill averages less noise per update)",
                         f.count, f.positions_deg.empty() ? kNaN : f.positions_deg.front()[0], f.suggested,
                         f.value, cfg.settle_s, cfg.end_margin_s, f.sigma,
                         f.sigma + cfg.settle_s + cfg.end_margin_s);
    case est::HealthCause::kAngleJitter:
      return fmt::format("no standstill was found: plat1_deg/plat2_deg move by small steps, up to {:.3g} deg between "
                         "samples, in {:.0f} % of the rows, more than angle_tolerance_deg {:g} (an encoder's noise?), "
                         "so the platforms never counted as resting; set angle_tolerance_deg: {:.2g} in the "
                         "configuration, or standstill: gyro",
                         f.value, 100.0 * f.suggested, f.sigma, 3.0 * f.value);
    case est::HealthCause::kPriorRejected:
      return fmt::format("the first update (t = {:.2f} s, NIS {:.3g}) was rejected: its residual, up to {:.3g} deg/s, "
                         "lies outside the prior (initial_sigma_dps {:g}): the biases are larger than the "
                         "configuration allows, not an outlier; that standstill was lost and the later ones brought "
                         "the estimate in. Set initial_sigma_dps to at least {:.2g}",
                         f.suggested, f.value, f.sigma, cfg.initial_sigma_dps, f.sigma);
    case est::HealthCause::kParallelHinges:
      return fmt::format("hinge1_axis and hinge2_axis are {:.1f} deg from parallel: the bias along the line both "
                         "platforms turn about can never be observed, whatever the flips; the platforms must flip "
                         "about different axes (the paper: orthogonal), or check the hinge axes in the log header",
                         f.value);
    case est::HealthCause::kNeverFlipped:
      return fmt::format("the platforms never moved: all {} standstill(s) were at {}, which measure only "
                         "R1 b1 - R2 b2 (3 of the 6 bias directions); flip each platform (eq. (5): (+,+) (+,-) "
                         "(-,-) (-,+)), or check plat1_deg/plat2_deg",
                         f.count, position_text(f.positions_deg));
    case est::HealthCause::kGyroGapPositions:
      if (std::isnan(f.suggested)) {
        return fmt::format("with 'standstill: gyro' a time gap of {:.3g} s from t = {:.2f} s may have hidden a flip, "
                           "and the platform positions after it could not be recovered: the box never turned enough "
                           "at rest to tell the four position pairs apart, so no standstill was used from there on "
                           "(the biases are those from before the gap); log without gaps, or log the platform "
                           "angles (plat1_deg, plat2_deg)",
                           f.sigma, f.value);
      }
      return fmt::format("with 'standstill: gyro' a time gap of {:.3g} s from t = {:.2f} s hid the platforms; their "
                         "positions were recovered at t = {:.2f} s from the one position pair that fits both sensors "
                         "on the turning box{}",
                         f.sigma, f.value, f.suggested,
                         f.count > 0 ? ": a flip was lost in the gap" : " (no flip was lost in it)");
    case est::HealthCause::kGyroStartMidFlip: {
      const int p = f.components.empty() ? 0 : f.components[0];
      const double pos = f.positions_deg.empty() ? driftless::kNaN : f.positions_deg[0][p == 1 ? 0 : 1];
      return fmt::format("the log starts during a flip of platform {0} (hinge rate {1:.0f} deg/s at t = {2:.2f} s): "
                         "its first position is unknown until the flip ended at t = {3:.2f} s, so no standstill was "
                         "taken before; from there platform {0} is at {4:+.0f} deg, the stop its turn went towards "
                         "(the platforms at {5}); if that is wrong, cut the log after the flip or log plat{0}_deg",
                         p, f.value, f.sigma, f.suggested, pos, position_text(f.positions_deg));
    }
    default: break;
  }
  return "?";
}

}  // namespace

std::string describe(const est::HealthFinding& f, const est::EstimatorConfig& cfg, est::GravitySource gravity) {
  est::HealthReport h;
  h.gravity_source = gravity;
  return describe(f, cfg, h);
}

std::string describe(const est::HealthFinding& f, const est::EstimatorConfig& cfg, const est::HealthReport& h) {
  const RunUsed u = run_used(cfg, h);
  if (is_flip_cause(f.cause)) return describe_flip(f, cfg);
  switch (f.cause) {
    case est::HealthCause::kNoUpdate:
    case est::HealthCause::kAllRejected:
    case est::HealthCause::kNeverLocked:
    case est::HealthCause::kUnobservable:
    case est::HealthCause::kLockLost:
    case est::HealthCause::kRelocks:
    case est::HealthCause::kLateLock:
    case est::HealthCause::kSteadyStateAtLock:
    case est::HealthCause::kLockUnreachable:
      return describe_lock(f, cfg, u);
    case est::HealthCause::kNoiseUnderstated:
    case est::HealthCause::kNoiseOverstated:
    case est::HealthCause::kRejectionsAtPosition:
    case est::HealthCause::kRejections:
    case est::HealthCause::kLoneRejection:
    case est::HealthCause::kSignalChainLag:
      return describe_fit(f, cfg, u);
    case est::HealthCause::kPaperRestAngles:
    case est::HealthCause::kPaperSchedule:
    case est::HealthCause::kSaturation:
    case est::HealthCause::kDeadAxis:
    case est::HealthCause::kAttitudeWithheld:
      return describe_input(f);
    case est::HealthCause::kAttitudeWithheldNoRate:
    case est::HealthCause::kAttitudeWithheldGap:
    case est::HealthCause::kGyroFlipAngle:
    case est::HealthCause::kStampRate:
    case est::HealthCause::kAngleJitter:
    case est::HealthCause::kPriorRejected:
    case est::HealthCause::kParallelHinges:
    case est::HealthCause::kNeverFlipped:
    case est::HealthCause::kStampUnit:
    case est::HealthCause::kNoDataRows:
    case est::HealthCause::kStandstillsTooShort:
    case est::HealthCause::kGyroGapPositions:
    case est::HealthCause::kGyroStartMidFlip:
      return describe_input_checks(f, cfg);
    case est::HealthCause::kReferenceMismatch:
      return describe_reference(f);
    case est::HealthCause::kBoxNotAtRest:
      return describe_box_motion(f);
    case est::HealthCause::kAccelUnit:
    case est::HealthCause::kAccelEmpty:
    case est::HealthCause::kCalibUncertain:
      return describe_accel(f);
    case est::HealthCause::kBoxDwellsRejected:
      return describe_box_dwells(f, u);
    case est::HealthCause::kVerticalUnobserved:
      return describe_vertical(f, cfg, u);
    case est::HealthCause::kClippedFlipsScale:
      return describe_clipped_flips(f, u);
    default: break;  // the flip-turn check's causes: describe_flip() above
  }
  return "?";
}

namespace {
// the closed-form steady state of the run's first updates, or null
std::string steady_state_json(const est::SteadyStatePrediction& p) {
  if (!p.available) return "null";
  return fmt::format("{{\"sigma_dps\": {}, \"sigma_low_dps\": {}, \"lock_sigma_dps\": {}, \"lock_unreachable\": {}, "
                     "\"q_dps2_per_s\": {}, \"interval_s\": {}, \"window_s\": {}, \"meas_var_dps2\": {}, "
                     "\"known_at_t_s\": {}, \"interval_for_lock_s\": {}, \"bias_only\": {}}}",
                     json_number(p.closed.sigma_dps), json_number(p.closed.sigma_low_dps), json_number(p.lock_sigma_dps),
                     p.lock_unreachable() ? "true" : "false", json_number(p.schedule.q_dps2_per_s),
                     json_number(p.schedule.interval_s), json_number(p.schedule.window_s),
                     json_number(p.schedule.meas_var_dps2), json_number(p.known_at_t_s),
                     json_number(p.interval_for_lock_s), p.other_states ? "false" : "true");
}
}  // namespace

std::string health_json(const est::HealthReport& h, const est::EstimatorConfig& cfg) {
  std::string unobs = "[";
  for (std::size_t i = 0; i < h.unobservable.size(); ++i) {
    unobs += fmt::format("{}\"{}\"", i ? ", " : "", kComponentNames[h.unobservable[i]]);
  }
  unobs += "]";
  std::string findings = "[";
  for (std::size_t i = 0; i < h.findings.size(); ++i) {
    findings += fmt::format("{}\n    {{\"cause\": \"{}\", \"severity\": \"{}\", \"text\": {}}}", i ? "," : "",
                            cause_key(h.findings[i].cause), est::to_string(h.findings[i].severity),
                            json_string(describe(h.findings[i], cfg, h)));
  }
  findings += h.findings.empty() ? "]" : "\n  ]";
  return fmt::format(
      "  \"health\": {{\"verdict\": \"{}\", \"locked\": {}, \"lock_t_s\": {}, \"locked_at_end\": {}, \"lock_lost_t_s\": {}, "
      "\"updates\": {}, \"rejected\": {}, "
      "\"rejected_fraction\": {}, \"nis_updates\": {}, \"nis_dof_mean\": {}, \"nis_mean\": {}, "
      "\"nis_mean_band_95\": [{}, {}], \"nis_mean_degraded_above\": {}, \"relocks\": {}, \"lock_losses\": {}, "
      "\"unobservable\": {},\n"
      "  \"steady_state\": {},\n"
      "  \"signal_chain\": {{\"samples\": {}, \"lag_s\": {}, \"lag_sigma_s\": {}, \"update_excess\": {}, "
      "\"significant\": {}}},\n"
      "  \"findings\": {}}}",
      est::to_string(h.verdict), h.locked ? "true" : "false", json_number(h.lock_t_s),
      h.locked_at_end ? "true" : "false", json_number(h.lock_lost_t_s), h.updates, h.rejected,
      json_number(h.rejected_fraction), h.nis_updates, json_number(h.nis_dof_mean), json_number(h.nis_mean), json_number(h.nis_mean_band_lo),
      json_number(h.nis_mean_band_hi), json_number(h.nis_mean_degraded_above), h.relocks, h.lock_losses, unobs, steady_state_json(h.steady_state),
      h.signal_chain.samples,
      json_number(h.signal_chain.lag_s), json_number(h.signal_chain.lag_sigma_s), json_number(h.signal_chain.update_excess),
      h.signal_chain.significant ? "true" : "false", findings);
}

std::string tune_json(const est::TuneResult* t) {
  if (t == nullptr) return "null";
  return fmt::format("{{\"block_s\": {}, \"noise_block_pairs\": {}, \"noise_estimated\": {}, "
                     "\"noise_density_dps_rthz\": {}, \"wander_pairs\": {}, \"q_estimated\": {}, "
                     "\"q_dps2_per_s\": {}, \"q_upper_bound\": {}}}",
                     json_number(t->block_s), t->noise_block_pairs, t->noise_estimated ? "true" : "false",
                     json_number(t->noise_density_dps_rthz), t->wander_pairs, t->q_estimated ? "true" : "false",
                     json_number(t->q_dps2_per_s), t->q_upper_bound ? "true" : "false");
}

namespace {
// "locked at t = 57.0 s", "locked at t = 57.0 s, lost at t = 518.9 s", "never locked"
std::string lock_text(const est::HealthReport& h) {
  if (!h.locked) return "never locked";
  std::string o = fmt::format("locked at t = {:.1f} s", h.lock_t_s);
  if (!h.locked_at_end) o += fmt::format(", lost at t = {:.1f} s", h.lock_lost_t_s);
  return o;
}
}  // namespace

std::vector<std::string> health_lines(const est::HealthReport& h, const est::EstimatorConfig& cfg) {
  std::vector<std::string> lines;
  // a log without data rows has no lock, NIS or updates to speak of
  if (!h.findings.empty() && h.findings.front().cause == est::HealthCause::kNoDataRows) {
    lines.push_back(fmt::format("health: {}: the log has no data rows", est::to_string(h.verdict)));
    lines.push_back(fmt::format("  {}: {}", est::to_string(h.findings.front().severity), describe(h.findings.front(), cfg, h)));
    return lines;
  }
  lines.push_back(fmt::format(
      "health: {}: {}, {} of {} updates rejected ({:.1f} %), NIS mean {:.3g} (95 % band {:.3g}..{:.3g}), {} re-lock(s)",
      est::to_string(h.verdict), lock_text(h),
      h.rejected, h.updates, std::isfinite(h.rejected_fraction) ? 100.0 * h.rejected_fraction : 0.0, h.nis_mean,
      h.nis_mean_band_lo, h.nis_mean_band_hi, h.relocks));
  for (const auto& f : h.findings) lines.push_back(fmt::format("  {}: {}", est::to_string(f.severity), describe(f, cfg, h)));
  return lines;
}

}  // namespace driftless::cli
