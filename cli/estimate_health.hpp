// The health verdict of a `driftless estimate` run as text (docs/estimator.md section 6.1): the
// `health` block of summary.json and the console lines, each finding with its likely cause and
// the fix. The verdict itself is computed in estimator/health.*; text is made only here.
#pragma once

#include <string>
#include <vector>

#include "estimator/config.hpp"
#include "estimator/health.hpp"
#include "estimator/tune.hpp"

namespace driftless::cli {

/// "b1_z + b2_y" for the component indices 0..5 (b1_x .. b2_z).
std::string component_names(const std::vector<int>& components);
/// The finding as one line: what was measured, the likely cause and the fix.
std::string describe(const est::HealthFinding& f, const est::EstimatorConfig& cfg);
/// The `"health": {...}` member of summary.json (no trailing comma), indented by two spaces.
std::string health_json(const est::HealthReport& h, const est::EstimatorConfig& cfg);
/// The `tune` value of summary.json: what --tune auto measured, or null.
std::string tune_json(const est::TuneResult* t);
/// The console lines: "health: ok|degraded|failed ..." then one line per finding.
std::vector<std::string> health_lines(const est::HealthReport& h, const est::EstimatorConfig& cfg);

}  // namespace driftless::cli
