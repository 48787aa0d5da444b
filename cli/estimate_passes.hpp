// The passes of `driftless estimate` over a log and the default model choice between them
// (docs/estimator.md section 1i): the six-state pass, the self-calibrating pass (started beside it on
// the second core when it fails early, or after it), and which pass's files are kept. The rule of
// the choice is estimator/selfcal_choice.hpp; the text is made here and in cli/estimate_health.cpp.
#pragma once

#include <filesystem>
#include <memory>
#include <string>

#include "cli/estimate_outputs.hpp"
#include "estimator/config.hpp"
#include "estimator/log.hpp"
#include "estimator/pipeline.hpp"
#include "estimator/smoother.hpp"

namespace driftless::cli {

/// What the passes take from the command line.
struct PassInputs {
  std::string log;                        // the measurement log
  bool calib = false;                     // --calib given (its G needs the accel columns)
  bool smooth = false;                    // --smooth: each pass feeds a fixed-interval smoother
  double attitude_start_sigma_dps = est::EstimateRunOptions{}.attitude_start_sigma_dps;  // deg/s
};

/// One pass of the filter over the log into `dir`; its files stay uncommitted (a pass that is not
/// kept leaves nothing behind).
struct EstimatePass {
  est::EstimatorConfig cfg;
  log::ReaderOptions read_opt;
  std::unique_ptr<EstimateFiles> files;
  std::unique_ptr<est::FixedIntervalSmoother> smoother;
  est::EstimateSummary summary;
  std::filesystem::path dir;
};

/// The column groups a pass with `cfg` parses.
log::ReaderOptions reader_options(const PassInputs& in, const est::EstimatorConfig& cfg);

/// The column groups the first pass's reader parses: reader_options(in, cfg), and in the automatic
/// choice (`mode`) the accel columns too, so that it can hand its rows on to the self-calibrating pass.
log::ReaderOptions first_reader_options(const PassInputs& in, const est::EstimatorConfig& cfg, est::SelfcalMode mode);

/// The pass with `cfg` over `reader` (opened with first_reader_options(in, cfg, choice.mode)) into `dir` and, where
/// `choice.mode` is automatic and the choice wants it, the self-calibrating pass; returns the kept
/// pass with its files uncommitted and fills `choice` (summary.json's self_calibration_choice).
EstimatePass run_passes(const PassInputs& in, const est::EstimatorConfig& cfg, log::LogReader& reader,
                        const std::filesystem::path& dir, const EstimateFilesOptions& file_opt, SelfcalChoice& choice);

/// Commits the kept pass's files and moves them into `dir` (a self-calibrating pass wrote into a
/// folder of its own); the pass's dir is `dir` afterwards.
void commit_pass(EstimatePass& p, const std::filesystem::path& dir);

/// The console line after a self-calibrating pass that was tried (nothing when none was).
void print_choice(const SelfcalChoice& c);

}  // namespace driftless::cli
