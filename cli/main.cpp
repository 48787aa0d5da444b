// driftless: the command-line front. It sits above every folder and nothing includes it.
// Exit status (README "Exit status"): 0 success, 1 bad input or failed run, 2 usage error,
// 130/143 interrupted by SIGINT/SIGTERM.
#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <exception>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include <unistd.h>

#include <fmt/core.h>

#include "cli/command.hpp"

namespace driftless::cli {
namespace {

struct Registered {
  int order;
  CommandSetup setup;
  Interrupt interrupt;
};

std::vector<Registered>& registry() {
  static std::vector<Registered> commands;
  return commands;
}

std::atomic<bool> g_stop{false};
std::atomic<int> g_signal{0};

// the first SIGINT/SIGTERM asks the run to stop; the default action is back for a second one
extern "C" void on_signal(int sig) {
  g_signal.store(sig);
  g_stop.store(true);
  std::signal(sig, SIG_DFL);
}

double now_s() {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}

}  // namespace

bool register_command(int order, CommandSetup setup, Interrupt interrupt) {
  registry().push_back(Registered{order, std::move(setup), interrupt});
  return true;
}

const std::atomic<bool>& stop_requested() { return g_stop; }

int interrupted_exit_code() {
  if (!g_stop.load()) return 0;
  return g_signal.load() == SIGTERM ? kExitSigterm : kExitSigint;
}

Progress::Progress(std::string label)
    : label_(std::move(label)), tty_(::isatty(STDERR_FILENO) == 1), start_s_(now_s()) {}

Progress::~Progress() {
  if (tty_ && !finished_ && last_print_s_ >= 0) std::fputc('\n', stderr);
}

void Progress::update(double fraction, const std::string& detail) {
  if (!tty_) return;
  const double now = now_s();
  if (last_print_s_ >= 0 && now - last_print_s_ < 0.2) return;
  last_print_s_ = now;
  const double elapsed = now - start_s_;
  const double eta = fraction > 1e-6 ? elapsed * (1.0 - fraction) / fraction : 0.0;
  fmt::print(stderr, "\r{}  {:5.1f} %  {}  elapsed {:.0f} s  eta {:.0f} s   ", label_, 100.0 * fraction, detail,
             elapsed, eta);
  std::fflush(stderr);
}

void Progress::done(const std::string& detail) {
  finished_ = true;
  if (!tty_) return;
  fmt::print(stderr, "\r{}  100.0 %  {}  in {:.1f} s            \n", label_, detail, now_s() - start_s_);
}

namespace {

struct Runner {
  CLI::App* app;
  std::function<int()> run;
  Interrupt interrupt;
};

std::string command_list(const std::vector<Runner>& runners) {
  std::string out;
  for (const auto& r : runners) out += (out.empty() ? "" : ", ") + r.app->get_name();
  return out;
}

// the option name of an argument ("--out=x" -> "--out"), or empty for a value
std::string option_name(std::string_view arg) {
  if (arg.size() < 2 || arg[0] != '-' || arg == "--") return {};
  if (arg[1] != '-' && (arg[1] == '.' || (arg[1] >= '0' && arg[1] <= '9'))) return {};  // -5, -0.1
  return std::string(arg.substr(0, arg.find('=')));
}

// unknown command or option, found before CLI11 (whose messages for these are unreadable:
// "A subcommand is required" for a misspelt command). Empty when the arguments look right.
std::string usage_problem(int argc, char** argv, CLI::App& app, const std::vector<Runner>& runners) {
  const Runner* cmd = nullptr;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    const std::string opt = option_name(arg);
    if (cmd == nullptr) {
      if (!opt.empty()) continue;  // --help, --version
      for (const auto& r : runners) {
        if (r.app->get_name() == arg) cmd = &r;
      }
      if (cmd == nullptr) {
        return fmt::format("driftless: unknown command '{}'; the commands are {} (driftless --help)", arg,
                           command_list(runners));
      }
      continue;
    }
    if (!opt.empty() && cmd->app->get_option_no_throw(opt) == nullptr && opt != "-h" && opt != "--help") {
      return fmt::format("driftless {}: unknown option '{}' (driftless {} --help lists the options)",
                         cmd->app->get_name(), opt, cmd->app->get_name());
    }
  }
  (void)app;
  return {};
}

// CLI11's parse errors as one readable line naming the command
std::string parse_error_text(const CLI::ParseError& e, const std::vector<Runner>& runners) {
  std::string where = "driftless";
  for (const auto& r : runners) {
    if (r.app->parsed()) where += " " + r.app->get_name();
  }
  std::string what = e.what();
  if (what == "A subcommand is required") {
    what = "a command is required; the commands are " + command_list(runners);
  }
  return fmt::format("{}: {} ({} --help)", where, what, where);
}

int run_command(const Runner& r) {
  if (r.interrupt == Interrupt::kPolls) {
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
  }
  try {
    const int code = r.run();
    const int stopped = interrupted_exit_code();
    return stopped != 0 && r.interrupt == Interrupt::kPolls ? stopped : code;
  } catch (const std::exception& e) {
    fmt::print(stderr, "driftless {}: error: {}\n", r.app->get_name(), e.what());
    const int stopped = interrupted_exit_code();
    return stopped != 0 ? stopped : kExitFailed;
  }
}

}  // namespace
}  // namespace driftless::cli

int main(int argc, char** argv) {
  using namespace driftless::cli;
  CLI::App app{
      "DriftLess Twin: a physics-simulated digital twin of a dual-gyro bias-estimation box.\n"
      "Units: deg/s, deg, s, m/s^2, degC in every file and option (docs/).\n"
      "Exit status: 0 success, 1 bad input or failed run, 2 usage error, 130/143 interrupted."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "driftless 0.1.0");

  auto& cmds = registry();
  std::stable_sort(cmds.begin(), cmds.end(), [](const auto& a, const auto& b) { return a.order < b.order; });
  std::vector<Runner> runners;
  for (auto& c : cmds) {
    const std::size_t before = app.get_subcommands({}).size();
    auto run = c.setup(app);
    auto subs = app.get_subcommands({});
    if (subs.size() > before) runners.push_back(Runner{subs.back(), std::move(run), c.interrupt});
  }

  if (const std::string problem = usage_problem(argc, argv, app, runners); !problem.empty()) {
    fmt::print(stderr, "{}\n", problem);
    return kExitUsage;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help, --version: printed, exit 0
  } catch (const CLI::ParseError& e) {
    fmt::print(stderr, "{}\n", parse_error_text(e, runners));
    return kExitUsage;
  }
  for (const auto& r : runners) {
    if (r.app->parsed()) return run_command(r);
  }
  return kExitUsage;
}
