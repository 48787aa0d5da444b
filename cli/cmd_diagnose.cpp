// driftless diagnose: find the effect the model misses and (with --apply) write the model with it.
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

struct DiagnoseArgs {
  std::string log, model, out, apply;
  bool resample = false;
  double threshold = 10.0;
};

int run_diagnose(const DiagnoseArgs& a) {
  Progress progress("diagnose");
  diagnose::CompareModel model = a.model.empty() ? diagnose::default_compare_model() : diagnose::load_compare_model(a.model);
  diagnose::CompareOptions opt;
  opt.evidence_threshold = a.threshold;
  opt.replay.model_sample_rate_hz = model.sample_rate_hz;
  opt.replay.resample = a.resample;
  if (std::isfinite(model.latitude_deg)) opt.replay.default_latitude_deg = model.latitude_deg;
  const diagnose::Replay replay = diagnose::replay_log(a.log, opt.replay);
  for (const auto& n : replay.notes) fmt::print("note: {}\n", n);
  const diagnose::CompareResult r = diagnose::compare(replay, model, opt);
  progress.update(0.5, "compared");
  fmt::print("{}: {}\n", r.verdict, r.statement);
  int top = 0;
  for (const auto& c : r.ranking) {
    if (++top > 5) break;
    fmt::print("  {}. {:<22} sensor {:<4} axis {:<14} evidence {:>12.1f}  explains {:5.1f} %\n", top, c.effect, c.sensor, c.axis,
               c.evidence, 100.0 * c.explained_fraction);
  }
  if (!a.apply.empty()) {
    if (r.verdict != "missing_effect") {
      diagnose::write_report(r, a.out);
      throw std::runtime_error(fmt::format("--apply: nothing to apply ({}); {} not written", r.verdict, a.apply));
    }
    const diagnose::Candidate& best = r.ranking.front();
    diagnose::CompareModel updated = model;
    diagnose::apply_candidate(updated, best);
    diagnose::save_compare_model(updated, a.apply);
    updated.source = a.apply;
    const diagnose::CompareResult after = diagnose::compare(replay, updated, opt);
    diagnose::ReportExtras x{&after, a.apply, fmt::format("{} on sensor {} axis {}", best.effect, best.sensor, best.axis)};
    diagnose::write_report(r, a.out, x);
    fmt::print("wrote {} with {} added; after: {}: {}\n", a.apply, best.effect, after.verdict, after.statement);
  } else {
    diagnose::write_report(r, a.out);
  }
  progress.done();
  fmt::print("wrote {}/report.html and {}/diagnosis.json\n", a.out, a.out);
  return 0;
}

const bool registered = register_command(51, [](CLI::App& app) {
  auto* cmd = app.add_subcommand("diagnose", "Find the physical effect the model misses (ranked by evidence) and, with "
                                             "--apply, write the model with the winner added (docs/compare.md)");
  auto a = std::make_shared<DiagnoseArgs>();
  cmd->add_option("--log", a->log, "Measurement log (CSV, driftless-log 1; gyro in deg/s)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--model", a->model, "Model or scenario YAML; default: embedded nominal MPU6050 at 100 Hz (datasheet "
                  "noise, bias instability, turn-on bias; scale, cross-axis, g-sensitivity, "
                  "temperature coefficients at zero; docs/compare.md)")->check(CLI::ExistingFile);
  cmd->add_option("--out", a->out, "Output directory (report.html, diagnosis.json, plots/)")->required();
  cmd->add_option("--apply", a->apply, "Write the model with the best candidate's fitted parameters added to this YAML file");
  cmd->add_flag("--resample", a->resample, "Resample a log whose rate differs from the model's (else it is refused)");
  cmd->add_option("--threshold", a->threshold, "Evidence above which an effect is missing (default 10)");
  return [a] { return run_diagnose(*a); };
});

}  // namespace
}  // namespace driftless::cli
