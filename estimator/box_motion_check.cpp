#include "estimator/box_motion_check.hpp"

#include <algorithm>
#include <cmath>

#include "estimator/geometry.hpp"

namespace driftless::est {
namespace {

// the larger of `a` and `b`, NaN counting as nothing
double larger(double a, double b) { return std::isnan(a) || b > a ? b : a; }

}  // namespace

bool box_turned(const BoxMotion& m, const BoxMotionLimits& lim) {
  return m.ref_rate_dps > lim.ref_rate_dps || m.gyro_change_dps > lim.gyro_change_dps;
}

void BoxMotionCheck::push(const Sample& s, const SampleOutput& out) {
  const bool resting = out.at_rest && out.sensors_fused == 2 && std::isfinite(s.t_s) &&
                       out.rate_body_raw_dps.allFinite();
  if (open_ && (!resting || out.plat1_deg != plat1_deg_ || out.plat2_deg != plat2_deg_)) close();
  if (!resting) return;
  if (!open_) {
    open_ = true;
    plat1_deg_ = out.plat1_deg;
    plat2_deg_ = out.plat2_deg;
    t0_s_ = mean_t0_s_ = s.t_s;
    first_mean_dps_.setConstant(kNaN);
    sum_dps_.setZero();
    n_ = 0;
    change_dps_ = 0.0;
    ref0_.setConstant(kNaN);
    ref_last_.setConstant(kNaN);
  }
  t_last_s_ = s.t_s;
  if (s.ref_q_wxyz.allFinite()) {
    if (!ref0_.allFinite()) {
      ref0_ = s.ref_q_wxyz;
      ref0_t_s_ = s.t_s;
    }
    ref_last_ = s.ref_q_wxyz;
    ref_last_t_s_ = s.t_s;
  }
  sum_dps_ += out.rate_body_raw_dps;
  ++n_;
  if (s.t_s - mean_t0_s_ < lim_.mean_s) return;
  const Eigen::Vector3d mean = sum_dps_ / double(n_);
  if (!first_mean_dps_.allFinite()) {
    first_mean_dps_ = mean;
  } else {
    const double change = (mean - first_mean_dps_).norm();
    change_dps_ = std::max(change_dps_, change);
    if (larger(m_.gyro_change_dps, change) != m_.gyro_change_dps) m_.gyro_change_t_s = s.t_s;
    m_.gyro_change_dps = larger(m_.gyro_change_dps, change);
  }
  sum_dps_.setZero();
  n_ = 0;
  mean_t0_s_ = s.t_s;
}

// the standstill ends: ref_q's turn over it (its conjugate, q_body_from_enu, gives the same angle)
void BoxMotionCheck::close() {
  open_ = false;
  ++m_.standstills;
  const double span_s = ref_last_t_s_ - ref0_t_s_;
  if (!ref0_.allFinite() || !ref_last_.allFinite() || !(span_s >= lim_.min_span_s)) return;
  const Eigen::Quaterniond q0 = Eigen::Quaterniond(ref0_[0], ref0_[1], ref0_[2], ref0_[3]).normalized();
  const Eigen::Quaterniond q1 = Eigen::Quaterniond(ref_last_[0], ref_last_[1], ref_last_[2], ref_last_[3]).normalized();
  const double rate_dps = geo::rotvec_rad(q0.conjugate() * q1).norm() * kDegPerRad / span_s;
  if (larger(m_.ref_rate_dps, rate_dps) != m_.ref_rate_dps) m_.ref_rate_t_s = ref_last_t_s_;
  m_.ref_rate_dps = larger(m_.ref_rate_dps, rate_dps);
  if (rate_dps <= lim_.ref_rate_dps && change_dps_ < lim_.gyro_change_dps) ++m_.still_standstills;
  if (change_dps_ < lim_.gyro_change_dps && rate_dps < lim_.dwell_rate_dps) {
    if (larger(m_.quiet_ref_rate_dps, rate_dps) != m_.quiet_ref_rate_dps) m_.quiet_ref_rate_t_s = ref_last_t_s_;
    m_.quiet_ref_rate_dps = larger(m_.quiet_ref_rate_dps, rate_dps);
  }
}

BoxMotion BoxMotionCheck::finish() {
  if (open_) close();
  return m_;
}

}  // namespace driftless::est
