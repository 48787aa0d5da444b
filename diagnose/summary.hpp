// The residual after the selected effects, and what a comparison reports about it: per-channel
// statistics (whiteness, Allan deviation against the model's band), regimes, windows,
// correlations with inputs, and the verdict in one sentence. docs/compare.md section 4.
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "diagnose/channel_fit.hpp"
#include "diagnose/compare.hpp"

namespace driftless::diagnose {

/// A fitted low-pass delay at or below this is "no low-pass" (the chain's boundary), s.
inline constexpr double kNoLowpassDelayS = 1e-4;

/// True when a fitted low-pass delay is "no low-pass": at or below kNoLowpassDelayS, or within
/// 2 sigma of zero (0.10 +- 0.05 ms on a log without a filter: written as a filter, it took a
/// 731 Hz bandwidth from the datasheet relation, and the noise aliased from there read 0.26x).
bool is_no_lowpass(const FittedParam& p);
/// True when a fitted parameter switches off an effect the model has (a quantisation of 0
/// LSB/(deg/s): the outputs lie on no lattice; a low-pass delay at "no low-pass"; a jitter or
/// delay of 0): the model's effect is not in the data, and the fix is to remove it (P11).
bool removes_model_effect(const FittedParam& p);
/// "the model's quantization (s1.x.sensitivity_lsb_per_dps = 131 LSB/(deg/s)) is not in the
/// data: remove it" for such a parameter.
std::string removal_text(Effect e, const FittedParam& p);

/// The residual of every channel after a fit (nuisance and the fit's effects taken out).
struct AfterFit {
  std::array<std::vector<double>, 6> z;       // block means
  std::array<std::vector<double>, 6> bias;    // smoothed bias per block (RTS)
  std::array<std::vector<float>, 6> e_drift;  // per sample, bias drift kept (NaN unusable); kSamples only
  std::size_t block_len = 1;                  // samples per block of z and bias
  /// The smoothed bias of channel c at sample k: linear between block centres, deg/s.
  double bias_at(int c, std::size_t k) const;
  /// Per sample, the smoothed bias removed too (e_drift - bias_at), deg/s; kSamples only. Formed
  /// when asked: a stored float copy was 8.6 MB for a 1 h log at 100 Hz
  float e(int c, std::size_t k) const {
    return static_cast<float>(e_drift[static_cast<std::size_t>(c)][k] - bias_at(c, k));
  }
  // mean and rms of `e` over the fit samples, deg/s (kStats and kSamples)
  std::array<double, 6> mean_dps{}, rms_dps{};
};
/// How much of the per-sample residual residual_after keeps: block means only; the per-sample
/// statistics (mean, rms) without the series (a 1 h log's float series is 8.6 MB); or both.
enum class AfterDetail { kBlocks, kStats, kSamples };
/// Computes the residual after `spec` / `fit` (an empty spec: the nuisance-only residual).
AfterFit residual_after(const Channels& ch, const ColumnInputs& in, const Residual& res, const FitSpec& spec,
                        const FitResult& fit, AfterDetail detail);

/// Fills channel statistics: raw and nuisance-only residual (`before`, against `model`), after
/// the selection (`after`, against `selected_model`: the model with the selected effects), noise
/// floors, whiteness of the whitened block residual, turn-on bias, Allan deviation against the
/// selected model's with its 95 % band.
void summarise_channels(const Channels& ch, const Residual& res, const CompareModel& model,
                        const CompareModel& selected_model, const AfterFit& before, const AfterFit& after,
                        const CompareOptions& opt, CompareResult& out);

/// Fills regimes, windows and correlations from the residual after the selection.
void summarise_regimes(const Replay& r, const Residual& res, const Channels& ch, const AfterFit& after,
                       const CompareOptions& opt, CompareResult& out);

/// Sets the verdict and the one-sentence statement from the selection, noise model and tests.
void decide_verdict(CompareResult& out);

}  // namespace driftless::diagnose
