// What one sweep run does: build the run's scenario and filter configuration from the grid
// values, run the source (fast closed form or full MuJoCo twin) through the DriftLess filter
// (and the fault detector), and score it against the truth. Metrics: docs/sweep.md.
#pragma once

#include <atomic>
#include <functional>
#include <string>

#include "estimator/fdi.hpp"
#include "estimator/filter.hpp"
#include "estimator/log.hpp"
#include "estimator/pipeline.hpp"
#include "twin/scenario.hpp"
#include "studies/sweep.hpp"

namespace driftless::studies {

/// Everything one run needs, after the grid values and fixed keys are applied.
struct RunSetup {
  twin::Scenario scenario;
  est::EstimatorConfig estimator;
  // planted fault (runner fdi): keys fault.kind (0 none, 1 stuck, 2 bias_step, 3 noise_burst,
  // 4 scale_change), fault.sensor (1|2), fault.axis (0..2), fault.t_s (s), fault.size
  // (bias step deg/s; noise sigma ratio; relative scale change; 0 = 0.5 deg/s, x5, +5 %)
  int fault_kind = 0, fault_sensor = 1, fault_axis = 0;
  double fault_t_s = 0.0, fault_size = 0.0;
  double eval_start_s = -1.0;  // s, metrics from here; < 0: a quarter of the duration
};

/// Builds the base once: the sweep's scenario (file or built-in) as YAML.
class SetupBuilder {
 public:
  explicit SetupBuilder(const SweepConfig& cfg);
  /// The setup of run `spec`; throws std::invalid_argument naming the key on a bad value.
  RunSetup build(const RunSpec& spec) const;

 private:
  SweepConfig cfg_;
  std::string base_yaml_;
  std::filesystem::path base_dir_;
};

/// Source of samples for evaluate(): fills the next sample, false at the end.
using SampleSource = est::SampleSource;

/// The estimate pass as the sweep scores it (docs/sweep.md): attitude (paper Fig. 9) from the
/// DriftLess-corrected rate and from the gyros with their bias zeroed once at the first sample
/// (a perfect turn-on calibration, then drift: the paper's "without DriftLess"), both started on
/// the reference and re-aligned on it at the window start (eval_start_s; < 0: a quarter of the
/// duration); truth statistics over the window. `driftless estimate` on a saved run log with
/// these options scores what the sweep scored.
est::EstimateRunOptions bias_run_options(const RunSetup& setup);

/// Runs `source` through the estimate pass (est::run_estimate) with the filter of `setup` and
/// scores the bias estimate against the true_bias columns: bias_err_rms_dph (all six components over t >= eval start),
/// per-component RMS, max, final, mean NEES/6, NIS mean, updates and rejections, attitude drift
/// with DriftLess and with the bias zeroed once. With `attitude_csv` set, also writes the attitude
/// error angles (deg) once per second: t_s,err_driftless_deg,err_zeroed_deg.
Metrics evaluate_bias(const RunSetup& setup, const log::Metadata& meta, const SampleSource& source,
                      const std::filesystem::path& attitude_csv = {});

/// Runs the source with the planted fault through the filter and the fault detector; metrics:
/// alarm, alarm delay, isolation delay, kind/sensor/axis correct, false alarm.
Metrics evaluate_fdi(const RunSetup& setup, const log::Metadata& meta, const SampleSource& source);

/// The job of a sweep's runner (fast | twin | fdi | fdi_twin). With `log_dir` set, every run also writes its
/// samples to log_dir/run_<index>.csv (driftless-log 1) for `driftless estimate` / `allan`, and
/// (runners fast, twin) its attitude errors to log_dir/attitude_<index>.csv. When `stop` becomes true
/// (Ctrl-C) a run in progress ends at its next sample and throws "stopped" (the runner marks it failed).
SweepJob make_job(const SweepConfig& cfg, const std::filesystem::path& log_dir = {},
                  const std::atomic<bool>* stop = nullptr);

}  // namespace driftless::studies
