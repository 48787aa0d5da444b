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

struct CompareCommandArgs {
  CompareArgs common;
  std::string before;
};

int run_compare(const CompareCommandArgs& a) {
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
  return finish_report("compare", a.common, r, 0);
}

const bool registered_compare = register_command(50, [](CLI::App& app) {
  auto* cmd = app.add_subcommand("compare", "Compare the model with a measurement log: residual per channel, regime and "
                                            "window, whiteness and Allan deviation against the model's noise, and the "
                                            "missing effects by forward selection (docs/compare.md)");
  auto a = std::make_shared<CompareCommandArgs>();
  add_compare_options(*cmd, a->common);
  cmd->add_option("--before", a->before, "An earlier model YAML: report the residual before (this) and after (--model)")
      ->check(CLI::ExistingFile);
  return [a] { return run_compare(*a); };
});

}  // namespace
}  // namespace driftless::cli
