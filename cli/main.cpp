// driftless: the command-line front. It sits above every folder and nothing includes it.
#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <exception>
#include <utility>
#include <vector>

#include <unistd.h>

#include <fmt/core.h>

#include "cli/command.hpp"

namespace driftless::cli {
namespace {

std::vector<std::pair<int, CommandSetup>>& registry() {
  static std::vector<std::pair<int, CommandSetup>> commands;
  return commands;
}

std::atomic<bool> g_stop{false};

extern "C" void on_signal(int) { g_stop.store(true); }

double now_s() {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}

}  // namespace

bool register_command(int order, CommandSetup setup) {
  registry().emplace_back(order, std::move(setup));
  return true;
}

const std::atomic<bool>& stop_requested() { return g_stop; }

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
  fmt::print(stderr, "\r{}  {:5.1f} %  {}  elapsed {:.0f} s  eta {:.0f} s   ", label_,
             100.0 * fraction, detail, elapsed, eta);
  std::fflush(stderr);
}

void Progress::done(const std::string& detail) {
  finished_ = true;
  if (!tty_) return;
  fmt::print(stderr, "\r{}  100.0 %  {}  in {:.1f} s            \n", label_, detail,
             now_s() - start_s_);
}

}  // namespace driftless::cli

int main(int argc, char** argv) {
  using namespace driftless::cli;
  CLI::App app{
      "DriftLess Twin: a physics-simulated digital twin of a dual-gyro bias-estimation box.\n"
      "Units: deg/s, deg, s, m/s^2, degC in every file and option (docs/)."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "driftless 0.1.0");

  auto& cmds = registry();
  std::stable_sort(cmds.begin(), cmds.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::pair<CLI::App*, std::function<int()>>> runners;
  for (auto& [order, setup] : cmds) {
    const std::size_t before = app.get_subcommands({}).size();
    auto run = setup(app);
    auto subs = app.get_subcommands({});
    if (subs.size() > before) runners.emplace_back(subs.back(), std::move(run));
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  for (auto& [sub, run] : runners) {
    if (!sub->parsed()) continue;
    try {
      return run();
    } catch (const std::exception& e) {
      fmt::print(stderr, "driftless {}: error: {}\n", sub->get_name(), e.what());
      return 1;
    }
  }
  return 2;
}
