#include "estimator/reference_check.hpp"

#include <algorithm>
#include <cmath>

#include "estimator/geometry.hpp"

namespace driftless::est {

const char* to_string(RefConvention c) {
  switch (c) {
    case RefConvention::kEnuFromBodyWxyz: return "q_enu_from_body, scalar first";
    case RefConvention::kBodyFromEnuWxyz: return "q_body_from_enu, scalar first";
    case RefConvention::kEnuFromBodyXyzw: return "q_enu_from_body, scalar last";
    case RefConvention::kBodyFromEnuXyzw: return "q_body_from_enu, scalar last";
  }
  return "?";
}

Eigen::Quaterniond ref_q_as(const Eigen::Vector4d& wxyz, RefConvention c) {
  const bool scalar_last = c == RefConvention::kEnuFromBodyXyzw || c == RefConvention::kBodyFromEnuXyzw;
  // scalar last: the columns ref_qw..ref_qz hold x, y, z, w
  Eigen::Quaterniond q = scalar_last ? Eigen::Quaterniond(wxyz[3], wxyz[0], wxyz[1], wxyz[2])
                                     : Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
  q.normalize();
  const bool body_from_enu = c == RefConvention::kBodyFromEnuWxyz || c == RefConvention::kBodyFromEnuXyzw;
  return body_from_enu ? q.conjugate() : q;
}

void ReferenceCheck::restart(const Sample& s, const Eigen::Vector3d& rate_dps) {
  open_ = true;
  t0_s_ = t_last_s_ = s.t_s;
  ref0_wxyz_ = s.ref_q_wxyz;
  rate_last_dps_ = rate_dps;
  q_gyro_ = Eigen::Quaterniond::Identity();
}

void ReferenceCheck::push(const Sample& s, const DriftlessFilter& filter) {
  const Eigen::Vector3d& rate = filter.output().rate_body_dps;
  const bool window_due = open_ && s.t_s - t0_s_ >= lim_.window_s;  // sigma only when it is used
  const double sigma = !window_due           ? kNaN
                       : filter.has_update() ? filter.correction_sigma_dps().maxCoeff()
                                             : filter.sigma_dps().maxCoeff();
  push(s, rate, sigma);
}

void ReferenceCheck::push(const Sample& s, const Eigen::Vector3d& rate_body_dps, double bias_sigma_dps) {
  const bool usable = std::isfinite(s.t_s) && s.ref_q_wxyz.allFinite() && s.ref_q_wxyz.norm() > 0.5 &&
                      rate_body_dps.allFinite();
  if (!usable) {
    open_ = false;  // a gap in either: the window cannot span it
    return;
  }
  if (!open_ || !(s.t_s > t_last_s_)) {
    restart(s, rate_body_dps);
    return;
  }
  // trapezoid in the body frame, as AttitudeIntegrator does (the Earth rate, <= 0.0042 deg/s, is
  // left in: far below the turns compared), with the step's quaternion to second order in its
  // half-angle h (angle error |phi|^3 / 48 per step: 3e-9 rad at 30 deg/s and 100 Hz, 3e-7 rad over a
  // 1 s window, against turns of degrees); no sine or cosine per sample
  const double dt_s = s.t_s - t_last_s_;
  const Eigen::Vector3d h = (0.25 * dt_s * kRadPerDeg) * (rate_last_dps_ + rate_body_dps);
  q_gyro_ = (q_gyro_ * Eigen::Quaterniond(1.0 - 0.5 * h.squaredNorm(), h.x(), h.y(), h.z())).normalized();
  t_last_s_ = s.t_s;
  rate_last_dps_ = rate_body_dps;
  if (s.t_s - t0_s_ >= lim_.window_s) {
    close_window(s, bias_sigma_dps);
    restart(s, rate_body_dps);
  }
}

// compares the gyro turn over the window with ref_q's in each convention, if the box turned
// clearly more than the bias sigma can account for
void ReferenceCheck::close_window(const Sample& s, double bias_sigma_dps) {
  const double span_s = s.t_s - t0_s_;
  const Eigen::Vector3d gyro_rad = geo::rotvec_rad(q_gyro_);
  const auto ref_turn_rad = [&](RefConvention c) {
    return geo::rotvec_rad(ref_q_as(ref0_wxyz_, c).conjugate() * ref_q_as(s.ref_q_wxyz, c));
  };
  const Eigen::Vector3d given_rad = ref_turn_rad(RefConvention::kEnuFromBodyWxyz);
  const double sigma = std::isfinite(bias_sigma_dps) ? bias_sigma_dps : 1e9;
  const double min_turn_deg = std::max(lim_.min_turn_deg, lim_.sigma_factor * sigma * span_s);
  const double turn_deg = std::max(gyro_rad.norm(), given_rad.norm()) * kDegPerRad;
  if (!(turn_deg > min_turn_deg)) return;
  ++windows_;
  den_ += std::max(gyro_rad.squaredNorm(), given_rad.squaredNorm());
  for (int c = 0; c < kRefConventions; ++c) {
    num_[static_cast<std::size_t>(c)] += (gyro_rad - ref_turn_rad(static_cast<RefConvention>(c))).squaredNorm();
  }
  if (turn_deg > example_turn_deg_) {
    example_turn_deg_ = turn_deg;
    example_.example_t_s = s.t_s;
    example_.example_span_s = span_s;
    example_.example_gyro_deg = gyro_rad * kDegPerRad;
    example_.example_ref_deg = given_rad * kDegPerRad;
  }
}

ReferenceFit ReferenceCheck::finish() const {
  ReferenceFit f = example_;
  f.windows = windows_;
  if (windows_ == 0 || !(den_ > 0.0)) return f;
  for (std::size_t c = 0; c < num_.size(); ++c) f.misfit[c] = num_[c] / den_;
  std::size_t best = 0;
  for (std::size_t c = 1; c < num_.size(); ++c) {
    if (f.misfit[c] < f.misfit[best]) best = c;
  }
  f.best = static_cast<RefConvention>(best);
  if (windows_ < lim_.min_windows) return f;
  if (f.misfit[0] <= lim_.fit_max) f.verdict = RefFitVerdict::kFits;
  else if (f.misfit[best] <= lim_.fit_max) f.verdict = RefFitVerdict::kOtherConvention;
  else f.verdict = RefFitVerdict::kNoFit;
  return f;
}

}  // namespace driftless::est
