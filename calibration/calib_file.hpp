// calib.yaml: the calibrated matrices M per sensor and end stop, their 1-sigma, the fit residuals
// and the rig conditions. Written by `driftless calibrate`, read by `driftless estimate --calib`
// and by the twin (as a model prior). Format: docs/calibration.md.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "estimator/calibration.hpp"
#include "calibration/rig_plan.hpp"

namespace driftless::calib {

inline constexpr const char* kCalibFormat = "driftless-calib 1";

/// Where and how the calibration was made.
struct RigConditions {
  std::string source;                    // "scenario FILE" / "log FILE, plan FILE"
  double latitude_deg = driftless::kNaN;   // deg
  double sample_rate_hz = driftless::kNaN; // Hz
  bool earth_rate_removed = false;
  std::array<double, 2> mean_temp_c{driftless::kNaN, driftless::kNaN};  // degC, per sensor
  Eigen::Vector3d hinge1_axis = Eigen::Vector3d::UnitZ();  // box axes
  Eigen::Vector3d hinge2_axis = Eigen::Vector3d::UnitX();
  RigPlan plan;                          // the segments used (times, orientations, rates)
  std::vector<std::size_t> samples_used; // plateau samples per segment
};

/// The contents of calib.yaml that its readers use.
struct CalibFile {
  std::string method;                    // top_to_top | least_squares
  est::CalibMatrices M;                  // [sensor][pos], box_from_sensor
  std::array<std::array<Eigen::Matrix3d, 2>, 2> M_sigma{};  // 1-sigma per coefficient (0 if absent)
  std::array<std::array<Eigen::Vector3d, 2>, 2> residual_rms_dps{};
  Eigen::Vector3d hinge1_axis = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d hinge2_axis = Eigen::Vector3d::UnitX();
  double latitude_deg = driftless::kNaN;
  bool earth_rate_removed = false;
  std::string source;
  /// g-sensitivity per sensor (sensorN.g_sensitivity.G_dps_per_g, deg/s per g), when fitted
  bool has_g_sensitivity = false;
  std::array<Eigen::Matrix3d, 2> G_dps_per_g{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  std::array<Eigen::Matrix3d, 2> G_sigma_dps_per_g{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};  // 1-sigma
  /// scale-factor and misalignment error per sensor (sensorN.scale_misalignment, fraction, sensor
  /// axes: y = (I + E) M^-1 w + ...) with each element's 1-sigma; a self-calibration writes it
  bool has_scale_misalign = false;
  std::array<Eigen::Matrix3d, 2> E_frac{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  std::array<Eigen::Matrix3d, 2> E_sigma_frac{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  /// `matrices: nominal`: M are the nominal rotations Rot(hinge, +-90), not calibrated (a
  /// self-calibration's file); the twin prior then leaves scale, misalignment and mounting alone
  bool matrices_nominal = false;
  /// bias temperature coefficients (sensorN.temperature, deg/s per degC) with their 1-sigma
  bool has_temp_coef = false;
  std::array<Eigen::Vector3d, 2> temp_coef_dps_per_degc{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  std::array<Eigen::Vector3d, 2> temp_coef_sigma_dps_per_degc{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  /// end-stop angle errors (end_stops.platformN, deg, actual - read rest angle about the hinge;
  /// [platform 1 at -90, at +90, platform 2 at -90, at +90]) with their 1-sigma; a self-calibration
  /// with end-stop states writes them (only with matrices_nominal)
  bool has_end_stops = false;
  Eigen::Vector4d end_stop_deg = Eigen::Vector4d::Zero();
  Eigen::Vector4d end_stop_sigma_deg = Eigen::Vector4d::Zero();
  /// M as the twin should plant it: the file's M with E folded in, M (I + E)^-1 (M alone without E)
  est::CalibMatrices matrices_with_scale() const;
  /// what the estimator uses: M, G, E (each with its sigma) and the temperature coefficients
  est::Calibration to_filter_calibration() const;
};

/// What `driftless estimate --selfcal --calib-out` writes: the g-sensitivity, scale/misalignment,
/// temperature coefficients and end-stop angle errors the filter estimated, each with its 1-sigma;
/// M stays nominal.
struct SelfCalibration {
  std::string source;  // "estimate --selfcal on FILE"
  double latitude_deg = driftless::kNaN;
  double sample_rate_hz = driftless::kNaN;
  Eigen::Vector3d hinge1_axis = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d hinge2_axis = Eigen::Vector3d::UnitX();
  std::array<Eigen::Matrix3d, 2> G_dps_per_g{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  std::array<Eigen::Matrix3d, 2> G_sigma{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  bool scale_states = false;  // E below was estimated (scale_misalign_sigma_frac > 0)
  std::array<Eigen::Matrix3d, 2> E_frac{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  std::array<Eigen::Matrix3d, 2> E_sigma_frac{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  bool temp_states = false;  // the temperature coefficients below were states
  std::array<Eigen::Vector3d, 2> temp_coef_dps_per_degc{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  std::array<Eigen::Vector3d, 2> temp_coef_sigma_dps_per_degc{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  std::array<double, 2> temp_ref_c{driftless::kNaN, driftless::kNaN};  // degC, of the final bias
  bool stop_states = false;  // the end-stop angles below were states (docs/estimator.md section 1g)
  Eigen::Vector4d end_stop_deg = Eigen::Vector4d::Zero();        // deg, [p1 -90, p1 +90, p2 -90, p2 +90]
  Eigen::Vector4d end_stop_sigma_deg = Eigen::Vector4d::Zero();  // deg, 1-sigma
};

/// Writes a self-calibration as calib.yaml (same format; method selfcal, matrices nominal).
void save_selfcal_calib(const std::filesystem::path& path, const SelfCalibration& sc);

/// Writes calib.yaml (throws std::runtime_error naming the path when it cannot be written).
/// With a valid `g`, each sensor block also holds its g_sensitivity.
void save_calib(const std::filesystem::path& path, const est::CalibFit& fit,
                const RigConditions& rig, const est::GSensitivityFit* g = nullptr);
/// Reads calib.yaml; throws std::invalid_argument naming file, line and key (missing matrix,
/// wrong shape, singular M, another format).
CalibFile load_calib(const std::filesystem::path& path);
/// Reads calib.yaml from its text (`file` names it in errors); what load_calib does after reading.
CalibFile parse_calib(const std::string& yaml_text, const std::string& file);

}  // namespace driftless::calib
