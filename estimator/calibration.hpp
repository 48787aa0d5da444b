// Calibration on the pan/tilt unit (paper section 4): one matrix M per sensor and platform
// position that combines the sensor calibration C (scale factors incl. ADC gain, misalignment,
// cross-coupling) with the platform's actual rotation T.
//
// Convention (used by the fit, calib.yaml, the estimator and the twin alike):
//
//     y_i = M_{i,p}^{-1} w_body + b_i + n_i          (eq. (1) with R_i^T -> M_{i,p}^{-1})
//
// w_body: the box's inertial rate in box axes (deg/s); y_i: sensor i's output in its own axes;
// p: the platform end stop the sensor rests at (-90 or +90). So M_{i,p} (y_i - b_i) maps an output
// back into the box frame, and in eq. (2) r = M_1 y_1 - M_2 y_2 replaces R_1 y_1 - R_2 y_2.
// An ideal box has M_{i,p} = R_i(p) = Rot(hinge_i, p). With M^{-1} = C T^T (C: sensor calibration,
// T: actual platform rotation) M = T C^{-1}.
//
// Eigen and the standard library only (this code also runs next to hardware).
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "estimator/filter.hpp"

#include "estimator/geometry.hpp"

namespace driftless::est {

/// Index of a platform end stop in calibration tables: 0 = -90 deg, 1 = +90 deg.
inline constexpr int kPosMinus90 = 0;
inline constexpr int kPosPlus90 = 1;
/// Nominal end-stop angle (deg) of a position index.
inline constexpr double position_deg(int pos) { return pos == kPosPlus90 ? 90.0 : -90.0; }
/// Position index of a platform angle within tol_deg of +-90, or -1 (moving / elsewhere).
int position_index(double plat_deg, double tol_deg = 10.0);
/// "-90" / "+90".
std::string position_name(int pos);

/// The four calibrated matrices M_{i,p} (box_from_sensor), [sensor 0/1][position 0=-90, 1=+90].
struct CalibMatrices {
  std::array<std::array<Eigen::Matrix3d, 2>, 2> M_box_from_sensor{};

  /// Ideal box: M_{i,p} = Rot(hinge_i, +-90 deg).
  static CalibMatrices nominal(const Eigen::Vector3d& hinge1_axis,
                               const Eigen::Vector3d& hinge2_axis);
  const Eigen::Matrix3d& M(int sensor, int pos) const { return M_box_from_sensor[sensor][pos]; }
  Eigen::Matrix3d& M(int sensor, int pos) { return M_box_from_sensor[sensor][pos]; }
  /// Throws std::invalid_argument when a matrix is not finite or is (near) singular.
  void validate() const;
};

/// The filter's calibration hook (EstimatorConfig::calibration) holding these four matrices.
Calibration to_filter_calibration(const CalibMatrices& m);

/// eq. (1) with M: the output of a calibrated sensor without noise, y = M^{-1} w_body + b (deg/s).
Eigen::Vector3d sensor_output_dps(const Eigen::Matrix3d& M_box_from_sensor,
                                  const Eigen::Vector3d& w_body_dps,
                                  const Eigen::Vector3d& bias_dps);
/// Its inverse: the box rate that output came from, w_body = M (y - b) (deg/s).
Eigen::Vector3d box_rate_dps(const Eigen::Matrix3d& M_box_from_sensor, const Eigen::Vector3d& y_dps,
                             const Eigen::Vector3d& bias_dps);

// ---- the fit ------------------------------------------------------------------------------

/// One gyro sample on a rate-table plateau (the box turning at the commanded rate).
struct CalibSample {
  double t_s = 0.0;
  double sign = 0.0;                    // commanded rate sign, +1 or -1
  std::array<Eigen::Vector3d, 2> gyro_dps{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  Eigen::Vector3d earth_rate_box_dps = Eigen::Vector3d::Zero();  // from ref_q + latitude
};

/// One rig segment: the box mounted in one orientation, both platforms at rest at an end stop,
/// the table turning the box back and forth about axis_box at +-rate_dps.
struct CalibSegment {
  std::string name;                     // e.g. "XY@-90"
  std::string orientation;              // "XY", "YZ", "XZ" or "custom"
  std::array<int, 2> pos{kPosMinus90, kPosMinus90};  // end stop of sensor 1 and 2
  Eigen::Vector3d axis_box = Eigen::Vector3d::UnitZ();  // table rotation axis in box axes (unit)
  double rate_dps = 50.0;               // table rate magnitude
  std::vector<CalibSample> samples;     // plateau samples only
  /// mean specific force of sensor 1 and 2 over the plateaus, g, sensor axes (from the
  /// accelerometers); NaN when the log has none. Feeds the g-sensitivity fit.
  std::array<Eigen::Vector3d, 2> f_mean_g{Eigen::Vector3d::Constant(kNaN), Eigen::Vector3d::Constant(kNaN)};
  /// mean temperature of sensor 1 and 2 over the plateaus, degC; NaN when the log has none
  std::array<double, 2> temp_mean_c{kNaN, kNaN};
};

enum class CalibMethod {
  kTopToTop,      // the paper: average top and bottom of each square wave, Earth rate ignored
  kLeastSquares,  // full linear least squares, Earth rate from ref_q + latitude removed
};
std::string method_name(CalibMethod m);

struct CalibFitOptions {
  CalibMethod method = CalibMethod::kLeastSquares;
  std::size_t min_samples_per_level = 20;  // per segment and per sign (top / bottom)
  /// Smallest singular value of the stacked unit rotation axes per sensor and position below
  /// which a direction counts as unobservable (1 = three orthogonal axes).
  double min_axis_singular_value = 0.2;
  void validate() const;
};

/// The bias a sensor showed in one segment (deg/s). Top-to-top: Earth rate included.
struct SegmentBias {
  std::string segment;
  Eigen::Vector3d bias_dps = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_dps = Eigen::Vector3d::Zero();
};

/// The fit of one sensor at one end stop.
struct SensorPositionFit {
  Eigen::Matrix3d M = Eigen::Matrix3d::Identity();             // box_from_sensor
  Eigen::Matrix3d M_sigma = Eigen::Matrix3d::Zero();           // 1-sigma of each coefficient of M
  Eigen::Matrix3d M_inv = Eigen::Matrix3d::Identity();         // sensor response: y = M_inv w + b
  Eigen::Matrix3d M_inv_sigma = Eigen::Matrix3d::Zero();
  Eigen::Matrix<double, 9, 9> M_inv_cov = Eigen::Matrix<double, 9, 9>::Zero();  // of vec(M_inv), column-major
  std::vector<SegmentBias> biases;                             // one per segment used
  Eigen::Vector3d residual_rms_dps = Eigen::Vector3d::Zero();  // per output axis
  Eigen::Vector3d residual_max_dps = Eigen::Vector3d::Zero();
  std::size_t n_samples = 0;
};

struct CalibFit {
  CalibMethod method = CalibMethod::kLeastSquares;
  std::array<std::array<SensorPositionFit, 2>, 2> fit{};  // [sensor][position]
  CalibMatrices matrices() const;
};

/// Fits M and the biases from the rig segments (paper section 4). Throws std::invalid_argument
/// naming the sensor, position and unobservable coefficients when the segments do not determine
/// every coefficient (an orientation missing), or naming the segment when it lacks samples.
CalibFit fit_calibration(const std::vector<CalibSegment>& segments,
                         const CalibFitOptions& opts = {});

// ---- g-sensitivity from the per-segment biases ------------------------------------------------

/// The g-sensitivity G of each sensor (y += G f, deg/s per g) read from the rig: every segment
/// holds the box in another orientation, so gravity lies along other sensor axes and the
/// segment's bias is b_seg = b0 + G f_seg + k_T (T_seg - T_mean). Per output axis j a
/// least-squares fit of [b0_j, G_j,:, k_T,j] over the segments (both end stops; at least 5
/// segments with 3 independent gravity directions). The temperature term (the bias drifts while
/// the chip warms up during the rig, and would otherwise alias into G) is fitted when every
/// segment has a temperature, there are 6 or more segments and the temperatures spread by more
/// than 0.05 degC.
struct GSensitivityFit {
  bool valid = false;
  std::string reason;  // why not valid (too few segments, no accelerometer data, degenerate)
  bool temperature_term = false;
  std::array<Eigen::Matrix3d, 2> G_dps_per_g{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  std::array<Eigen::Matrix3d, 2> G_sigma{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  std::array<Eigen::Vector3d, 2> bias_tc_dps_per_degc{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  std::array<Eigen::Vector3d, 2> b0_dps{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  std::array<Eigen::Vector3d, 2> residual_rms_dps{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  std::size_t segments = 0;
};
/// Fits G from `fit`'s per-segment biases and the segments' mean specific force. Never throws
/// for missing data: returns valid = false with the reason.
GSensitivityFit fit_g_sensitivity(const std::vector<CalibSegment>& segments, const CalibFit& fit);

// ---- reading a fitted M as physical errors ------------------------------------------------

/// Errors read off M for one sensor, each observable without extra assumptions: scale factors
/// and the angles between sensing axes do not depend on T, and the travel between the stops is
/// M_{-90} M_{+90}^{-1} = T_{-90} T_{+90}^T (C cancels).
struct CalibErrors {
  Eigen::Vector3d scale_error = Eigen::Vector3d::Zero();  // |row j of M^{-1}| - 1, mean of the stops
  Eigen::Vector3d nonorthogonality_deg = Eigen::Vector3d::Zero();  // 90 - angle(x,y), (y,z), (x,z)
  std::array<Eigen::Vector3d, 2> axis_error_deg{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  // angle of sensing axis j from its nominal box direction, per position
  std::array<Eigen::Vector3d, 2> tilt_box_deg{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  // small rotation vector (deg, box axes) taking the nominal sensor frame to the fitted one
  // (the polar-decomposition rotation of M), per position
  double travel_error_deg = 0.0;   // (theta_+90 - theta_-90) - 180 about the hinge
  double travel_offaxis_deg = 0.0; // rotation of M_{-90} M_{+90}^{-1} not about the hinge (should be 0)
};
/// Reads the physical errors of sensor `sensor` from M (hinge: that platform's axis, box frame).
CalibErrors describe_errors(const CalibMatrices& m, int sensor, const Eigen::Vector3d& hinge_axis);

}  // namespace driftless::est
