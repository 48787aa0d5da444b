// What `compare` and `diagnose` share: one model and one rate policy whatever the model's source
// (embedded or file), the replay, and what a result means for the exit code (docs/compare.md).
#pragma once

#include <string>

#include "diagnose/compare.hpp"

namespace CLI {
class App;
}

namespace driftless::cli {

/// The options both commands take.
struct CompareArgs {
  std::string log, model, out;
  bool resample = false;
  double block_s = 0.1;
  double threshold = 10.0;
};

/// Declares the options of CompareArgs on `cmd` (--log, --model, --out, --resample, --block,
/// --threshold), once for both commands; `a` must outlive the parse.
void add_compare_options(CLI::App& cmd, CompareArgs& a);

/// The model, options and replayed log of a comparison.
struct CompareSetup {
  diagnose::CompareModel model;
  diagnose::CompareOptions opt;
  diagnose::Replay replay;
};

/// Loads the model (embedded nominal MPU6050 without --model) and replays the log. One rate
/// policy: the model runs at the log's rate; a model file stating another sample_rate_hz is
/// said in a note; --resample resamples the log to the rate the model file states.
CompareSetup setup_compare(const CompareArgs& a);

/// Prints the verdict line, the selected effects and the noise-model changes.
void print_result(const diagnose::CompareResult& r);

/// Why a result cannot be stood behind ("" when it can): the residual has structure no effect
/// explains, or a selected fit is implausible.
std::string doubt(const diagnose::CompareResult& r);

/// The end both commands share: says where the report went; when doubt(r) has a reason, prints
/// it as "driftless COMMAND: why; see OUT/report.html" and returns 1, else `code`.
int finish_report(const char* command, const CompareArgs& a, const diagnose::CompareResult& r, int code);

}  // namespace driftless::cli
