// The signal chain of each sensor: its low-pass (group delay as one continuous parameter, 0 =
// no filter, bandwidth from the MPU6050 datasheet relation), its own sample delay, and the box
// time offset. All three delay the signal (regressor -dw/dt); only the low-pass also colours the
// noise, so the lag-1 correlation of the residual noise at quiet samples tells them apart.
// docs/compare.md section 3, docs/effects.md 11a and 13.
#pragma once

#include <array>

#include "diagnose/compare_model.hpp"
#include "diagnose/residual.hpp"

namespace driftless::diagnose {

/// Lag-1 correlation of one sensor's residual noise: the residual with its delay signature
/// regressed out (OLS on -dw/dt, d2w/dt2), a cubic taken out of each window of 12 samples
/// (what a motion leaves is smooth), pooled over the three axes. Its expectation under a model
/// follows from the model's noise autocorrelation through the same detrending.
struct NoiseColour {
  double stat = 0.0;      // sum d_k d_{k-1} / sum d_k^2 of the detrended windows
  double pairs = 0.0;     // independent pairs (window length - 4 per window)
  double mean_square_dps2 = 0.0;  // mean square of the detrended residual
  std::size_t block_len = 12;     // samples per window
  bool usable() const { return pairs >= 500.0; }
};

/// A signal chain's second- and third-order terms, s^2 and s^3: delays change the signal by
/// -c1 dw/dt + c2 d2w/dt2 - c3 d3w/dt3, with c_n = E[t^n]/n! of the chain's impulse response.
struct ChainTerms {
  double c2 = 0.0, c3 = 0.0;
};
/// The terms of a low-pass of group delay D (s) with pole time T (s; an exponential of mean T
/// after a pure delay D - T), followed by a pure delay d (s): c1 = D + d,
/// c2 = (D^2 + T^2)/2 + d D + d^2/2 and, with a = D - T + d, c3 = (6 T^3 + 6 a T^2 + 3 a^2 T + a^3)/6.
ChainTerms chain_moments(double group_delay_s, double pole_time_s, double extra_delay_s);

/// Measures both sensors' noise colour on windows of usable samples.
std::array<NoiseColour, 2> measure_noise_colour(const Replay& r, const Residual& res);

/// The model's group delay of sensor p's gyro low-pass, s (0 without a filter).
double lowpass_delay_s(const twin::SensorParams& p);
/// `p` with its low-pass replaced by the continuous one of group delay `delay_s` (0: none).
twin::SensorParams with_lowpass_delay(twin::SensorParams p, double delay_s);

/// The colour statistic the model `p` expects at rate fs for a measured colour (its mean square).
double expected_colour(const twin::SensorParams& p, double fs, const NoiseColour& measured);

/// -2 ln L of a colour mismatch. The statistic's spread is 1/sqrt(pairs) plus a tolerance of
/// 0.05 for filters of another shape than the model's (first-order pole + delay).
double colour_penalty(const NoiseColour& measured, double expected);

}  // namespace driftless::diagnose
