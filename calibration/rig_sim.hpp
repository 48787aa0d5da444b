// The simulated calibration rig: the paper's section 4 procedure run on the twin's pan/tilt unit.
// The MuJoCo box (twin/world.hpp: motors pressing the platforms onto their real, error-laden end
// stops) is carried by a rate table that turns it back and forth about the orientation's axis;
// between segments the table re-orients the box smoothly and the motors flip the platforms.
// The sensors are the scenario's sensor models (twin/sensor/), planted errors included.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "estimator/calibration.hpp"
#include "estimator/log.hpp"
#include "calibration/rig_plan.hpp"
#include "twin/scenario.hpp"

namespace driftless::calib {

/// The scenario's `calibration:` block (docs/calibration.md).
struct RigParams {
  ProcedureParams procedure;         // rates, segment lengths, orientations, full scale
  double table_accel_dps2 = 1000.0;  // deg/s^2, rate-table acceleration at each reversal
  double remount_s = 3.0;            // s, the smooth re-orientation between segments (< gap_s)
  std::string method = "least_squares";  // default fit method
  void validate() const;
};

/// A calibration scenario: a regular scenario (model, latitude, rate, seed; its motion and flip
/// schedule are not used) plus the rig.
struct CalibScenario {
  twin::Scenario scenario;
  RigParams rig;
};

/// Loads a scenario file holding a `calibration:` block (its other keys are a normal scenario).
/// Errors name file, line and key.
CalibScenario load_calib_scenario(const std::filesystem::path& path);

/// The outcome of a simulated rig run.
struct RigRun {
  std::vector<Sample> samples;       // the log rows (true_ columns filled)
  log::Metadata meta;
  RigPlan plan;
  /// The true M per sensor and end stop: the sensor model's realised calibration C and the
  /// platforms' mean rest angles measured in MuJoCo (M^-1 = C T^T).
  est::CalibMatrices true_M;
  std::array<std::array<double, 2>, 2> rest_angle_deg{};  // [platform][pos], MuJoCo joint angle
};

/// Runs the procedure. `progress(fraction)` may return false to stop (the run is then partial
/// and the call throws std::runtime_error).
RigRun run_rig(const CalibScenario& cs, const std::function<bool(double)>& progress = {});

}  // namespace driftless::calib
