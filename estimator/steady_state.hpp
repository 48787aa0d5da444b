// The steady state of the bias filter in closed form (docs/estimator.md section 6.5): the bias is
// a random walk of rate q, each standstill measures the mean of R1 b1 - R2 b2 over its window, and
// the updates come every T seconds. The posterior variance settles where the walk between updates
// balances what the updates pin down: the fixed point of the periodic Riccati recursion. If that
// sigma sits at or above the lock level, a longer log cannot lock the filter (stop-27 finding F27).
// Eigen-free, std only.
#pragma once

#include <limits>

namespace driftless::est {

/// A scalar variance map p -> (a p + b) / (c p + d) (a Moebius transformation): one predict or
/// update step of a scalar Kalman filter's variance; steps compose into one map of the same form.
struct VarianceMap {
  double a = 1.0, b = 0.0, c = 0.0, d = 1.0;
  double operator()(double p) const { return (a * p + b) / (c * p + d); }
  /// The map p -> next(this(p)).
  VarianceMap then(const VarianceMap& next) const;
};

/// The predict step: p -> p + q dt ((deg/s)^2; q in (deg/s)^2/s, dt in s).
VarianceMap predict_map(double q_dps2_per_s, double dt_s);
/// The update by the mean of the state over a window of `window_s` that ends at the update
/// (section 1h: noise -u with Var(u) = q T/3, Cov(u, prior error) = q T/2), measurement variance
/// `meas_var_dps2`: p -> ((R + q v) p - (q c)^2) / (p + R + q (v - 2 c)). A window of 0 is the
/// plain update p -> R p / (p + R).
VarianceMap window_update_map(double q_dps2_per_s, double meas_var_dps2, double window_s);
/// The non-negative fixed point a repeated map converges to: the larger root of
/// c p^2 + (d - a) p - b = 0 (b / (d - a) when c = 0); NaN when there is none.
double attracting_fixed_point(const VarianceMap& m);

/// The update schedule of a run: what the steady state depends on.
struct UpdateSchedule {
  double q_dps2_per_s = 0.0;  // (deg/s)^2/s, the bias random walk per axis
  double interval_s = 0.0;    // s, between updates (one flip and one standstill)
  double window_s = 0.0;      // s, each standstill's averaging span (<= interval_s)
  double meas_var_dps2 = 0.0; // (deg/s)^2, variance of one sensor's mean over a standstill (sigma^2 / n)
};

/// The steady state of the bias sigma after each update over an eq. (5) cycle (four updates,
/// platform 2 and platform 1 flipping in turn, perpendicular hinges, rests at +-90 deg). Each
/// update measures, per bias-component pair, b1 + b2 or b1 - b2 (variance 2 R); in the sum and
/// difference coordinates the pairs split into scalar walks measured with R. The pair whose sign
/// follows both platforms alternates sum and difference (each seen every 2 T); the pairs whose sign
/// follows one platform see the sum on two updates in a row and then the difference on two.
struct SteadyState {
  double sigma_dps = 0.0;          // deg/s, the largest bias sigma after every update of the cycle:
                                   // the filter locks only if this is below the lock level
  double sigma_low_dps = 0.0;      // deg/s, the smallest bias sigma the cycle reaches
  double walk_per_update_dps = 0.0;  // deg/s, sqrt(q T): the wander between two updates
};

/// The closed-form steady state of `s` (NaN fields when q, T or R is not positive and finite).
SteadyState bias_steady_state(const UpdateSchedule& s);

/// The update interval (s) that brings SteadyState::sigma_dps down to `target_dps`, with the flip
/// time (interval - window) and the standstill's noise per second of averaging unchanged; NaN when
/// even a standstill-only schedule cannot (the flips alone take the time).
double interval_for_sigma_s(const UpdateSchedule& s, double target_dps);

/// The lock level's margin: the schedule advised reaches this fraction of the lock level.
inline constexpr double kSteadyStateLockMargin = 0.8;

/// What a run's first updates say of its steady state (summary.json `health.steady_state`).
struct SteadyStatePrediction {
  bool available = false;   // the first updates gave a schedule (general mode, 3-row updates)
  UpdateSchedule schedule;  // their mean interval and window, the configured q and noise
  SteadyState closed;       // its closed form (bias_steady_state)
  double known_at_t_s = std::numeric_limits<double>::quiet_NaN();    // s, the update that completed it
  double lock_sigma_dps = std::numeric_limits<double>::quiet_NaN();  // deg/s, the lock level
  // s, the update interval whose closed form is kSteadyStateLockMargin of the lock level (NaN: none)
  double interval_for_lock_s = std::numeric_limits<double>::quiet_NaN();
  // self-calibration or temperature states add to the correction's sigma: the closed form, for the
  // bias alone, is then its lower bound
  bool other_states = false;
  /// The lock level cannot be reached: the bias alone settles at or above it.
  bool lock_unreachable() const { return available && closed.sigma_dps >= lock_sigma_dps; }
};

}  // namespace driftless::est
