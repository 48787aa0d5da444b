// What calibration buys on a moving box (paper section 3: misalignment with a rotating body puts
// a rate-dependent error into the residual): run the DriftLess filter over a dynamic log with and
// without calibrated matrices and measure the bias-estimation error (against the log's true_bias
// columns) and the attitude drift (integrated corrected rate against ref_q).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "estimator/calibration.hpp"
#include "estimator/filter.hpp"
#include "estimator/log.hpp"

namespace driftless::calib {

/// One evaluated configuration.
struct EvalRow {
  std::string label;
  bool bias_estimated = true;          // false: the raw gyros (no DriftLess)
  double bias_rms_error_dps = kNaN;    // RMS over time (after skip) and the 6 components
  double bias_final_error_dps = kNaN;  // |b_hat - b_true| (6-vector norm) at the end
  double attitude_final_error_deg = kNaN;
  double attitude_max_error_deg = kNaN;
  double attitude_drift_deg_per_h = kNaN;  // final error / (duration - skip)
  std::uint64_t updates = 0;
};

struct EvalOptions {
  double skip_s = 300.0;  // s, the filter's convergence time: excluded from the bias RMS; the
                          // attitude is integrated from the reference at skip_s on
  void validate() const;
};

/// Runs the filter with `cfg` over `log` (which must hold true_bias and ref_q columns).
/// With bias_estimated = false the raw outputs are integrated instead (cfg gives the matrices).
EvalRow evaluate_log(const std::vector<Sample>& log, const log::Metadata& meta,
                     const est::EstimatorConfig& cfg, const std::string& label,
                     bool bias_estimated = true, const EvalOptions& opts = {});

/// Formats rows as a Markdown table (bias error in deg/s and deg/h, attitude in deg, deg/h).
std::string eval_table(const std::vector<EvalRow>& rows);

}  // namespace driftless::calib
