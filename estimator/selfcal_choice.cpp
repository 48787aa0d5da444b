#include "estimator/selfcal_choice.hpp"

#include <cmath>

namespace driftless::est {

const char* to_string(SelfcalMode m) {
  switch (m) {
    case SelfcalMode::kOn: return "on";
    case SelfcalMode::kOff: return "off";
    case SelfcalMode::kAuto: break;
  }
  return "auto";
}

namespace {

// the findings whose cause the self-calibration's states model (docs/estimator.md 1b, 1c, 1g):
// a position-dependent error, a model error spread over the positions, a residual larger than
// noise and wander explain, and the vertical the six-state model cannot see
bool modelled_by_selfcal(HealthCause c) {
  switch (c) {
    case HealthCause::kRejectionsAtPosition:
    case HealthCause::kRejections:
    case HealthCause::kAllRejected:
    case HealthCause::kNoiseUnderstated:
    case HealthCause::kVerticalUnobserved:
      return true;
    default:
      return false;
  }
}

// a degraded or failed finding of this cause
bool has_bad(const HealthReport& h, HealthCause c) {
  for (const HealthFinding& f : h.findings) {
    if (f.cause == c && f.severity != HealthVerdict::kOk) return true;
  }
  return false;
}

// `a` has a degraded or failed finding whose cause `b` has not. An NIS above its band is not
// counted: the noise level is the configuration's, which both passes share (--tune auto measures
// it), and the six-state pass's NIS over the updates its gate accepted can hide it
bool adds_finding(const HealthReport& a, const HealthReport& b) {
  for (const HealthFinding& f : a.findings) {
    if (f.severity == HealthVerdict::kOk || f.cause == HealthCause::kNoiseUnderstated) continue;
    if (!has_bad(b, f.cause)) return true;
  }
  return false;
}

}  // namespace

SelfcalTrigger selfcal_trigger(const HealthReport& six_state, bool gravity_logged) {
  SelfcalTrigger t;
  if (!gravity_logged || six_state.verdict == HealthVerdict::kOk) return t;
  for (const HealthFinding& f : six_state.findings) {
    if (f.severity == HealthVerdict::kOk || !modelled_by_selfcal(f.cause)) continue;
    t.wanted = true;
    t.cause = f.cause;
    return t;
  }
  return t;
}

int verdict_rank(HealthVerdict v) {
  switch (v) {
    case HealthVerdict::kOk: return 2;
    case HealthVerdict::kDegraded: return 1;
    case HealthVerdict::kFailed: break;
  }
  return 0;
}

bool selfcal_pass_better(const HealthReport& selfcal, const HealthReport& six_state) {
  // NaN (no accepted update, or none rejected to compare) compares false: not better
  const double gain = six_state.rejected_fraction - selfcal.rejected_fraction;
  const int a = verdict_rank(selfcal.verdict), b = verdict_rank(six_state.verdict);
  // its NIS in its band, or a better verdict with fewer rejections: the noise set too low, which
  // the NIS shows, is no reason to keep a six-state pass that rejects what the other explains
  const bool fits = std::isfinite(selfcal.nis_mean) &&
                    (selfcal.nis_mean <= selfcal.nis_mean_band_hi || (a > b && gain >= kSelfcalRejectionGain));
  return fits && gain >= 0.0 && a >= b && !adds_finding(selfcal, six_state) &&
         (a > b || gain >= kSelfcalRejectionGain);
}

}  // namespace driftless::est
