// The files `driftless estimate` writes (docs/estimator.md section 5): corrected.csv (one row per
// log row, formatted and written on the second core), estimate.csv (one row per update),
// attitude.csv (one row per comparison point) and summary.json. Every file goes through the one
// output helper (io::OutputFile): written under a partial name, renamed only when complete.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "cli/command.hpp"
#include "cli/estimate_figures.hpp"
#include "estimator/background_writer.hpp"
#include "estimator/output_file.hpp"
#include "estimator/pipeline.hpp"
#include "estimator/selfcal_choice.hpp"
#include "estimator/tune.hpp"

namespace driftless::cli {

/// What the per-sample outputs hold.
struct EstimateFilesOptions {
  bool truth = false;         // estimate.csv gets the true_bias columns
  bool corrected = false;     // write corrected.csv (--corrected)
  bool smoothed = false;      // its rows come from --smooth's second pass (on_smoothed_sample), marked smoothed = 1
  bool keep_series = false;   // collect the Fig. 5 series (--plot)
  double t_end_s = kNaN;      // s, for the progress display (the log's duration_s)
};

/// The sink of one estimate pass: streams the three CSV files while the filter runs.
class EstimateFiles : public est::EstimateSink {
 public:
  EstimateFiles(const std::filesystem::path& dir, const EstimateFilesOptions& opt);
  ~EstimateFiles() override;

  void on_sample(const Sample& s, const est::SampleOutput& o, bool locked) override;
  void on_update(const est::UpdateRecord& r, const est::Matrix6d& P, const Sample& s, bool locked) override;
  void on_attitude(const est::AttitudePoint& p) override;
  /// A corrected.csv row of --smooth's second pass (smoothed = 1; `locked` as in on_sample).
  void on_smoothed_sample(const Sample& s, const est::SampleOutput& o, bool locked);

  /// Writes what is left and renames the files into place (throws io::OutputError "<file>: <reason>").
  void commit();
  const FigureSeries& series() const { return series_; }

  /// One corrected.csv row: t, y1c (3), y2c (3), fused rate (3), all deg/s (s for t), the status
  /// and whether the correction was locked.
  struct CorrectedRow {
    double v[10];
    est::PushStatus status;
    bool locked;
    bool smoothed;  // a --smooth row: the column smoothed = 1 follows
  };

 private:
  EstimateFilesOptions opt_;
  std::optional<io::OutputFile> corrected_;
  io::OutputFile estimate_, attitude_;
  std::unique_ptr<io::BackgroundWriter<CorrectedRow>> corrected_writer_;  // after the file it writes
  FigureSeries series_;
  Progress progress_;
  std::uint64_t samples_ = 0;
};

/// How the model was chosen (docs/estimator.md section 1i): the mode, and in the automatic mode
/// whether the six-state pass called for a self-calibrating pass, why, and which one was kept.
struct SelfcalChoice {
  est::SelfcalMode mode = est::SelfcalMode::kAuto;
  bool tried = false;        // the self-calibrating pass ran after the six-state pass
  bool used = false;         // its results are the outputs
  bool interrupted = false;  // a stop came during it: the six-state pass's outputs stand
  std::string error;         // it could not read the log (a column only it parses): the six-state outputs stand
  est::HealthCause cause = est::HealthCause::kNoUpdate;  // the six-state finding that called for it
  est::HealthReport six_state, selfcal;                  // the two passes' health (when tried)
};

/// What summary.json says beyond the pass's own summary.
struct SummaryContext {
  std::string log_path;
  est::FilterMode mode = est::FilterMode::kGeneral;
  bool complete = true;             // false: the run was interrupted
  double stopped_at_t_s = kNaN;     // s, the last row processed when interrupted
  // --smooth given, and whether its second pass ran to the end (corrected.csv is then smoothed)
  bool smooth_requested = false;
  bool smoothed = false;
  const std::vector<FigureOutcome>* figures = nullptr;  // what --plot drew (nullptr: no "figures")
  const est::EstimatorConfig* config = nullptr;  // the configuration used (nullptr: no "health" text)
  const est::TuneResult* tune = nullptr;         // what --tune auto measured (nullptr: "tune": null)
  const SelfcalChoice* selfcal_choice = nullptr;  // how the model was chosen (nullptr: not said)
};

/// Writes summary.json (docs/estimator.md): "complete" and "stopped_at_t_s" first, then the
/// pass's results and warnings.
void write_estimate_summary(const std::filesystem::path& path, const SummaryContext& ctx,
                            const est::EstimateSummary& s);

}  // namespace driftless::cli
