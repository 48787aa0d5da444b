// The ADC of each channel, read from the raw output: its LSB (quantisation lattice), where it
// clips (saturation plateaus), and codes it never outputs. docs/compare.md section 3.
#pragma once

#include <vector>

#include "diagnose/compare.hpp"
#include "diagnose/residual.hpp"

namespace driftless::diagnose {

/// quantization, saturation and adc_missing_codes against the model, each with its evidence
/// (2 ln-likelihood gain - BIC penalty; `log_m` = ln of the blocks per channel).
std::vector<Candidate> adc_candidates(const Replay& r, const Residual& res, const CompareModel& model,
                                      const std::array<double, 6>& noise_floor_dps, double log_m);

}  // namespace driftless::diagnose
