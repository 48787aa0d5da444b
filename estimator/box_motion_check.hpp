// Did the box turn while both platforms rested? (docs/estimator.md section 1d) `--box-at-rest`
// and the self-calibration's box dwells claim that the box then turns at the Earth rate only; on a
// car, a ship or a slow turntable that claim is wrong and its error goes into the biases or the
// g-sensitivity. Two witnesses, each free of the gyro bias: ref_q's own turn over a standstill
// (its rate, deg/s; catches a steady slow turn), and the change of the fused uncorrected rate
// within one standstill (the bias is constant there: a change of 1 deg/s is motion). Eigen + std.
#pragma once

#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "estimator/filter.hpp"
#include "estimator/sample.hpp"

namespace driftless::est {

/// What the check saw: the largest evidence of each kind, with when.
struct BoxMotion {
  // deg/s: the largest turn rate of ref_q over one standstill of at least min_span_s (NaN: no ref_q)
  double ref_rate_dps = kNaN;
  double ref_rate_t_s = kNaN;  // s, the end of that standstill
  // deg/s: the same over the quiet standstills only (fused rate changing less than gyro_change_dps,
  // ref_q slower than dwell_rate_dps): the slow steady turn a box dwell would take for a pause
  double quiet_ref_rate_dps = kNaN;
  double quiet_ref_rate_t_s = kNaN;
  // deg/s: the largest change of the 1 s mean fused uncorrected rate within one standstill
  double gyro_change_dps = kNaN;
  double gyro_change_t_s = kNaN;
  std::uint64_t standstills = 0;  // standstills of both platforms checked
  // standstills in which ref_q (over at least min_span_s) turned slower than ref_rate_dps and the
  // fused rate changed less than gyro_change_dps: pauses, in which a box dwell observes the vertical
  std::uint64_t still_standstills = 0;
};

struct BoxMotionLimits {
  double min_span_s = 2.0;           // s, shorter standstills are not judged by ref_q
  double ref_rate_dps = 0.01;        // deg/s: ref_q turning faster over a standstill is motion
  double gyro_change_dps = 1.0;      // deg/s: the fused rate changing more within one is motion
  double mean_s = 1.0;               // s, the span of the means compared
  double dwell_rate_dps = 2.0;       // deg/s, box_dwell_rate_dps: faster turns are never dwells
};

/// True when `m` shows the box turning while the platforms rested (by the limits `lim`).
bool box_turned(const BoxMotion& m, const BoxMotionLimits& lim = {});

/// Streams the samples of a pass (after the filter has seen each one).
class BoxMotionCheck {
 public:
  explicit BoxMotionCheck(const BoxMotionLimits& lim = {}) : lim_(lim) {}
  void push(const Sample& s, const SampleOutput& out);
  BoxMotion finish();

 private:
  void close();

  BoxMotionLimits lim_;
  BoxMotion m_;
  bool open_ = false;
  double plat1_deg_ = kNaN, plat2_deg_ = kNaN;
  double t0_s_ = kNaN, t_last_s_ = kNaN;
  Eigen::Vector4d ref0_ = Eigen::Vector4d::Constant(kNaN), ref_last_ = Eigen::Vector4d::Constant(kNaN);
  double ref0_t_s_ = kNaN, ref_last_t_s_ = kNaN;
  // the 1 s means of the fused uncorrected rate: the first of the standstill and the running one
  Eigen::Vector3d first_mean_dps_ = Eigen::Vector3d::Constant(kNaN);
  Eigen::Vector3d sum_dps_ = Eigen::Vector3d::Zero();
  std::uint64_t n_ = 0;
  double mean_t0_s_ = kNaN;
  double change_dps_ = 0.0;  // the largest change of the means within this standstill
};

}  // namespace driftless::est
