// Model versus measurement: residual statistics, where the model fails, and which physical
// effect is missing (driftless compare / diagnose). Method and choices: docs/compare.md.
#pragma once

#include <array>
#include <limits>
#include <string>
#include <vector>

#include "estimator/allan.hpp"
#include "diagnose/compare_model.hpp"
#include "diagnose/replay.hpp"

namespace driftless::diagnose {

/// Settings of a comparison. Units: s, deg/s.
struct CompareOptions {
  double block_s = 0.1;             // s; residual block means for fits and whiteness
  double window_s = 0.0;            // s; windowed residual (0: duration / 30, clamped 10..300 s)
  int worst_windows = 5;            // windows listed by time
  double evidence_threshold = 10.0; // evidence (2 ln-likelihood gain - BIC penalty) for "missing"
  double whiteness_alpha = 1e-3;    // per-channel false-alarm level of the whiteness tests
  int ljung_box_lags = 20;          // lags of the Ljung-Box portmanteau (chi-square on lags - 1 dof)
  double min_effect_fraction = 0.005;  // structure must also explain this fraction of the residual
                                       // variance (sum of squared autocorrelations, or rho^2 of a
                                       // correlation) to count: significance alone grows with length
  double correlation_z = 5.0;       // |rho| sqrt(m) above this names a correlated input
  ReplayOptions replay;
  /// Throws std::invalid_argument naming the field.
  void validate() const;
};

/// A fitted parameter, in file units.
struct FittedParam {
  std::string name;   // e.g. "x.value_pct"
  double value = 0.0;
  double sigma = 0.0;
  std::string unit;   // "%", "deg/s/g", "deg", "s", ...
};

/// One regression coefficient of a candidate on one channel (for after-residuals and --apply).
struct ColumnFit {
  int channel = 0;  // 0..5 = sensor*3 + axis
  int column = 0;   // internal regressor id
  double beta = 0.0;
  double sigma = 0.0;
};

/// One candidate explanation of the residual.
struct Candidate {
  std::string effect;       // catalogue id (docs/effects.md) or box-level id
  std::string sensor = "-"; // "1", "2", "both" or "-"
  std::string axis = "-";   // "x", "y,z", "x,y,z" or "-"
  std::vector<FittedParam> params;
  double evidence = -std::numeric_limits<double>::infinity();
  double chi2 = 0.0;        // likelihood-ratio (or Wald) statistic
  int dof = 0;              // parameters added
  double p_value = 1.0;
  double explained_fraction = 0.0;  // of the whitened residual sum of squares
  bool testable = true;
  bool applicable = true;   // diagnose --apply can write it into the model
  std::string kind;         // "regression", "noise", "adc", "box"
  std::string note;
  std::vector<ColumnFit> fit;  // regression coefficients (regression candidates)
  std::array<double, 6> rms_after_dps{};  // residual rms per channel with the candidate added
};

/// Residual statistics of one channel.
struct ChannelSummary {
  double raw_mean_dps = 0.0, raw_rms_dps = 0.0;  // measured - predicted
  double mean_dps = 0.0, rms_dps = 0.0;          // after the nuisance (bias, run-to-run) fit
  double noise_floor_dps = 0.0;                  // the model's white noise after its DLPF
  double systematic_rms_dps = 0.0;               // sqrt(max(0, rms^2 - floor^2))
  double white_fit_dps_rthz = 0.0;               // N fitted to the residual
  double ljung_box_q = 0.0, ljung_box_p = 1.0;   // whiteness of the block residual
  double autocorrelation_excess = 0.0;           // sum of squared autocorrelations - lags/m
  bool white = true;                             // p >= alpha/6 or excess <= min_effect_fraction
  double turn_on_bias_dps = 0.0, turn_on_sigma_dps = 0.0;
  est::AllanCurve adev;                          // of the residual (bias drift kept)
  std::vector<double> adev_model;                // the model's ADEV at the same taus
  double adev_outside_fraction = 0.0;            // taus whose CI excludes the model's ADEV
};

/// The residual of one regime (standstill pair, flips, rate band, ...).
struct RegimeSummary {
  std::string group, name;
  std::size_t samples = 0;
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
  std::string verdict;    // missing_effect | consistent_with_noise | unexplained_structure
  std::string statement;  // one line
  std::vector<Candidate> ranking;  // best first
  std::array<ChannelSummary, 6> channels;
  std::vector<RegimeSummary> regimes;
  std::vector<WindowSummary> windows, worst_windows;
  std::vector<Correlation> correlations;  // significant ones, strongest first
  std::vector<std::string> notes;         // assumptions (replay, resampling, model)
  std::string model_source, log_path;
  double duration_s = 0.0, sample_rate_hz = 0.0, block_s = 0.0;
  std::size_t samples = 0, samples_used = 0, blocks_used = 0;
  bool resampled = false;
  // series for plots: block times, per-channel block residual and smoothed nuisance bias
  std::vector<double> block_t_s;
  std::array<std::vector<double>, 6> block_residual_dps, block_bias_dps;
};

/// Compares a replayed log with a model: residual, nuisance fit, regimes, candidates, verdict.
CompareResult compare(const Replay& replay, const CompareModel& model, const CompareOptions& opt);

/// Adds candidate `c` (fitted values) to `model`; throws std::runtime_error if it cannot be
/// represented in the model file (the message says what to do instead).
void apply_candidate(CompareModel& model, const Candidate& c);

/// Channel name "gyro1_x" ... "gyro2_z".
std::string channel_name(int channel);

}  // namespace driftless::diagnose
