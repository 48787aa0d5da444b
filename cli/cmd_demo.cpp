// driftless demo: the main job. Runs a short pipeline on the built-in default scenario into
// DIR and says where to look. Each step is one function; later steps (estimate, report, video)
// append to the list.
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
  if (!run_self({"estimate", "--log", (c.dir / "sim" / "log.csv").string(), "--out", out.string(), "--plot"}))
    return false;
  c.outputs.push_back(fmt::format("{}: bias estimates, attitude drift with/without DriftLess, NEES (docs/estimator.md)",
                                  (out / "summary.json").string()));
  c.outputs.push_back(fmt::format("{}: Fig. 4 bias estimate vs truth (also fig5_allan.png, fig9_attitude.png)",
                                  (out / "fig4_bias.png").string()));
  return true;
}

// step 3: model versus measurement against the model that produced the log (docs/compare.md)
bool step_report(DemoContext& c) {
  const auto out = c.dir / "report";
  if (!run_self({"diagnose", "--log", (c.dir / "sim" / "log.csv").string(), "--model",
                 (c.dir / "sim" / "scenario.resolved.yaml").string(), "--out", out.string()}))
    return false;
  c.outputs.push_back(fmt::format("{}: model vs measurement report, open in a browser (diagnosis.json beside it)",
                                  (out / "report.html").string()));
  return true;
}

// step 4: an off-screen rendered time-lapse of the run (docs/render.md)
bool step_video(DemoContext& c) {
  if (!c.video) return true;
  const auto out = c.dir / "video.mp4";
  if (!run_self({"render", "--log", (c.dir / "sim" / "log.csv").string(), "--out", out.string(), "--speed", "10"}))
    return false;
  c.outputs.push_back(fmt::format("{}: 640x480 time-lapse (x10, flips shown at x1 now and then)", out.string()));
  return true;
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
  for (const auto& [name, step] : steps) {
    if (!step(c)) {
      fmt::print(stderr, "driftless demo: step '{}' did not finish (see its message above)\n", name);
      return stop_requested().load() ? 130 : 1;
    }
  }
  fmt::print("done. Look at:\n");
  for (const auto& o : c.outputs) fmt::print("  {}\n", o);
  return 0;
}

const bool registered = register_command(0, [](CLI::App& app) {
  auto* cmd = app.add_subcommand("demo", "The main job on the built-in default scenario: simulate, estimate "
                                         "(with plots), model-vs-measurement report and a rendered video into "
                                         "DIR, then where to look");
  auto args = std::make_shared<DemoArgs>();
  cmd->add_option("--out", args->out_dir, "Output directory (default out/demo)");
  cmd->add_option("--duration", args->duration_s, "Simulated duration in s (default 600)")
      ->check(positive_number("s"));
  cmd->add_flag("!--no-video", args->video, "Skip the rendered video step");
  return [args] { return run_demo(*args); };
}, Interrupt::kPolls);

}  // namespace
}  // namespace driftless::cli
