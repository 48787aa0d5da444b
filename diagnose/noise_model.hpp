// What the noise model gets wrong, judged on the residual left after the selected effects (so
// a missing physical effect is never mistaken for more noise): white noise density, bias
// instability, rate random walk, turn-on bias against the model's spread, sample jitter.
// docs/compare.md section 3.
#pragma once

#include <vector>

#include "diagnose/summary.hpp"

namespace driftless::diagnose {

/// Noise-model candidates: supported ones (evidence > threshold) and the others.
struct NoiseModelFindings {
  std::vector<Candidate> supported, not_supported;
};

/// Evaluates the noise model per channel on the residual after the selection.
NoiseModelFindings noise_model_candidates(const Replay& r, const Residual& res, const Channels& ch,
                                          const CompareModel& model, const AfterFit& after, double threshold);

}  // namespace driftless::diagnose
