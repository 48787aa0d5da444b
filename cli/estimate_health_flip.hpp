// The flip-turn check's findings as text (docs/estimator.md section 6.4): what the gyros saw over
// the flips against the angle columns, the likely cause and the fix in the words a user needs.
#pragma once

#include <string>

#include "estimator/config.hpp"
#include "estimator/health.hpp"

namespace driftless::cli {

/// True for the causes of the flip-turn check (kFlipGyroUnit .. kFlipsTooSlow).
bool is_flip_cause(est::HealthCause c);
/// The summary.json key of such a cause ("flip_gyro_unit", ...).
const char* flip_cause_key(est::HealthCause c);
/// The finding as one line.
std::string describe_flip(const est::HealthFinding& f, const est::EstimatorConfig& cfg);

}  // namespace driftless::cli
