// The default choice of model for `driftless estimate` (docs/estimator.md section 1i): the paper's
// six-state filter where it fits the log, the self-calibrating one (section 1b) where the six-state
// pass shows an error a constant bias cannot absorb. The rule reads the six-state pass's health
// verdict only, so a log the paper's model fits is estimated exactly as before. Standard library only.
#pragma once

#include "estimator/health.hpp"

namespace driftless::est {

/// How the self-calibrating mode is chosen: forced on (--selfcal, self_calibration: true), forced
/// off (--no-selfcal), or from the six-state pass's health (the default).
enum class SelfcalMode { kAuto, kOn, kOff };
const char* to_string(SelfcalMode m);  // "auto", "on", "off"

/// Whether the six-state pass calls for the self-calibrating pass, and the finding that does.
struct SelfcalTrigger {
  bool wanted = false;
  HealthCause cause = HealthCause::kNoUpdate;  // the first finding (worst first) that calls for it
};

/// The self-calibrating pass is wanted when the six-state verdict is not ok and one of its
/// degraded or failed findings is an error that G, E or the end-stop states model: updates
/// rejected at one position pair or spread over them, every update rejected, the NIS mean above
/// its band, or the shared vertical unobserved. `gravity_logged`: the log has both accel triads
/// or ref_q (what drives the g-sensitivity states); without either the pass is not tried.
SelfcalTrigger selfcal_trigger(const HealthReport& six_state, bool gravity_logged);

/// Order of the verdicts: ok above degraded above failed.
int verdict_rank(HealthVerdict v);

/// Whether the self-calibrating pass's results replace the six-state pass's: where its model fits
/// the data better. All of: no more of its updates rejected, a verdict at least as good, no degraded
/// or failed finding of a cause the six-state pass did not have (it must remove the problem, not
/// trade it for another: a late lock, an unobserved vertical; an NIS above its band does not count,
/// the noise level being the configuration's), a gain (a better verdict or kSelfcalRejectionGain
/// less rejected), and its NIS mean at or below the top of its 95 % band unless its verdict is
/// better with that gain in rejections. Noise larger than configured that no model explains (more
/// rejected) keeps the six-state results; its fix is --tune auto.
inline constexpr double kSelfcalRejectionGain = 0.05;
bool selfcal_pass_better(const HealthReport& selfcal, const HealthReport& six_state);

}  // namespace driftless::est
