// driftless demo: the main job. Runs a short pipeline on the built-in default scenario into
// DIR and says where to look. Each step is one function; later steps (estimate, report, video)
// append to the list.
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "cli/command.hpp"
#include "twin/scenario.hpp"
#include "twin/simulator.hpp"

namespace driftless::cli {
namespace {

struct DemoArgs {
  std::string out_dir = "out/demo";
  double duration_s = 180.0;
};

struct DemoContext {
  std::filesystem::path dir;
  twin::Scenario scenario;
  std::vector<std::string> outputs;  // "path: what it is", printed at the end
};

// step 1: simulate the built-in default scenario (short run)
bool step_simulate(DemoContext& c) {
  std::filesystem::create_directories(c.dir / "sim");
  const auto resolved = c.dir / "sim" / "scenario.resolved.yaml";
  {
    std::ofstream y(resolved, std::ios::binary);
    y << twin::emit_scenario(c.scenario);
  }
  Progress progress("demo: simulate");
  const double dur = c.scenario.duration_s;
  const auto r = twin::simulate_to_log(c.scenario, c.dir / "sim" / "log.csv", [&](double f) {
    progress.update(f, fmt::format("{:.0f} / {:.0f} s sim", f * dur, dur));
    return !stop_requested().load();
  });
  if (r.complete) progress.done();
  c.outputs.push_back(fmt::format("{}: simulated measurement log, {} rows at {} Hz (docs/log-format.md)",
                                  (c.dir / "sim" / "log.csv").string(), r.rows, c.scenario.sample_rate_hz));
  c.outputs.push_back(fmt::format("{}: the scenario with every default explicit (docs/scenario.md)",
                                  resolved.string()));
  return r.complete;
}

int run_demo(const DemoArgs& a) {
  DemoContext c;
  c.dir = a.out_dir;
  c.scenario = twin::default_scenario();
  c.scenario.duration_s = a.duration_s;
  c.scenario.validate();
  fmt::print("driftless demo: scenario '{}' ({}), {:.0f} s simulated, into {}\n", c.scenario.name,
             c.scenario.description, c.scenario.duration_s, c.dir.string());
  using Step = bool (*)(DemoContext&);
  const std::vector<std::pair<const char*, Step>> steps = {
      {"simulate", step_simulate},
  };
  for (const auto& [name, step] : steps) {
    if (!step(c)) {
      fmt::print(stderr, "driftless demo: stopped during step '{}'\n", name);
      return 130;
    }
  }
  fmt::print("done. Look at:\n");
  for (const auto& o : c.outputs) fmt::print("  {}\n", o);
  return 0;
}

const bool registered = register_command(0, [](CLI::App& app) {
  auto* cmd = app.add_subcommand("demo", "The main job: a short simulation of the built-in default scenario "
                                         "into DIR, then where to look");
  auto args = std::make_shared<DemoArgs>();
  cmd->add_option("--out", args->out_dir, "Output directory (default out/demo)");
  cmd->add_option("--duration", args->duration_s, "Simulated duration in s (default 180)")
      ->check(CLI::PositiveNumber);
  return [args] { return run_demo(*args); };
});

}  // namespace
}  // namespace driftless::cli
