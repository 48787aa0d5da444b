// driftless compare: the model against a measurement log (docs/compare.md).
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include <fmt/core.h>

#include "cli/command.hpp"
#include "diagnose/compare.hpp"
#include "diagnose/report.hpp"

namespace driftless::cli {
namespace {

struct CompareArgs {
  std::string log, model, before, out;
  bool resample = false;
  double block_s = 0.1;
  double threshold = 10.0;
};

int run_compare(const CompareArgs& a) {
  Progress progress("compare");
  diagnose::CompareModel model = a.model.empty() ? diagnose::default_compare_model() : diagnose::load_compare_model(a.model);
  diagnose::CompareOptions opt;
  opt.block_s = a.block_s;
  opt.evidence_threshold = a.threshold;
  opt.replay.model_sample_rate_hz = model.sample_rate_hz;
  opt.replay.resample = a.resample;
  if (std::isfinite(model.latitude_deg)) opt.replay.default_latitude_deg = model.latitude_deg;
  const diagnose::Replay replay = diagnose::replay_log(a.log, opt.replay);
  for (const auto& n : replay.notes) fmt::print("note: {}\n", n);
  progress.update(0.3, "replayed");
  if (!a.before.empty()) {
    // before/after: the same log against the earlier model, then the given one
    const diagnose::CompareModel old = diagnose::load_compare_model(a.before);
    const diagnose::CompareResult r0 = diagnose::compare(replay, old, opt);
    const diagnose::CompareResult r1 = diagnose::compare(replay, model, opt);
    diagnose::ReportExtras x{&r1, model.source, "model changed from " + old.source};
    diagnose::write_report(r0, a.out, x);
    fmt::print("before ({}): {}\nafter  ({}): {}\n", old.source, r0.statement, model.source, r1.statement);
  } else {
    const diagnose::CompareResult r = diagnose::compare(replay, model, opt);
    diagnose::write_report(r, a.out);
    fmt::print("{}: {}\n", r.verdict, r.statement);
  }
  progress.done();
  fmt::print("wrote {}/report.html and {}/diagnosis.json\n", a.out, a.out);
  return 0;
}

const bool registered = register_command(50, [](CLI::App& app) {
  auto* cmd = app.add_subcommand("compare", "Compare the model with a measurement log: residual per channel, regime and "
                                            "window, whiteness and Allan deviation against the model's noise, and a ranking "
                                            "of candidate missing effects (docs/compare.md)");
  auto a = std::make_shared<CompareArgs>();
  cmd->add_option("--log", a->log, "Measurement log (CSV, driftless-log 1; gyro in deg/s)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--model", a->model, "Model or scenario YAML (its 'model:' block); default: embedded nominal MPU6050 at "
                  "100 Hz (datasheet noise, bias instability, turn-on bias; scale, cross-axis, "
                  "g-sensitivity, temperature coefficients at zero; docs/compare.md)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--before", a->before, "An earlier model YAML: report the residual before (this) and after (--model)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", a->out, "Output directory (report.html, diagnosis.json, plots/)")->required();
  cmd->add_flag("--resample", a->resample, "Resample a log whose rate differs from the model's (else it is refused)");
  cmd->add_option("--block", a->block_s, "Block length of the residual fits, s (default 0.1)")->check(positive_number("s"));
  cmd->add_option("--threshold", a->threshold, "Evidence (2 ln L gain - ln(n) per parameter) above which an effect is missing (default 10)");
  return [a] { return run_compare(*a); };
});

}  // namespace
}  // namespace driftless::cli
