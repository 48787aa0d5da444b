// driftless demo: the main job. Runs a short pipeline on the built-in default scenario into
// DIR, checks that each output holds what it claims (demo_checks.hpp) and says where to look,
// or what failed and why (non-zero exit).
#include <cerrno>
#include <filesystem>
#include <stdexcept>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/core.h>

#include "cli/command.hpp"
#include "estimator/output_file.hpp"
#include "cli/demo_checks.hpp"
#include "twin/scenario.hpp"
#include "twin/simulator.hpp"

namespace driftless::cli {
namespace {

struct DemoArgs {
  std::string out_dir = "out/demo";
  double duration_s = 600.0;
  bool video = true;
};

struct DemoContext {
  std::filesystem::path dir;
  bool video = true;
  twin::Scenario scenario;
  std::uint64_t log_rows = 0;        // rows the simulation wrote
  std::vector<OutputCheck> checks;   // what each output holds, printed at the end
};

constexpr double kVideoSpeed = 10.0;  // x real time of the demo's time-lapse
constexpr double kVideoFps = 30.0;

// step 1: simulate the built-in default scenario (short run)
bool step_simulate(DemoContext& c) {
  std::filesystem::create_directories(c.dir / "sim");
  const auto resolved = c.dir / "sim" / "scenario.resolved.yaml";
  io::write_file(resolved, twin::emit_scenario(c.scenario));
  Progress progress("demo: simulate");
  const double dur = c.scenario.duration_s;
  const auto r = twin::simulate_to_log(c.scenario, c.dir / "sim" / "log.csv", [&](double f) {
    progress.update(f, fmt::format("{:.0f} / {:.0f} s sim", f * dur, dur));
    return !stop_requested().load();
  });
  if (r.complete) progress.done();
  c.log_rows = r.rows;
  return r.complete;
}

// runs `driftless <args...>` (this same program) as a user would; true on exit status 0
bool run_self(const std::vector<std::string>& args) {
  std::vector<std::string> argv_s = {"/proc/self/exe"};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& x : argv_s) argv.push_back(x.data());
  argv.push_back(nullptr);
  std::string shown = "driftless";
  for (const auto& x : args) shown += " " + x;
  fmt::print("  $ {}\n", shown);
  std::fflush(stdout);
  pid_t pid = 0;
  if (posix_spawn(&pid, "/proc/self/exe", nullptr, nullptr, argv.data(), environ) != 0) {
    throw std::runtime_error("demo: cannot start '" + shown + "'");
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw std::runtime_error("demo: lost track of '" + shown + "'");
  }
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

// step 2: the DriftLess estimator on the log, with the paper's Fig. 4/5/9 plots
bool step_estimate(DemoContext& c) {
  const auto out = c.dir / "estimate";
  return run_self({"estimate", "--log", (c.dir / "sim" / "log.csv").string(), "--out", out.string(), "--plot"});
}

// step 3: model versus measurement against the model that produced the log (docs/compare.md)
bool step_report(DemoContext& c) {
  const auto out = c.dir / "report";
  return run_self({"diagnose", "--log", (c.dir / "sim" / "log.csv").string(), "--model",
                   (c.dir / "sim" / "scenario.resolved.yaml").string(), "--out", out.string()});
}

// step 4: an off-screen rendered time-lapse of the run (docs/render.md)
bool step_video(DemoContext& c) {
  if (!c.video) return true;
  return run_self({"render", "--log", (c.dir / "sim" / "log.csv").string(), "--out", (c.dir / "video.mp4").string(),
                   "--speed", fmt::format("{:g}", kVideoSpeed), "--fps", fmt::format("{:g}", kVideoFps)});
}

// what each output holds, in the order a user would open them
std::vector<OutputCheck> check_outputs(const DemoContext& c) {
  std::vector<OutputCheck> all = {check_log(c.dir / "sim" / "log.csv", c.log_rows)};
  for (auto& x : check_estimate(c.dir / "estimate")) all.push_back(std::move(x));
  for (auto& x : check_figures(c.dir / "estimate")) all.push_back(std::move(x));
  all.push_back(check_report(c.dir / "report"));
  if (c.video) {
    // the time-lapse plays every data second at x10 and adds flips at x1: never fewer frames
    const auto min_frames = static_cast<std::uint64_t>(std::floor(c.scenario.duration_s / kVideoSpeed * kVideoFps));
    all.push_back(check_video(c.dir / "video.mp4", min_frames));
  }
  return all;
}

// prints the checks; returns the number that failed
int report_checks(const std::vector<OutputCheck>& checks) {
  int failed = 0;
  fmt::print("checks (does each output hold what it claims?):\n");
  for (const auto& k : checks) {
    fmt::print("  {:4}  {}: {}: {}\n", k.ok ? "ok" : "FAIL", k.path.string(), k.claim, k.detail);
    failed += k.ok ? 0 : 1;
  }
  if (failed == 0) {
    fmt::print("done. Look at:\n");
    for (const auto& k : checks) fmt::print("  {}\n", k.path.string());
  } else {
    std::fflush(stdout);
    fmt::print(stderr, "driftless demo: {} of {} outputs do not hold what they claim (FAIL above)\n", failed,
               checks.size());
  }
  return failed;
}

int run_demo(const DemoArgs& a) {
  DemoContext c;
  c.dir = a.out_dir;
  c.video = a.video;
  c.scenario = twin::default_scenario();
  c.scenario.duration_s = a.duration_s;
  c.scenario.validate();
  fmt::print("driftless demo: scenario '{}' ({}), {:.0f} s simulated, into {}\n", c.scenario.name,
             c.scenario.description, c.scenario.duration_s, c.dir.string());
  using Step = bool (*)(DemoContext&);
  const std::vector<std::pair<const char*, Step>> steps = {
      {"simulate", step_simulate},
      {"estimate", step_estimate},
      {"report", step_report},
      {"video", step_video},
  };
  // every step after the simulation runs even if one fails: the checks say what each left behind
  bool all_ran = true;
  for (const auto& [name, step] : steps) {
    const bool ran = step(c);
    if (stop_requested().load()) return 130;
    if (!ran) {
      fmt::print(stderr, "driftless demo: step '{}' failed (see its message above)\n", name);
      if (std::string(name) == "simulate") return 1;
      all_ran = false;
    }
  }
  const int failed = report_checks(check_outputs(c));
  return failed == 0 && all_ran ? 0 : 1;
}

const bool registered_demo = register_command(0, [](CLI::App& app) {
  auto* cmd = app.add_subcommand("demo", "The main job on the built-in default scenario: simulate, estimate "
                                         "(with plots), model-vs-measurement report and a rendered video into "
                                         "DIR; then checks that each output holds what it claims and says where "
                                         "to look (exit 1 when one does not)");
  auto args = std::make_shared<DemoArgs>();
  cmd->add_option("--out", args->out_dir, "Output directory (default out/demo)");
  cmd->add_option("--duration", args->duration_s, "Simulated duration in s (default 600)")
      ->check(positive_number("s"));
  cmd->add_flag("!--no-video", args->video, "Skip the rendered video step");
  return [args] { return run_demo(*args); };
}, Interrupt::kPolls);

}  // namespace
}  // namespace driftless::cli
