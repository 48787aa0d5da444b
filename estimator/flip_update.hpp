// Flip updates of the self-calibrating mode (docs/estimator.md section 1f): while one platform
// flips and the other rests, the moving sensor's readings integrated over the flip carry its
// scale-factor and misalignment error times the flip angle, E_m a Δθ (180° in about a second: a
// large, known rotation), where a standstill's mean rate carries E times a few deg/s at most.
// FlipWindow cuts the flips out of the sample stream; flip_rows() turns one into a 3-dim
// measurement of the filter's state. Eigen + std only.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "estimator/sample.hpp"
#include "estimator/standstill.hpp"

namespace driftless::est {

/// d(M A v)/d vec(A) for a row-major vec(A) (3x3 A): column 3 r + c is M.col(r) v_c. The
/// regressor of a sensor-error matrix (g-sensitivity G f, scale/misalignment E w) seen through M.
inline Eigen::Matrix<double, 3, 9> matrix_error_jacobian(const Eigen::Matrix3d& M, const Eigen::Vector3d& v) {
  Eigen::Matrix<double, 3, 9> J;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) J.col(3 * r + c) = M.col(r) * v[c];
  return J;
}

/// One sample inside a flip window (the readings the measurement needs).
struct FlipSample {
  double dt_s;                            // s, since the previous sample
  Eigen::Vector3d gyro1_dps, gyro2_dps;   // sensor axes
  Eigen::Vector3d accel1_mps2, accel2_mps2;  // sensor axes (NaN when the log has none)
};

/// Cuts flips out of the stream: a window opens at the last sample where both platforms rest
/// and closes `settle_s` after the moving platform rests again at another angle, the other
/// platform resting at one angle throughout. Allocates once (at construction).
class FlipWindow {
 public:
  enum class Event { kNone, kClosed, kAborted };
  /// `max_s`: longest window kept (s); `rate_hz`: the sample rate (sizes the buffer).
  FlipWindow(double settle_s, double max_s, double rate_hz);
  /// Takes one sample with finite time and gyros (`dt_s` since the previous one, NaN for the
  /// first) and the standstill detector's view of it. kClosed: a flip is ready (read it before
  /// the next push()); kAborted: a window was dropped (both moved, a gap, too long).
  Event push(const Sample& s, double dt_s, const StandstillStep& st);
  /// The stream restarts (source switch): a window in progress is dropped.
  void reset();

  int moving() const { return moving_; }  // 1 or 2: the platform that flipped
  double start_deg() const { return start_deg_; }  // deg, its angle before and after
  double end_deg() const { return end_deg_; }
  double rest_deg() const { return rest_deg_; }    // deg, the other platform's angle
  double t_start_s() const { return t_start_s_; }  // s, the last resting sample before the flip
  double t_end_s() const { return t_end_s_; }      // s, the last sample in the window
  const std::vector<FlipSample>& samples() const { return buf_; }

 private:
  void remember_rest(const Sample& s, const StandstillStep& st);
  Event abort();

  double settle_s_, max_s_;
  std::size_t capacity_;
  std::vector<FlipSample> buf_;
  bool have_rest_ = false, open_ = false;
  double rest_t_s_ = kNaN, rest_p1_deg_ = kNaN, rest_p2_deg_ = kNaN;
  int moving_ = 0;
  double start_deg_ = kNaN, end_deg_ = kNaN, rest_deg_ = kNaN;
  double t_start_s_ = kNaN, t_end_s_ = kNaN, t_back_s_ = kNaN;
};

/// The sensor errors of one sensor at the current estimate (deg/s, deg/s per g, fraction).
struct SensorErrors {
  Eigen::Vector3d b_dps = Eigen::Vector3d::Zero();
  Eigen::Matrix3d G_dps_per_g = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d E_frac = Eigen::Matrix3d::Zero();
};

/// What flip_rows() needs besides the window.
struct FlipModel {
  Eigen::Matrix3d M_moving_start;  // body from moving sensor at its start angle
  Eigen::Matrix3d M_rest;          // body from the resting sensor
  Eigen::Vector3d hinge_box;       // the moving platform's hinge axis, box axes (unit)
  Eigen::Vector3d hinge_rest_box = Eigen::Vector3d::UnitX();  // the resting platform's, box axes
  SensorErrors moving, rest;       // the estimate (the profile and the E regressor use it)
  bool use_g = false;              // g-sensitivity states: their columns need the accel columns
  // (deg/s per g)^2: the uncertainty of each g-sensitivity element (its sigma^2 plus its estimate^2).
  // A window without accel samples is used without the G columns; G f, |f| <= 1 g, then enters R
  double g_var_dps2_per_g2 = 0.0;
  double sample_var_dps2 = 0.0;    // white-noise variance of one sample, per axis, (deg/s)^2
  double angle_sigma_deg = 0.0;    // 1 sigma of each rest-angle reading, deg
};

/// The measurement of one flip, in the moving sensor's axes at its start angle:
///   z = sum (y_m - C_k y_s) dt - Δθ a_m
///     = T b_m - S_b b_s + G_m F_m - sum C_k G_s f_s dt + E_m W_m - sum C_k E_s w_s dt + noise
/// with C_k = Rot(a_m, δ_k)^T M_m0^T M_s (rest sensor to moving sensor), δ_k the flip profile
/// (from the gyros, scaled to Δθ), W_m = Δθ a_m + sum C_k w_s dt (docs/estimator.md 1f).
struct FlipRows {
  bool valid = false;
  Eigen::Vector3d z_deg = Eigen::Vector3d::Zero();
  Eigen::Matrix3d H_b_moving = Eigen::Matrix3d::Zero(), H_b_rest = Eigen::Matrix3d::Zero();
  Eigen::Matrix<double, 3, 9> H_G_moving = Eigen::Matrix<double, 3, 9>::Zero();
  Eigen::Matrix<double, 3, 9> H_G_rest = Eigen::Matrix<double, 3, 9>::Zero();
  Eigen::Matrix<double, 3, 9> H_E_moving = Eigen::Matrix<double, 3, 9>::Zero();
  Eigen::Matrix<double, 3, 9> H_E_rest = Eigen::Matrix<double, 3, 9>::Zero();
  // end-stop angle errors (deg per deg): the moving platform's stop at the end and at the start
  // (the flip is d_end - d_start larger than read; the start frame turned by d_start turns the
  // box rate seen meanwhile), and the resting platform's (its sensor's rate turned by it)
  Eigen::Vector3d H_stop_end = Eigen::Vector3d::Zero(), H_stop_start = Eigen::Vector3d::Zero();
  Eigen::Vector3d H_stop_rest = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_deg2 = Eigen::Matrix3d::Zero();
  double span_s = 0.0;  // s, the window's length T
  bool g_columns = false;  // H_G_* filled (use_g and every sample had accel); else G f is in R
};

/// Whether a gyro clipped inside the flip window: a channel whose largest |reading| in it comes in
/// runs of identical values (the test of estimator/clip_detector.hpp, applied to the window). Its
/// integrated turn then falls short of the flip, so the flip is no measurement of E.
bool flip_clipped(const FlipWindow& w);

/// The angle change dtheta_deg + k 360 nearest the gyros' turn turn_deg (deg): the angle columns
/// give the platform's position modulo 360, the gyros how far and which way it turned. A platform
/// that always turns +180 with its angle wrapped at +-180 reads -180 where it turned +180.
double nearest_turn_mod_360_deg(double dtheta_deg, double turn_deg);

/// Builds the flip measurement (Δθ: the angle columns' change modulo 360 nearest the gyros' turn);
/// invalid when the window is not a clean flip (the gyro-integrated turn more than 20 % off that
/// Δθ or of the other sign). With `use_g` and a sample
/// without accel the G columns are left out and G f's variance goes into R (g_columns false).
FlipRows flip_rows(const FlipWindow& w, const FlipModel& m);

}  // namespace driftless::est
