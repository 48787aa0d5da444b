// driftless diagnose: find the effects the model misses and (with --apply) write the model with
// all of them, then compare again (docs/compare.md).
#include <cstdio>
#include <memory>
#include <string>

#include <fmt/core.h>

#include "cli/command.hpp"
#include "cli/compare_run.hpp"
#include "diagnose/apply.hpp"
#include "diagnose/report.hpp"

namespace driftless::cli {
namespace {

struct DiagnoseArgs {
  CompareArgs common;
  std::string apply;
};

// writes the selected set into a copy of the model, saves it, compares again; the exit code
// says whether the written model explains the log
int apply_and_check(const DiagnoseArgs& a, const CompareSetup& s, const diagnose::CompareResult& r, diagnose::ReportExtras& x) {
  diagnose::CompareModel updated = s.model;
  const diagnose::ApplyReport rep = diagnose::apply_result(updated, r);
  diagnose::save_compare_model(updated, a.apply);
  updated.source = a.apply;
  const diagnose::CompareResult after = diagnose::compare(s.replay, updated, s.opt);
  x.after = &after;
  x.after_model = a.apply;
  x.applied = rep.written;
  x.skipped = rep.skipped;
  diagnose::write_report(r, a.common.out, x);
  if (rep.written.empty()) fmt::print("nothing to apply; wrote {} unchanged\n", a.apply);
  for (const auto& w : rep.written) fmt::print("wrote {}\n", w);
  for (const auto& w : rep.skipped) fmt::print(stderr, "not written: {}\n", w);
  fmt::print("{}: after --apply: {}: {}\n", a.apply, diagnose::verdict_id(after.verdict), after.statement);
  if (!rep.complete()) {
    fmt::print(stderr, "driftless diagnose: {} holds only part of the selected effects (see above)\n", a.apply);
    return 1;
  }
  if (after.verdict != diagnose::Verdict::kConsistent) {
    fmt::print(stderr, "driftless diagnose: the model written to {} does not yet explain the log ({}); run diagnose "
               "again with --model {}\n", a.apply, diagnose::verdict_id(after.verdict), a.apply);
    return 1;
  }
  return 0;
}

int run_diagnose(const DiagnoseArgs& a) {
  Progress progress("diagnose");
  const CompareSetup s = setup_compare(a.common);
  const diagnose::CompareResult r = diagnose::compare(s.replay, s.model, s.opt);
  progress.update(0.5, "compared");
  print_result(r);
  diagnose::ReportExtras x;
  x.command = "diagnose";
  int code = 0;
  if (!a.apply.empty()) {
    code = apply_and_check(a, s, r, x);
  } else {
    diagnose::write_report(r, a.common.out, x);
  }
  progress.done();
  return finish_report("diagnose", a.common, r, code);
}

const bool registered_diagnose = register_command(51, [](CLI::App& app) {
  auto* cmd = app.add_subcommand("diagnose", "Find the effects the model misses (forward selection: physical and signal-chain "
                                             "effects first, then the noise model) and, with --apply, write the model with "
                                             "all of them and compare again (docs/compare.md)");
  auto a = std::make_shared<DiagnoseArgs>();
  add_compare_options(*cmd, a->common);
  cmd->add_option("--apply", a->apply, "Write the model with every selected effect and noise-model change to this YAML "
                  "file, then compare again; exit 1 unless the new model is consistent with the log");
  return [a] { return run_diagnose(*a); };
});

}  // namespace
}  // namespace driftless::cli
