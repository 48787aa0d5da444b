// driftless compare: the model against a measurement log (docs/compare.md).
#include <cstdio>
#include <memory>
#include <string>

#include <fmt/core.h>

#include "cli/command.hpp"
#include "cli/compare_run.hpp"
#include "diagnose/report.hpp"

namespace driftless::cli {
namespace {

struct Args {
  CompareArgs common;
  std::string before;
};

int run_compare(const Args& a) {
  Progress progress("compare");
  const CompareSetup s = setup_compare(a.common);
  progress.update(0.3, "replayed");
  diagnose::ReportExtras x;
  x.command = "compare";
  diagnose::CompareResult r = diagnose::compare(s.replay, s.model, s.opt);
  if (!a.before.empty()) {
    // before/after: the same log against the earlier model (the report's main part), then --model
    const diagnose::CompareModel old = diagnose::load_compare_model(a.before);
    diagnose::CompareResult r0 = diagnose::compare(s.replay, old, s.opt);
    x.after_model = s.model.source;
    x.applied.push_back("model changed from " + old.source);
    x.after = &r;
    diagnose::write_report(r0, a.common.out, x);
    fmt::print("before ({}): {}: {}\nafter  ({}): {}: {}\n", old.source, diagnose::verdict_id(r0.verdict), r0.statement,
               s.model.source, diagnose::verdict_id(r.verdict), r.statement);
  } else {
    diagnose::write_report(r, a.common.out, x);
    print_result(r);
  }
  progress.done();
  fmt::print("wrote {}/report.html and {}/diagnosis.json\n", a.common.out, a.common.out);
  if (const std::string why = doubt(r); !why.empty()) {
    fmt::print(stderr, "driftless compare: {}; see {}/report.html\n", why, a.common.out);
    return 1;
  }
  return 0;
}

const bool registered = register_command(50, [](CLI::App& app) {
  auto* cmd = app.add_subcommand("compare", "Compare the model with a measurement log: residual per channel, regime and "
                                            "window, whiteness and Allan deviation against the model's noise, and the "
                                            "missing effects by forward selection (docs/compare.md)");
  auto a = std::make_shared<Args>();
  cmd->add_option("--log", a->common.log, "Measurement log (CSV, driftless-log 1; gyro in deg/s)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--model", a->common.model, "Model or scenario YAML (its 'model:' block); default: embedded nominal MPU6050 "
                  "(datasheet noise, bias instability, turn-on bias, DLPF_CFG 3; scale, cross-axis, g-sensitivity, "
                  "temperature coefficients at zero; docs/compare.md). The model runs at the log's rate")
      ->check(CLI::ExistingFile);
  cmd->add_option("--before", a->before, "An earlier model YAML: report the residual before (this) and after (--model)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", a->common.out, "Output directory (report.html, diagnosis.json, plots/)")->required();
  cmd->add_flag("--resample", a->common.resample, "Resample the log to the sample_rate_hz the model file states (default: "
                "the model runs at the log's rate)");
  cmd->add_option("--block", a->common.block_s, "Block length of the residual fits, s (default 0.1)")->check(positive_number("s"));
  cmd->add_option("--threshold", a->common.threshold, "Evidence (2 ln L gain - ln(m) per parameter) above which an effect "
                  "is selected (default 10)")->check(CLI::NonNegativeNumber);
  return [a] { return run_compare(*a); };
});

}  // namespace
}  // namespace driftless::cli
