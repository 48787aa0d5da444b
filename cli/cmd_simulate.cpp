// driftless simulate: run a scenario in the MuJoCo twin and write DIR/log.csv and
// DIR/scenario.resolved.yaml.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <fmt/core.h>

#include "cli/command.hpp"
#include "estimator/log.hpp"
#include "estimator/output_file.hpp"
#include "twin/scenario.hpp"
#include "twin/simulator.hpp"

namespace driftless::cli {
namespace {

struct SimulateArgs {
  std::string scenario;  // file or built-in name; empty: the embedded default
  std::string out_dir;
  std::optional<double> duration_s;
  std::optional<std::uint64_t> seed;
};

int run_simulate(const SimulateArgs& a) {
  twin::Scenario sc = a.scenario.empty() ? twin::default_scenario() : twin::load_scenario(a.scenario);
  if (a.duration_s) sc.duration_s = *a.duration_s;
  if (a.seed) sc.seed = *a.seed;
  sc.validate();

  const std::filesystem::path dir(a.out_dir);
  std::filesystem::create_directories(dir);
  warn_if_disk_too_small("simulate", dir,
                         static_cast<double>(sc.total_samples()) * log::estimated_row_bytes(twin::Simulator::fields()),
                         "log.csv");
  io::write_file(dir / "scenario.resolved.yaml", twin::emit_scenario(sc));
  Progress progress(fmt::format("simulate {}", sc.name));
  const double dur = sc.duration_s;
  const auto r = twin::simulate_to_log(sc, dir / "log.csv", [&](double f) {
    progress.update(f, fmt::format("{:.0f} / {:.0f} s sim", f * dur, dur));
    return !stop_requested().load();
  });
  if (r.complete) {
    progress.done(fmt::format("{:.0f} s sim", dur));
  }
  fmt::print("{}: {} rows{}; {}\n", (dir / "log.csv").string(), r.rows,
             r.complete ? "" : " (stopped: log marked complete: false)",
             (dir / "scenario.resolved.yaml").string());
  return r.complete ? kExitOk : interrupted_exit_code();
}

const bool registered_simulate = register_command(10, [](CLI::App& app) {
  auto* cmd = app.add_subcommand("simulate",
                                 "Simulate a scenario in the MuJoCo twin: writes DIR/log.csv (docs/log-format.md) "
                                 "and DIR/scenario.resolved.yaml (docs/scenario.md)");
  auto args = std::make_shared<SimulateArgs>();
  cmd->add_option("--scenario", args->scenario,
                  "Scenario YAML file, or a built-in name (default, static, pan_tilt, vehicle, ship); "
                  "default: the built-in default scenario");
  cmd->add_option("--out", args->out_dir, "Output directory (created if missing)")->required();
  cmd->add_option_function<double>(
         "--duration", [args](double v) { args->duration_s = v; },
         "Simulated duration in s (overrides the scenario's duration_s)")
      ->check(positive_number("s"));
  cmd->add_option_function<std::uint64_t>(
      "--seed", [args](std::uint64_t v) { args->seed = v; },
      "Random seed 0 .. 2^64-1 (overrides the scenario's seed); the same seed gives a byte-identical log")
      ->check(seed_number());
  return [args] { return run_simulate(*args); };
}, Interrupt::kPolls);

}  // namespace
}  // namespace driftless::cli
