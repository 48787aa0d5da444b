// Is the residual of eq. (2) white noise, or does it follow the box's angular acceleration?
// (docs/estimator.md section 6.1, `signal_chain`). One sensor sampled later than the other (a
// sample delay, a slower low-pass filter) reads the box rate late: during a standstill on a
// moving box r = M1 y1 - M2 y2 = D dw/dt + bias + noise, D > 0 when sensor 2 is late. No noise
// density describes that (`--tune auto` would read a 15 ms lag as 25x the noise), so the check
// fits D over every standstill sample and says when it matters. Eigen + std only.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "estimator/filter.hpp"

namespace driftless::est {

/// What the check measured over the standstills of one pass.
struct LagCheckResult {
  std::uint64_t samples = 0;      // standstill samples in the fit
  double lag_s = kNaN;            // s, D: > 0 sensor 2 reads the box rate later than sensor 1;
                                  // NaN when the angular acceleration at rest is mostly the
                                  // sensors' own noise (a still box): not measurable
  double lag_sigma_s = kNaN;      // s, its 1 sigma (white residual, the regressor's noise included)
  double signal_share = kNaN;     // the share of sum |dw/dt|^2 that is motion, not noise
  double residual_var_dps2 = kNaN;  // (deg/s)^2 per axis and sample, what D leaves
  // what D puts into the standstill means against the white noise's share of their variance:
  // sum |D mean(dw/dt)|^2 / sum 3 var / n over the standstills (0.25: the innovations' variance
  // 25 % above what a white-noise R says)
  double update_excess = kNaN;
  bool significant = false;       // |D| > z_min sigma and update_excess > excess_min
};

/// Limits of the check.
struct LagCheckLimits {
  double z_min = 5.0;           // |D| / sigma above this ...
  double excess_min = 0.25;     // ... and update_excess above this: a finding
  double diff_half_s = 0.02;    // s, dw/dt by the central difference over +-this
  double end_margin_s = 0.25;   // s, dropped before each standstill's end (motion onset)
  std::uint64_t min_segment = 10;  // samples a standstill needs to enter the fit
  double min_signal_share = 0.1;   // below this share of motion in sum |dw/dt|^2: not measurable
};

/// Fed every sample after DriftlessFilter::push() (its output: corrected rates, rest, angles).
class LagCheck {
 public:
  explicit LagCheck(double rate_hz, const LagCheckLimits& limits = {});
  void push(const Sample& s, const DriftlessFilter& f);
  LagCheckResult finish();

 private:
  struct Entry {
    double t_s;
    Eigen::Vector3d w_dps, r_dps;  // fused corrected body rate and eq. (2)'s residual, box axes
  };
  void close_segment();

  LagCheckLimits limits_;
  int half_ = 1, margin_ = 25;  // samples
  double span_s_ = 0.04;        // s, the central difference's span, 2 half_ / rate
  std::vector<Entry> ring_;     // the newest 2 half_ + 1 + margin_ samples of the standstill
  std::size_t head_ = 0, count_ = 0;
  double p1_deg_ = kNaN, p2_deg_ = kNaN;
  // the current standstill's sums and the centred totals over all standstills
  struct Sums {
    std::uint64_t n = 0;
    Eigen::Vector3d a = Eigen::Vector3d::Zero(), r = Eigen::Vector3d::Zero();
    double aa = 0.0, ar = 0.0, rr = 0.0;
  } seg_;
  double S_aa_ = 0.0, S_ar_ = 0.0, S_rr_ = 0.0, dof_ = 0.0, mean_a2_ = 0.0, inv_n_ = 0.0;
  std::uint64_t samples_ = 0;
};

}  // namespace driftless::est
