// The estimator's configuration: plain values with units and a validate() that names the field.
// Read from `key: value` files (docs/estimator.md section 5) by config.cpp. Eigen + std only.
#pragma once

#include <array>
#include <iosfwd>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "estimator/mpu6050.hpp"

namespace driftless::est {

/// paper: H_k switches by k mod 4 as in eq. (5), 6-dim stacked residuals of consecutive
/// standstills. general: H from the platform attitudes in force (or calibrated matrices), one
/// 3-dim residual per standstill (or per sample).
enum class FilterMode { kPaper, kGeneral };

/// Where standstills (both platforms at rest relative to the box) come from.
enum class StandstillSource {
  kPlatformColumns,  // plat1_deg / plat2_deg: at rest when both are finite and unchanged
  kGyroSignal,       // the gyros alone (hardware without angle read-back): flips show as a
                     // rate difference between the sensors; positions tracked from the flips
  kSchedule,         // a fixed clock: one standstill every standstill_period_s (the paper's
                     // static Fig. 5 run, where the platforms never moved)
};

/// How P is updated after a gain: the paper's printed (I - W H)(P + Q), or Joseph form.
enum class CovarianceUpdate { kPrinted, kJoseph };

/// One calibrated matrix M of one sensor at one platform position (paper section 4):
/// y = M^-1 x + b, so M replaces R (and M^-1 replaces R^T) in eqs. (1), (2) and (5).
struct CalibratedPosition {
  double plat_deg = 0.0;                                        // deg, the platform angle
  Eigen::Matrix3d M_body_from_sensor = Eigen::Matrix3d::Identity();  // includes scale, misalignment
};

/// Calibrated matrices per sensor. An empty list means "use Rot(hinge axis, angle)".
struct Calibration {
  std::vector<CalibratedPosition> sensor1;
  std::vector<CalibratedPosition> sensor2;
  double match_tolerance_deg = 10.0;  // deg, a platform angle this close uses that position's M
  /// g-sensitivity per sensor, deg/s per g of specific force (sensor axes): push() subtracts
  /// G f / g from the gyros of samples whose accel columns are finite. Zero = none.
  std::array<Eigen::Matrix3d, 2> G_dps_per_g{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  /// bias temperature coefficients per sensor (deg/s per degC, sensor axes) and their 1-sigma,
  /// e.g. from a self-calibration's calib.yaml: the temperature states (when on) start here
  /// instead of at 0 with the data-sheet prior temp_coef_sigma_dps_per_degc
  bool has_temp_coef = false;
  std::array<Eigen::Vector3d, 2> temp_coef_dps_per_degc{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  std::array<Eigen::Vector3d, 2> temp_coef_sigma_dps_per_degc{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  /// the 1-sigma of each G element (deg/s per g), when the file gives it. With self-calibration's
  /// g-sensitivity states on, G and G_sigma are their prior (start value and P0), not a fixed
  /// correction (docs/estimator.md section 1e)
  bool has_g_sigma = false;
  std::array<Eigen::Matrix3d, 2> G_sigma_dps_per_g{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  /// scale-factor and misalignment error per sensor (fraction, sensor axes: y_i = (I + E_i) w_i + ...)
  /// and the 1-sigma of each element, e.g. from a self-calibration's calib.yaml. With the scale
  /// states on they are their prior; else push() removes them, y <- (I + E_i)^-1 y
  bool has_scale_misalign = false;
  std::array<Eigen::Matrix3d, 2> E_frac{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  std::array<Eigen::Matrix3d, 2> E_sigma_frac{Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  /// end-stop angle errors (deg, actual - read rest angle about the hinge; [platform 1 at -, at +,
  /// platform 2 at -, at +] like kStopAngle) and their 1-sigma, from a self-calibration's calib.yaml:
  /// the end-stop states (when on) start here instead of at 0 +- flip_angle_sigma_deg; without them
  /// each sensor's M turns to the stop's angle, Rot(a, plat + d)
  bool has_end_stops = false;
  Eigen::Vector4d end_stop_deg = Eigen::Vector4d::Zero();
  Eigen::Vector4d end_stop_sigma_deg = Eigen::Vector4d::Zero();
  bool empty() const { return sensor1.empty() && sensor2.empty(); }
  bool has_g_sensitivity() const { return !G_dps_per_g[0].isZero(0.0) || !G_dps_per_g[1].isZero(0.0); }
  /// Throws std::invalid_argument when a matrix is singular or not finite.
  void validate() const;
};

/// Filter configuration: plain values with units; defaults are MPU6050-like (paper section 4).
struct EstimatorConfig {
  FilterMode mode = FilterMode::kGeneral;
  CovarianceUpdate covariance_update = CovarianceUpdate::kJoseph;  // paper mode: kPrinted
  bool per_sample_updates = false;  // general mode: update on every standstill sample

  // standstill detection
  StandstillSource standstill = StandstillSource::kPlatformColumns;
  double settle_s = 0.5;               // s, samples skipped after the platforms come to rest
  double min_standstill_s = 1.0;       // s, shorter standstills are discarded
  double max_standstill_s = 0.0;       // s, split longer standstills into updates (0 = never)
  double end_margin_s = 0.1;           // s, samples dropped before motion is seen (its onset
                                       // hides below angle_tolerance_deg for a sample or two)
  double angle_tolerance_deg = 0.001;  // deg, platform angle change between samples = motion
  double gyro_motion_threshold_dps = 5.0;  // deg/s, | |y1| - |y2| | above this = a flip
  double standstill_period_s = 10.0;   // s, kSchedule: length of one standstill
  double initial_plat1_deg = 90.0;     // deg, kGyroSignal / kSchedule start positions
  double initial_plat2_deg = 90.0;     // deg

  // tuning. R: per-axis white noise of one sample = noise_density^2 * sample rate
  double noise_density_dps_rthz = 0.005;   // deg/s/sqrt(Hz), MPU6050 data sheet (paper sec. 4)
  bool noise_from_log = false;             // set by --tune auto (apply_tune): the density was measured
  // Q: the bias wanders like a random walk that reaches the bias-instability level B at tau_B:
  // K = 0.664 B sqrt(3 / tau_B), Q = K^2 dt per axis. The default B is the MPU6050's wander as the
  // twin's preset draws it (a Gauss-Markov of 0.1 deg/s over 3 h, driven at 2 sigma^2 / tau =
  // 1.85e-6 (deg/s)^2/s): K^2 = 1.85e-6 at tau_B = 100 s. With the windowed update (docs/estimator.md
  // section 1h) it puts NIS and NEES at 1 on Fig. 4, Fig. 9 and the demo (docs/results.md, the q decision)
  double bias_instability_dps = 0.01183;   // deg/s (42.6 deg/h)
  double bias_instability_tau_s = 100.0;   // s, where the Allan minimum lies (paper: ~100 s)
  double q_override_dps2_per_s = 0.0;      // (deg/s)^2/s, > 0 replaces the spec-derived Q rate
  double r_override_dps2 = 0.0;            // (deg/s)^2 per sample and axis, > 0 replaces R
  // the bias moves with the chip's temperature (temp1, temp2 columns): b_i += k_i dT_i, with
  // k_i three states per sensor (deg/s per degC) of this prior sigma; 0 = no temperature states.
  // MPU6050: ZRO variation +-20 deg/s over -40..85 degC taken as 3 sigma
  double temp_coef_sigma_dps_per_degc = 20.0 / 125.0 / 3.0;
  double initial_bias_dps = 0.0;           // deg/s, every component of x0
  double initial_sigma_dps = 20.0;         // deg/s, sqrt of P0's diagonal (MPU6050 turn-on +-20)
  double variance_floor_dps2 = 1e-14;      // (deg/s)^2, P's diagonal never drops below this
  double nis_gate_probability = 0.9999;    // chi-square probability of the NIS gate (1 = off)
  /// after this many consecutive gate rejections the filter re-locks: P is widened by the
  /// innovation and the update is taken (a real bias jump or a switch to other hardware,
  /// not an outlier). 0 = never re-lock.
  int gate_relock_after = 3;

  // self-calibrating mode (docs/estimator.md section 1b): each sensor's g-sensitivity G_i becomes
  // 9 states driven by the log's accel columns, prior sigma per element (MPU6050: 0.1 deg/s/g as
  // the rms row norm). General mode only.
  bool self_calibration = false;
  double gsens_sigma_dps_per_g = 0.1 / 1.7320508075688772;
  // ... and each sensor's scale-factor and misalignment error E_i (9 states, y_i = (I + E_i) w_i),
  // driven by the fused body rate over each standstill; prior sigma per element (fraction):
  // mpu6050::kScaleMisalignSigmaFrac. 0 = off (E_i stays 0).
  double scale_misalign_sigma_frac = mpu6050::kScaleMisalignSigmaFrac;
  // a box known to stand still on the Earth (a lab test like the paper's Fig. 4/5 runs): each
  // standstill also measures the fused rate about "up" (from the accel columns, else ref_q) as the
  // vertical Earth rate, Omega sin(latitude); that observes the bias common to both sensors about
  // the vertical, which eq. (2) cannot see once g-sensitivity is a state. General mode only.
  // self-calibrating mode on a log without accel columns but with ref_q: the pipeline drives the G
  // states with gravity from ref_q (f_i = M_i^T C^T (0, 0, g); gravity_from_ref_q, set by the pass,
  // not a key). The box's own acceleration a is then unknown: R takes G a with a of sigma
  // sqrt(ref_gravity_accel_sigma^2 + (ref_gravity_speed |w| / g)^2) per axis, w the standstill's
  // fused box rate (a turn at speed v has a centripetal v w; docs/estimator.md section 1b)
  bool gravity_from_ref_q = false;
  double ref_gravity_accel_sigma_g = 0.05;  // g, the box's mean acceleration over a standstill (1 sigma)
  double ref_gravity_speed_mps = 30.0;      // m/s, the fastest the box travels (a car on a highway)
  bool box_at_rest = false;
  double box_rest_rate_sigma_dps = 1e-4;  // deg/s, how still the box is about the vertical (1 sigma)
  // self-calibrating mode, a box that moves but pauses now and then (a pan/tilt unit's dwells, a
  // vehicle at a stop, a static box between flips; not with box_at_rest, which does it already): once
  // the correction is known to a tenth of box_dwell_rate, every stretch where both platforms rest,
  // the corrected fused rate stays below box_dwell_rate and the specific force is 1 g (within
  // 5 %) is a box dwell; at least box_dwell_min long after box_dwell_margin is dropped at each end,
  // it measures the vertical rate as Omega sin(latitude) (the same row as box_at_rest, variance
  // with box_rest_rate_sigma). It observes the g-sensitivity both sensors share, which eq. (2)
  // cannot see on a moving box (docs/estimator.md section 1d). Needs the accel columns.
  bool box_dwell_updates = true;
  double box_dwell_rate_dps = 2.0;   // deg/s, |corrected fused rate| below this: the box rests
  double box_dwell_min_s = 1.0;      // s, shortest dwell used (after the margins)
  double box_dwell_margin_s = 0.2;   // s, dropped at the start and the end of each dwell
  // self-calibrating mode with scale/misalignment states: each flip of one platform while the
  // other rests is a measurement too: the moving sensor's readings integrated over the flip carry
  // E times the flip angle (docs/estimator.md section 1f). The rest angles before and after are
  // the flip angle; flip_angle_sigma is each reading's 1 sigma (end-stop errors: the twin's
  // default box has up to 0.05 deg). A window is dropped when it lasts longer than flip_max.
  bool flip_updates = true;
  double flip_angle_sigma_deg = 0.05;  // deg, 1 sigma of each rest-angle reading
  double flip_max_s = 5.0;             // s, longest flip used (settle_s is added after it)

  Calibration calibration;  // optional calibrated matrices (issue 4); empty = rotations

  /// Throws std::invalid_argument naming the field on a bad value.
  void validate() const;
  /// Q rate per axis, (deg/s)^2/s, from the spec (or the override).
  double q_dps2_per_s() const;
  /// White-noise variance of one sample per axis, (deg/s)^2, at `sample_rate_hz`.
  double sample_variance_dps2(double sample_rate_hz) const;
};

/// Paper-mode defaults: printed recursion, platform columns.
EstimatorConfig paper_config();

/// Reads a `key: value` configuration (a flat YAML subset: '#' comments, blank lines) on top of
/// `base`. Keys are the EstimatorConfig field names; enums as text (mode: paper|general, ...).
/// Keys may use another unit of the field's quantity (`bias_instability_dph: 36`). Throws
/// driftless::InputError naming `name`, the line and the key on a bad line or a key given twice.
EstimatorConfig parse_estimator_config(std::istream& in, const std::string& name,
                                       EstimatorConfig base = {});
/// The same, applied to one key (for the CLI and YAML front ends).
void set_config_value(EstimatorConfig& cfg, const std::string& key, const std::string& value);
/// Writes every field as `key: value` lines (parse_estimator_config reads it back).
void write_estimator_config(std::ostream& out, const EstimatorConfig& cfg);

}  // namespace driftless::est
