#include "estimator/lag_check.hpp"

#include <algorithm>
#include <cmath>

namespace driftless::est {

LagCheck::LagCheck(double rate_hz, const LagCheckLimits& limits) : limits_(limits) {
  const double rate = std::isfinite(rate_hz) && rate_hz > 0.0 ? rate_hz : 100.0;
  half_ = std::max(1, static_cast<int>(std::lround(limits_.diff_half_s * rate)));
  margin_ = std::max(0, static_cast<int>(std::lround(limits_.end_margin_s * rate)));
  span_s_ = 2.0 * half_ / rate;
  ring_.resize(static_cast<std::size_t>(2 * half_ + 1 + margin_));
}

void LagCheck::push(const Sample& s, const DriftlessFilter& f) {
  const SampleOutput& o = f.output();
  // samples the filter adds to a standstill (settled, both platforms resting at known angles)
  const bool rest = o.status == PushStatus::kAccumulating && o.sensors_fused == 2;
  if (!rest || o.plat1_deg != p1_deg_ || o.plat2_deg != p2_deg_) close_segment();
  if (!rest || !o.rate_body_dps.allFinite()) return;
  p1_deg_ = o.plat1_deg;
  p2_deg_ = o.plat2_deg;
  // eq. (2) with the corrected rates: bias (and, self-calibrating, G f and E) removed
  const Eigen::Vector3d r =
      f.body_from_sensor(1, o.plat1_deg) * o.y1c_dps - f.body_from_sensor(2, o.plat2_deg) * o.y2c_dps;
  ring_[head_] = {s.t_s, o.rate_body_dps, r};
  head_ = (head_ + 1) % ring_.size();
  if (count_ < ring_.size()) ++count_;
  if (count_ < ring_.size()) return;
  // the oldest 2 half + 1 samples: dw/dt at their centre by the central difference; the newest
  // margin samples wait (the motion that ends the standstill may already be in them)
  const Entry& lo = ring_[head_];
  const Entry& c = ring_[(head_ + static_cast<std::size_t>(half_)) % ring_.size()];
  const Entry& hi = ring_[(head_ + static_cast<std::size_t>(2 * half_)) % ring_.size()];
  if (!(hi.t_s > lo.t_s)) return;
  const Eigen::Vector3d a = (hi.w_dps - lo.w_dps) / (hi.t_s - lo.t_s);
  ++seg_.n;
  seg_.a += a;
  seg_.r += c.r_dps;
  seg_.aa += a.squaredNorm();
  seg_.ar += a.dot(c.r_dps);
  seg_.rr += c.r_dps.squaredNorm();
}

// the standstill ends: its sums, centred (its bias and mean rate drop out), join the totals
void LagCheck::close_segment() {
  if (count_ == 0 && seg_.n == 0) return;
  if (seg_.n >= limits_.min_segment) {
    const double n = double(seg_.n);
    S_aa_ += seg_.aa - seg_.a.squaredNorm() / n;
    S_ar_ += seg_.ar - seg_.a.dot(seg_.r) / n;
    S_rr_ += seg_.rr - seg_.r.squaredNorm() / n;
    dof_ += 3.0 * (n - 1.0);
    mean_a2_ += (seg_.a / n).squaredNorm();
    inv_n_ += 1.0 / n;
    samples_ += seg_.n;
  }
  seg_ = Sums{};
  count_ = 0;
  head_ = 0;
  p1_deg_ = p2_deg_ = kNaN;
}

LagCheckResult LagCheck::finish() {
  close_segment();
  LagCheckResult out;
  out.samples = samples_;
  if (!(S_aa_ > 0.0) || !(dof_ > 1.0)) return out;
  // errors in variables: dw/dt is the central difference of the fused rate, the mean of the two
  // sensors, whose white noise is a quarter of r's per axis (var_r / 4); over the span T its noise
  // is var_r / (2 T^2) per axis and sample. It inflates S_aa and shrinks D toward 0 (a BMI088
  // at 200 Hz on a car read a 15 ms lag as 3 ms). S_aa's noise part is taken out, var_r from the
  // fit it gives (twice: the first var_r is the plain fit's).
  double D = S_ar_ / S_aa_, var_r = std::max(S_rr_ - D * S_ar_, 0.0) / (dof_ - 1.0), S_signal = S_aa_;
  double var_a = 0.0;
  for (int pass = 0; pass < 2; ++pass) {
    var_a = var_r / (2.0 * span_s_ * span_s_);
    S_signal = S_aa_ - dof_ * var_a;
    if (!(S_signal > limits_.min_signal_share * S_aa_)) break;
    D = S_ar_ / S_signal;
    var_r = std::max(S_rr_ - D * S_ar_, 0.0) / (dof_ - 1.0);
  }
  out.signal_share = std::max(S_signal, 0.0) / S_aa_;
  out.residual_var_dps2 = var_r;
  if (!(out.signal_share > limits_.min_signal_share)) return out;  // a still box: nothing to fit
  out.lag_s = D;
  out.lag_sigma_s = std::sqrt((var_r + D * D * var_a) * S_aa_) / S_signal;
  const double white = 3.0 * out.residual_var_dps2 * inv_n_;
  out.update_excess = white > 0.0 ? out.lag_s * out.lag_s * mean_a2_ / white : kNaN;
  out.significant = std::fabs(out.lag_s) > limits_.z_min * out.lag_sigma_s && out.update_excess > limits_.excess_min;
  return out;
}

}  // namespace driftless::est
