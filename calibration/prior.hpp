// calib.yaml as a model prior for the twin: the sensor calibration C and the end-stop travel that
// reproduce the calibrated M, written as a model-config file (`model:` block, docs/calibration.md).
#pragma once

#include <array>
#include <string>

#include <Eigen/Core>

#include "calibration/calib_file.hpp"

namespace driftless::calib {

/// The twin parameters of one sensor that give M: y = (I + K) diag(1 + s) R_mount^T ... with
/// M^-1 = C T^T, C = (I + K) diag(1 + s) R_sensor_from_nominal, the -90 stop taken as exact.
struct SensorPrior {
  Eigen::Vector3d scale_pct = Eigen::Vector3d::Zero();        // scale_factor.value_pct
  Eigen::Matrix3d misalignment_pct = Eigen::Matrix3d::Zero(); // misalignment.matrix_pct (diag 0)
  Eigen::Vector3d mounting_deg = Eigen::Vector3d::Zero();     // mounting_misalignment.angles_deg
  Eigen::Vector2d stop_error_deg = Eigen::Vector2d::Zero();   // box.stopN_error_deg [-stop, +stop]
};

/// Splits M into the twin's effect parameters (the common hinge rotation goes to the mounting).
SensorPrior sensor_prior(const est::CalibMatrices& m, int sensor, const Eigen::Vector3d& hinge_axis);

/// The model-config YAML (a file holding only `model:`) that plants the calibrated errors:
/// box hinge axes and stop errors (a self-calibration's end_stops as they are), each sensor's scale_factor, misalignment and
/// mounting_misalignment with their run-to-run sigmas set to 0.
std::string model_prior_yaml(const CalibFile& c);

}  // namespace driftless::calib
