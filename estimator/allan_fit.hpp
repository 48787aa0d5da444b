// The IEEE 952 noise terms of a rate signal from its overlapping Allan deviation: one joint
// weighted fit of quantisation Q, white noise N, bias instability (flicker B or Gauss-Markov),
// rate random walk K and rate ramp R over the whole curve, with uncertainties that include model
// error and "not identifiable" where a term has no support. Docs: docs/allan.md (fits).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "estimator/allan.hpp"

namespace driftless::est {

/// The terms of the Allan-variance model, in the order of NoiseModel::coef.
enum class NoiseTerm { kQ, kN, kB, kK, kR, kGaussMarkov };
inline constexpr int kNoiseTerms = 6;
/// "Q", "N", "B", "K", "R", "GM".
const char* to_string(NoiseTerm t);

/// An Allan-variance model: sum of the terms (units: the input's, e.g. deg/s; tau in s).
///  Q  3 Q^2 / tau^2          (angle quantisation / white PM)
///  N  N^2 / tau              (angle random walk, units sqrt(s) = units/sqrt(Hz)); when the white
///                             noise is low-passed with time constant Tf (a DLPF), the exact Allan
///                             variance of sampled first-order low-passed white noise (docs/allan.md),
///                             which is N^2 / tau again for tau >> Tf
///  B  (2 ln 2 / pi) B^2      (flicker bias instability, IEEE 952: the ADEV floor is 0.664 B)
///  K  K^2 (tau/3 + tau0^2/(6 tau))   (rate random walk, units/sqrt(s); exact for sampled data)
///  R  R^2 tau^2 / 2          (rate ramp, units/s)
///  GM first-order Gauss-Markov bias, stationary sigma^2 and correlation time T:
///     (2 sigma^2 T / tau) [1 - T/(2 tau) (3 - 4 e^(-tau/T) + e^(-2 tau/T))]
struct NoiseModel {
  std::array<double, kNoiseTerms> coef{};  // Q^2, N^2, B^2, K^2, R^2, sigma_GM^2
  double gm_tau_s = 0.0;                   // s, Gauss-Markov correlation time (when coef[GM] > 0)
  double white_tau_s = 0.0;                // s, low-pass time constant of the white noise (0: none)
  double tau0_s = 0.01;                    // s, sample interval (for the sampled K term)
  /// Allan variance of term t at tau (units^2).
  double term_avar(NoiseTerm t, double tau_s) const;
  /// Allan variance of the whole model at tau (units^2).
  double avar(double tau_s) const;
};

/// A fitted parameter, in the input's units (see NoiseFit).
struct NoiseParameter {
  double value = 0.0;      // estimate (NaN when not identifiable)
  double sigma = 0.0;      // 1-sigma: statistics (correlated taus) and model error
  double upper_95 = 0.0;   // one-sided 95 % upper bound (also when not identifiable)
  double tau_s = 0.0;      // s: where the term's share of the model is largest (B_min: the minimum)
  double tau_lo_s = 0.0;   // s: the region where the term is at least half of the model (NaN: none)
  double tau_hi_s = 0.0;
  bool valid = false;      // identifiable: significant (> 2 sigma) and >= 30 % of the model somewhere
  std::string note;        // why not, or what to beware of
};

/// Options of fit_noise_parameters().
struct NoiseFitOptions {
  /// Drop the shortest taus while their normalised residual exceeds this (coloured noise the model
  /// does not describe), keeping at least three more points than parameters.
  double trim_residual = 3.0;
  /// Extra variance inflation on top of the fit's own model of how neighbouring taus correlate
  /// (1 = none; the Monte Carlo calibration in docs/allan.md needs none).
  double correlation_inflation = 1.0;
  /// The Gauss-Markov model is preferred when it lowers chi-square by more than this (scaled by the
  /// flicker fit's inflation): long correlation times mimic K, so chance bends must not switch.
  double gm_preference = 10.0;
};

/// Which bias-instability model the fit prefers.
enum class BiasModel { kFlicker, kGaussMarkov };

/// The noise parameters of a rate signal, units of the input (deg/s: N in deg/s/sqrt(Hz),
/// B in deg/s, K in deg/s/sqrt(s), R in deg/s^2, Q in deg).
struct NoiseFit {
  NoiseParameter Q;        // angle quantisation
  NoiseParameter N;        // angle random walk
  NoiseParameter B;        // bias instability, IEEE 952 flicker convention (ADEV floor / 0.664)
  NoiseParameter B_min;    // bias instability, datasheet convention: the model's ADEV minimum
  NoiseParameter gm_sigma; // Gauss-Markov alternative: stationary sigma
  NoiseParameter gm_tau;   // Gauss-Markov alternative: correlation time, s
  NoiseParameter K;        // rate random walk
  NoiseParameter R;        // rate ramp
  double white_lowpass_tau_s = 0.0;  // s: the white noise's low-pass time constant (0: white to tau0)
  NoiseModel flicker_model, gm_model;  // the two fitted models
  BiasModel preferred = BiasModel::kFlicker;  // see NoiseFitOptions::gm_preference
  double gm_evidence = 0.0;  // chi-square the Gauss-Markov model saves over the flicker one, scaled
  double chi2_red = 0.0;   // reduced chi-square of the preferred fit (> 1: model error, inflates sigma)
  double tau_fit_lo_s = 0.0, tau_fit_hi_s = 0.0;  // s, the fitted range (after trimming)
  std::size_t points_fitted = 0;
  std::vector<std::string> warnings;  // record too short for B or K, taus trimmed, ...
  /// The preferred model.
  const NoiseModel& model() const { return preferred == BiasModel::kFlicker ? flicker_model : gm_model; }
};

/// Fits the noise terms to an Allan deviation curve (overlapping or not; not MDEV/HDEV).
/// Weights: edf per point, scaled so that a denser tau grid adds no information beyond octaves.
/// Throws std::invalid_argument for a curve of another deviation.
NoiseFit fit_noise_parameters(const AllanCurve& curve, const NoiseFitOptions& opt = {});

/// sqrt(2 ln 2 / pi): the Allan deviation floor of flicker noise is this times B (IEEE 952).
inline constexpr double kFlickerFloorFactor = 0.6642824702679600;

}  // namespace driftless::est
