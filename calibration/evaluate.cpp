// Bias error and attitude drift of the DriftLess filter on a dynamic log (see evaluate.hpp).
#include "calibration/evaluate.hpp"

#include "estimator/pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/core.h>

namespace driftless::calib {
namespace {

// the largest attitude error of the scored integration after the re-alignment at skip_s
class MaxAttitudeError final : public est::EstimateSink {
 public:
  explicit MaxAttitudeError(bool corrected) : corrected_(corrected) {}
  void on_attitude(const est::AttitudePoint& p) override {
    if (p.realigned) seen_ = true;
    if (seen_) max_deg_ = std::max(max_deg_, (corrected_ ? p.corrected : p.raw).angle_deg);
  }
  double max_deg() const { return max_deg_; }

 private:
  bool corrected_;
  bool seen_ = false;
  double max_deg_ = 0.0;
};

}  // namespace

void EvalOptions::validate() const {
  if (!(skip_s >= 0.0)) throw std::invalid_argument("evaluation: skip_s must be >= 0 s");
}

EvalRow evaluate_log(const std::vector<Sample>& log, const log::Metadata& meta,
                     const est::EstimatorConfig& cfg, const std::string& label,
                     bool bias_estimated, const EvalOptions& opts) {
  opts.validate();
  if (log.size() < 2) throw std::invalid_argument("evaluation: the log holds fewer than 2 samples");
  if (!log.front().ref_q_wxyz.allFinite() || !log.front().true_bias1_dps.allFinite())
    throw std::invalid_argument("evaluation: the log needs ref_q and true_bias columns (a twin log)");
  const double t0 = log.front().t_s;
  const double duration_h = (log.back().t_s - t0 - opts.skip_s) / 3600.0;
  if (!(duration_h > 0.0)) throw std::invalid_argument("evaluation: the log is not longer than skip_s");
  // the estimate pass scores it: the bias over every sample from skip_s on (WindowStats), the
  // attitude integrated from the reference at the first sample, re-aligned on it at skip_s and
  // compared at every sample
  est::EstimateRunOptions ro;
  ro.attitude_start_sigma_dps = 0.0;
  ro.attitude_interval_s = 0.0;
  ro.eval_start_s = t0 + opts.skip_s;
  ro.realign_at_eval_start = true;
  std::size_t k = 0;
  const est::SampleSource next = [&](Sample& s) { return k < log.size() ? (s = log[k++], true) : false; };
  MaxAttitudeError max_err(bias_estimated);
  const est::EstimateSummary sum =
      est::run_estimate(meta, kFieldTrueBias | kFieldRefQ, next, cfg, &max_err, ro);
  EvalRow row;
  row.label = label;
  row.bias_estimated = bias_estimated;
  if (bias_estimated) {
    row.bias_rms_error_dps = sum.window.bias_error_rms_dps;
    row.bias_final_error_dps = sum.window.final_error_dps.norm();
  }
  row.attitude_final_error_deg = (bias_estimated ? sum.final_corrected : sum.final_raw).angle_deg;
  row.attitude_max_error_deg = max_err.max_deg();
  row.attitude_drift_deg_per_h = row.attitude_final_error_deg / duration_h;
  row.updates = sum.counters.updates;
  return row;
}

std::string eval_table(const std::vector<EvalRow>& rows) {
  std::string out =
      "| configuration | bias error RMS (deg/s) | (deg/h) | final bias error (deg/s) | attitude "
      "error final (deg) | max (deg) | drift (deg/h) |\n|---|---|---|---|---|---|---|\n";
  for (const auto& r : rows) {
    const std::string b = r.bias_estimated ? fmt::format("{:.5f}", r.bias_rms_error_dps) : "-";
    const std::string bh = r.bias_estimated ? fmt::format("{:.1f}", r.bias_rms_error_dps * 3600) : "-";
    const std::string bf = r.bias_estimated ? fmt::format("{:.5f}", r.bias_final_error_dps) : "-";
    out += fmt::format("| {} | {} | {} | {} | {:.3f} | {:.3f} | {:.2f} |\n", r.label, b, bh, bf,
                       r.attitude_final_error_deg, r.attitude_max_error_deg,
                       r.attitude_drift_deg_per_h);
  }
  return out;
}

}  // namespace driftless::calib
