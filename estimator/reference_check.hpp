// Does the log's reference attitude (ref_q) turn with the gyros? (docs/estimator.md section 4.1)
// The attitude comparison takes ref_q as q_enu_from_body, scalar first; a logger that writes
// q_body_from_enu (the other half of the world's convention) or x, y, z, w (ROS, Eigen) gives
// attitude errors of 100-180 deg that would read as a drift of thousands of deg/h. Over windows
// in which the fused gyro rate turns the box clearly more than its bias sigma can explain, the
// box-axis rotation the gyros integrate is compared with the rotation between ref_q at the
// window's ends, read in each of four conventions: the one the data fit is named, and the
// attitude figures are withheld when the log's own convention does not fit. Eigen + std only.
#pragma once

#include <array>
#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "estimator/filter.hpp"
#include "estimator/sample.hpp"

namespace driftless::est {

/// How the four ref_q columns (ref_qw, ref_qx, ref_qy, ref_qz) may have been written.
enum class RefConvention {
  kEnuFromBodyWxyz,  // the log format's: q_enu_from_body, scalar first
  kBodyFromEnuWxyz,  // the conjugate: q_body_from_enu, scalar first
  kEnuFromBodyXyzw,  // q_enu_from_body with the scalar last (columns hold x, y, z, w)
  kBodyFromEnuXyzw,  // q_body_from_enu with the scalar last
};
inline constexpr int kRefConventions = 4;
const char* to_string(RefConvention c);

/// The quaternion q_enu_from_body that the columns `wxyz` (as read, log order) hold if they were
/// written in convention `c`.
Eigen::Quaterniond ref_q_as(const Eigen::Vector4d& wxyz, RefConvention c);

/// The outcome of the check.
enum class RefFitVerdict {
  kNotChecked,       // too few turning windows (a box that never turned): nothing to compare
  kFits,             // the log's convention fits the gyros
  kOtherConvention,  // another convention fits: the columns were written in it
  kNoFit,            // no convention fits: another body's attitude, or gyros in other units
};

struct ReferenceFit {
  RefFitVerdict verdict = RefFitVerdict::kNotChecked;
  std::uint64_t windows = 0;  // turning windows compared
  // per convention: sum |theta_gyro - theta_ref|^2 / sum |theta_gyro|^2 over those windows (0 is
  // a perfect fit; a reference that turns the other way gives 4)
  std::array<double, kRefConventions> misfit{};
  RefConvention best = RefConvention::kEnuFromBodyWxyz;  // the smallest misfit
  // the window where the gyros turned most: its end time (s), span (s), the gyro turn (deg, box
  // axes) and the log's ref_q turn over it as written (deg, box axes)
  double example_t_s = kNaN;
  double example_span_s = kNaN;
  Eigen::Vector3d example_gyro_deg = Eigen::Vector3d::Constant(kNaN);
  Eigen::Vector3d example_ref_deg = Eigen::Vector3d::Constant(kNaN);
};

/// Limits of the check.
struct ReferenceCheckLimits {
  double window_s = 1.0;         // s, the span of one comparison window
  double min_turn_deg = 2.0;     // a window counts when the gyros (or ref_q) turned more than
  double sigma_factor = 5.0;     // this and this many times (bias sigma x span): the bias error
                                 // then explains at most 1/sigma_factor^2 of the misfit
  std::uint64_t min_windows = 3; // fewer turning windows: not checked
  double fit_max = 0.1;          // a convention fits when its misfit is below this
};

/// Streams the samples of a pass (after the filter has seen each one).
class ReferenceCheck {
 public:
  explicit ReferenceCheck(const ReferenceCheckLimits& limits = {}) : lim_(limits) {}
  /// The sample `s` after `filter` has seen it: its fused inertial body rate (box axes), and at a
  /// window's end the largest sigma of its bias correction.
  void push(const Sample& s, const DriftlessFilter& filter);
  /// The same with the rate and that sigma (deg/s) given (the sigma is read at a window's end).
  void push(const Sample& s, const Eigen::Vector3d& rate_body_dps, double bias_sigma_dps);
  ReferenceFit finish() const;

 private:
  void restart(const Sample& s, const Eigen::Vector3d& rate_dps);
  void close_window(const Sample& s, double bias_sigma_dps);

  ReferenceCheckLimits lim_;
  bool open_ = false;
  double t0_s_ = kNaN, t_last_s_ = kNaN;
  Eigen::Vector4d ref0_wxyz_ = Eigen::Vector4d::Constant(kNaN);
  Eigen::Vector3d rate_last_dps_ = Eigen::Vector3d::Constant(kNaN);
  Eigen::Quaterniond q_gyro_ = Eigen::Quaterniond::Identity();  // box rotation since t0_s_
  std::uint64_t windows_ = 0;
  double den_ = 0.0;
  std::array<double, kRefConventions> num_{};
  double example_turn_deg_ = -1.0;
  ReferenceFit example_;
};

}  // namespace driftless::est
