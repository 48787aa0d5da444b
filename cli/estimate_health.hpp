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

/// The finding's id in summary.json (docs/estimator.md section 6.1): "rejections_at_position", ...
const char* cause_key(est::HealthCause c);
/// "b1_z + b2_y" for the component indices 0..5 (b1_x .. b2_z).
std::string component_names(const std::vector<int>& components);

/// What the run already used. No finding's fix names one of these as the thing to try (issue 13;
/// the outsider's F10, F19, F22): every fix text picks its alternative from here.
struct RunUsed {
  bool selfcal = false;      // --selfcal (self_calibration)
  bool tune_auto = false;    // --tune auto (the noise was measured from the log: noise_from_log)
  bool calib = false;        // --calib (a calibration is in the configuration)
  bool box_at_rest = false;  // --box-at-rest
  est::GravitySource gravity = est::GravitySource::kNone;  // what drove G (self-calibration)
  // what the run saw (HealthReport; unknown: as a box that may stand still, no columns)
  bool box_turned = false;             // ref_q or the fused rate showed the box turning at a rest
  std::uint64_t box_still = 0;         // standstills in which ref_q saw it still (pauses)
  double box_ref_rate_dps = kNaN;      // ref_q's largest turn rate over a standstill, deg/s
  double box_gyro_change_dps = kNaN;   // the fused rate's largest change within one, deg/s
  bool ref_q = false, accel = false;   // the log has ref_q / accel columns
  bool short_rests = false;            // a standstills_too_short finding: the rests, not the flips, are the cause
};
RunUsed run_used(const est::EstimatorConfig& cfg, est::GravitySource gravity);
/// The same with what the run saw: the box's motion at the rests and the log's columns.
RunUsed run_used(const est::EstimatorConfig& cfg, const est::HealthReport& h);
/// For an error a constant bias cannot absorb (g-sensitivity, scale, misalignment): what to try.
std::string model_error_fix(const RunUsed& u);
/// For noise or wander larger than configured: what to try.
std::string noise_fix(const RunUsed& u);
/// "calibrate with 'driftless calibrate' and pass --calib", or, with a calibration in use, recalibrate.
std::string calibrate_fix(const RunUsed& u);

/// The finding as one line: what was measured, the likely cause and the fix (`gravity`: what drove
/// the g-sensitivity states, HealthReport::gravity_source).
std::string describe(const est::HealthFinding& f, const est::EstimatorConfig& cfg,
                     est::GravitySource gravity = est::GravitySource::kNone);
/// The same, the fixes picked by what the run saw (h: its gravity source, box motion and columns).
std::string describe(const est::HealthFinding& f, const est::EstimatorConfig& cfg, const est::HealthReport& h);
/// Stamps whose median interval (`interval_s`, as read) only makes sense in another unit
/// (`to_s`: est::stamp_unit_to_s()): the likely unit and the fix (estimate's finding and check).
std::string stamp_unit_text(double interval_s, double to_s);
/// The `"health": {...}` member of summary.json (no trailing comma), indented by two spaces.
std::string health_json(const est::HealthReport& h, const est::EstimatorConfig& cfg);
/// The `tune` value of summary.json: what --tune auto measured, or null.
std::string tune_json(const est::TuneResult* t);
/// The console lines: "health: ok|degraded|failed ..." then one line per finding.
std::vector<std::string> health_lines(const est::HealthReport& h, const est::EstimatorConfig& cfg);

}  // namespace driftless::cli
