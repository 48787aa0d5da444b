// The closed-form steady state of the bias filter (steady_state.hpp; docs/estimator.md section 6.5).
#include "estimator/steady_state.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace driftless::est {

namespace {

constexpr double kNaNss = std::numeric_limits<double>::quiet_NaN();

bool positive_finite(double v) { return std::isfinite(v) && v > 0.0; }

// the steady-state variances of one sum/difference coordinate after each update of the cycle,
// for the two patterns of steady_state.hpp: alternating (measured every other update) and paired
// (two updates in a row, then two without)
struct CycleVariances {
  double alternating_dps2 = 0.0;  // the component's variance: (p_after + p_after + q T) / 2
  double paired_max_dps2 = 0.0;   // its larger value over the cycle, (p_k + p_{k+2}) / 2
  double paired_min_dps2 = 0.0;
};

CycleVariances cycle_variances(const UpdateSchedule& s) {
  const VarianceMap walk = predict_map(s.q_dps2_per_s, s.interval_s);
  const VarianceMap update = window_update_map(s.q_dps2_per_s, s.meas_var_dps2, s.window_s);
  const VarianceMap walk_update = walk.then(update);
  const double qT = s.q_dps2_per_s * s.interval_s;
  CycleVariances out;
  // alternating: right after this coordinate's update, it waits one update (the other
  // coordinate's), then is measured again; the component is the mean of the two coordinates
  const double p_alt = attracting_fixed_point(walk.then(walk_update));
  out.alternating_dps2 = p_alt + 0.5 * qT;
  // paired: after its second update in a row it waits two updates, then is measured twice
  const double p1 = attracting_fixed_point(walk.then(walk).then(walk_update).then(walk_update));
  const double p2 = p1 + qT, p3 = p1 + 2.0 * qT;
  const double p0 = walk_update(p3);
  const double at0 = 0.5 * (p0 + p2), at1 = 0.5 * (p1 + p3);
  out.paired_max_dps2 = std::max(at0, at1);
  out.paired_min_dps2 = std::min(at0, at1);
  return out;
}

// SteadyState::sigma_dps of the schedule `s` with the interval `interval_s`, the flip time and
// the noise per second of averaging (R times the window) kept
double sigma_at_interval(const UpdateSchedule& s, double interval_s) {
  UpdateSchedule t = s;
  const double flip_s = s.interval_s - s.window_s;
  t.interval_s = interval_s;
  t.window_s = interval_s - flip_s;
  t.meas_var_dps2 = s.meas_var_dps2 * s.window_s / t.window_s;
  return bias_steady_state(t).sigma_dps;
}

}  // namespace

VarianceMap VarianceMap::then(const VarianceMap& next) const {
  // next o this: the 2 x 2 matrix product [next] [this]
  return {next.a * a + next.b * c, next.a * b + next.b * d, next.c * a + next.d * c, next.c * b + next.d * d};
}

VarianceMap predict_map(double q_dps2_per_s, double dt_s) { return {1.0, q_dps2_per_s * dt_s, 0.0, 1.0}; }

VarianceMap window_update_map(double q_dps2_per_s, double meas_var_dps2, double window_s) {
  // section 1h with H = 1: W = (p - q c) / S, S = p + R + q (v - 2 c), p' = p - (p - q c)^2 / S
  const double c = 0.5 * window_s, v = window_s / 3.0;
  const double qc = q_dps2_per_s * c;
  return {meas_var_dps2 + q_dps2_per_s * v, -qc * qc, 1.0, meas_var_dps2 + q_dps2_per_s * (v - 2.0 * c)};
}

double attracting_fixed_point(const VarianceMap& m) {
  // p (c p + d) = a p + b: c p^2 + (d - a) p - b = 0
  const double A = m.c, B = m.d - m.a, C = -m.b;
  if (A == 0.0) return B != 0.0 && -C / B >= 0.0 ? -C / B : kNaNss;
  const double disc = B * B - 4.0 * A * C;
  if (!(disc >= 0.0)) return kNaNss;
  // the larger root, written without the cancellation of -B + sqrt(disc) when B > 0
  const double root = B > 0.0 ? (2.0 * C) / (-B - std::sqrt(disc)) : (-B + std::sqrt(disc)) / (2.0 * A);
  return root >= 0.0 ? root : kNaNss;
}

SteadyState bias_steady_state(const UpdateSchedule& s) {
  SteadyState out;
  if (!positive_finite(s.q_dps2_per_s) || !positive_finite(s.interval_s) || !positive_finite(s.meas_var_dps2) ||
      !(s.window_s >= 0.0 && s.window_s <= s.interval_s)) {
    out.sigma_dps = out.sigma_low_dps = out.walk_per_update_dps = kNaNss;
    return out;
  }
  const CycleVariances v = cycle_variances(s);
  out.sigma_dps = std::sqrt(std::max(v.alternating_dps2, v.paired_max_dps2));
  out.sigma_low_dps = std::sqrt(std::min(v.alternating_dps2, v.paired_min_dps2));
  out.walk_per_update_dps = std::sqrt(s.q_dps2_per_s * s.interval_s);
  return out;
}

double interval_for_sigma_s(const UpdateSchedule& s, double target_dps) {
  const double flip_s = s.interval_s - s.window_s;
  if (!std::isfinite(bias_steady_state(s).sigma_dps) || !positive_finite(target_dps) || !(flip_s >= 0.0)) return kNaNss;
  // sigma against the interval is U-shaped: short windows average little noise away, long
  // intervals let the bias wander; find the bottom (golden section on log(interval - flip))
  const double lo0 = std::log(std::max(1e-3 * s.window_s, 1e-6)), hi0 = std::log(100.0 * s.interval_s);
  auto sigma_log = [&](double u) { return sigma_at_interval(s, flip_s + std::exp(u)); };
  double lo = lo0, hi = hi0;
  constexpr double kGolden = 0.6180339887498949;
  for (int i = 0; i < 100; ++i) {
    const double m1 = hi - kGolden * (hi - lo), m2 = lo + kGolden * (hi - lo);
    if (sigma_log(m1) < sigma_log(m2)) hi = m2;
    else lo = m1;
  }
  const double best_u = 0.5 * (lo + hi);
  if (!(sigma_log(best_u) <= target_dps)) return kNaNss;
  // the root between the bottom and the present interval: the nearest change that reaches it
  const double now_u = std::log(std::max(s.window_s, 1e-6));
  if (sigma_log(now_u) <= target_dps) return s.interval_s;
  double a = best_u, b = now_u;  // sigma(a) <= target < sigma(b)
  for (int i = 0; i < 100; ++i) {
    const double m = 0.5 * (a + b);
    (sigma_log(m) <= target_dps ? a : b) = m;
  }
  return flip_s + std::exp(a);
}

}  // namespace driftless::est
