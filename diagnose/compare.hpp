// Model versus measurement: residual statistics, where the model fails, and which effects are
// missing (driftless compare / diagnose). The stages, each in a file of one concern:
//   residual.hpp      prediction along the replayed log, residual, samples and blocks used
//   channel_fit.hpp   per-channel regressors, whitening, and the one MAP solve
//   signal_chain.hpp  low-pass / sample delay / time offset with the noise colour
//   selection.hpp     forward stepwise selection of the missing effects
//   noise_model.hpp   what the noise model gets wrong, after the selected effects
//   adc.hpp           quantisation, saturation, missing codes
//   summary.hpp       channel statistics, regimes, windows, correlations, verdict
// Method and choices: docs/compare.md.
#pragma once

#include <array>
#include <limits>
#include <string>
#include <vector>

#include "diagnose/compare_model.hpp"
#include "diagnose/effects.hpp"
#include "diagnose/replay.hpp"
#include "estimator/allan.hpp"

namespace driftless::diagnose {

/// Settings of a comparison. Units: s, deg/s.
struct CompareOptions {
  double block_s = 0.1;             // s; residual block means for fits and whiteness
  double window_s = 0.0;            // s; windowed residual (0: duration / 30, clamped 10..300 s)
  int worst_windows = 5;            // windows listed by time
  double evidence_threshold = 10.0; // evidence (2 ln-likelihood gain - BIC penalty) to select an effect
  double whiteness_alpha = 1e-3;    // per-channel false-alarm level of the whiteness tests
  int ljung_box_lags = 20;          // lags of the Ljung-Box portmanteau (chi-square on lags - 1 dof)
  double min_effect_fraction = 0.005;  // structure must also explain this fraction of the residual
                                       // variance (sum of squared autocorrelations, or rho^2 of a
                                       // correlation) to count: significance alone grows with length
  double correlation_z = 5.0;       // |rho| sqrt(m) above this names a correlated input
  int max_steps = 12;               // forward selection steps at most
  ReplayOptions replay;
  /// Throws std::invalid_argument naming the field.
  void validate() const;
};

/// A fitted parameter: the change to the model's value (file units) and the value the model had.
struct FittedParam {
  ParamRef ref;
  double value = 0.0;        // fitted change (for the signal chain: new value - model value)
  double sigma = 0.0;        // 1-sigma of value
  double model_value = 0.0;  // the model's value before
  bool absurd = false;       // |new value| beyond what a MEMS gyro box can have
  double new_value() const { return model_value + value; }
  std::string name() const { return param_name(ref); }
  const char* unit() const { return param_unit(ref.param); }
};

/// An effect: fitted where the data support it (selected), or evaluated and not supported.
struct Candidate {
  Effect effect = Effect::kScaleFactor;
  std::vector<FittedParam> params;       // the parameters written by --apply (selected) or fitted
  std::vector<FittedParam> diagnostics;  // supporting numbers (noise colour), not written
  std::vector<std::pair<int, int>> codes;  // adc_missing_codes: (channel, code)
  double evidence = -std::numeric_limits<double>::infinity();  // at its step (selected) or now
  double chi2 = 0.0;                     // likelihood-ratio statistic
  int dof = 0;                           // parameters
  double p_value = 1.0;
  double explained_fraction = 0.0;       // of the whitened residual sum of squares at its step
  bool testable = true;                  // the log excites it
  int step = 0;                          // order in the forward selection (1 = first); 0 = not selected
  bool absurd = false;                   // some parameter is implausible: not written by --apply
  std::string note;
  bool selected() const { return step > 0; }
  Family family() const { return effect_info(effect).family; }
};
/// "1", "2", "both" or "-" (box-wide).
std::string sensor_text(const Candidate& c);
/// "x", "y,z", "s1:x s2:y,z", "-".
std::string axis_text(const Candidate& c);
/// The parameter named `name` ("s1.x.value_pct"), or nullptr.
const FittedParam* find_param(const Candidate& c, const std::string& name);

/// What a comparison concludes.
enum class Verdict { kConsistent, kMissingEffect, kUnexplained };
/// "consistent_with_noise", "missing_effect", "unexplained_structure".
const char* verdict_id(Verdict v);

/// Residual statistics of one channel.
struct ChannelSummary {
  double raw_mean_dps = 0.0, raw_rms_dps = 0.0;  // measured - predicted
  double mean_dps = 0.0, rms_dps = 0.0;          // after the nuisance (bias, run-to-run) fit
  double rms_after_dps = 0.0;                    // ... and after the selected effects
  double noise_floor_dps = 0.0;                  // the model's white noise after its DLPF
  double systematic_rms_dps = 0.0;               // sqrt(max(0, rms^2 - floor^2))
  double systematic_after_dps = 0.0;             // the same after the selected effects
  double white_fit_dps_rthz = 0.0;               // N fitted to the residual (after the selection)
  double ljung_box_q = 0.0, ljung_box_p = 1.0;   // whiteness of the block residual
  double autocorrelation_excess = 0.0;           // sum of squared autocorrelations - lags/m
  bool white = true;                             // p >= alpha/6 or excess <= min_effect_fraction
  double turn_on_bias_dps = 0.0, turn_on_sigma_dps = 0.0;
  est::AllanCurve adev;                          // of the residual after the selection (drift kept)
  std::vector<double> adev_model;                // the model's ADEV at the same taus
  std::vector<double> adev_model_lo, adev_model_hi;  // the model's 95 % band for a record this long
  double adev_outside_fraction = 0.0;            // taus whose CI excludes the model's band
};

/// The residual of one regime (standstill pair, flips, rate band, ...).
struct RegimeSummary {
  std::string group, name;
  std::size_t samples = 0;         // usable samples of the regime
  std::size_t samples_in_fit = 0;  // ... of which the fits use (0 for the flips: left out)
  std::array<double, 6> mean_dps{}, rms_dps{};
};

/// One window of the windowed residual.
struct WindowSummary {
  double t0_s = 0.0, t1_s = 0.0;
  std::array<double, 6> rms_dps{};
  double worst_ratio = 0.0;  // largest rms / noise floor over channels
  int worst_channel = 0;
};

/// Correlation of the whitened residual with an input signal.
struct Correlation {
  std::string signal;
  int channel = 0;
  double rho = 0.0;
  double z = 0.0;  // rho sqrt(m)
};

/// Everything a comparison found.
struct CompareResult {
  Verdict verdict = Verdict::kConsistent;
  std::string statement;                 // one sentence
  std::vector<Candidate> selected;       // the missing effects, in selection order
  std::vector<Candidate> noise_model;    // noise-model changes the rest supports (labelled)
  std::vector<Candidate> not_supported;  // evaluated given the selection, not supported
  double threshold = 10.0;               // the evidence threshold used
  std::array<ChannelSummary, 6> channels;
  std::vector<RegimeSummary> regimes;
  std::vector<WindowSummary> windows, worst_windows;
  std::vector<Correlation> correlations;  // significant ones, strongest first
  // channels whose constant offset from the reference (turn_on_bias_dps) no sensor of the model's
  // kind can have: beyond the MPU6050's zero-rate tolerance and 3 sigma of the model's turn-on
  // spread (the reference turns at a rate the gyro does not see, or another frame or unit)
  std::vector<int> offset_beyond_zro;
  std::vector<std::string> notes;         // assumptions (replay, resampling, model)
  std::string model_source, log_path;
  double duration_s = 0.0, sample_rate_hz = 0.0, block_s = 0.0;
  int sensors = 2;  // 1: a single-sensor log (channels gyro2_* are null in the outputs)
  std::size_t samples = 0, samples_used = 0, blocks_used = 0;
  bool resampled = false;
  // series for plots: block times; per channel the block residual after the selected effects and
  // the smoothed bias, and that bias
  std::vector<double> block_t_s;
  std::array<std::vector<double>, 6> block_residual_dps, block_bias_dps;
  /// True when any selected effect has an implausible value.
  bool any_absurd() const;
};

/// Compares a replayed log with a model: residual, nuisance fit, forward selection of the
/// missing effects, noise model, summaries, verdict.
CompareResult compare(const Replay& replay, const CompareModel& model, const CompareOptions& opt);

}  // namespace driftless::diagnose
