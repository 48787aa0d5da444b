// The text of the accelerometer and calibration-input findings (estimator/accel_check.hpp): an
// accel column in g or mg, an empty one, a --calib file whose G/E are too uncertain to apply as
// exact corrections. Each names what was measured and the fix.
#pragma once

#include <string>

#include "estimator/health.hpp"

namespace driftless::cli {

/// kAccelUnit, kAccelEmpty, kCalibUncertain (only without the self-calibration) as one line.
std::string describe_accel(const est::HealthFinding& f);

}  // namespace driftless::cli
