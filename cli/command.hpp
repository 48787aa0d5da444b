// The driftless program's subcommand registry. Each cmd_*.cpp registers itself, so adding a
// command touches no shared file.
#pragma once

#include <atomic>
#include <functional>
#include <string>

#include <CLI/CLI.hpp>

namespace driftless::cli {

/// Adds a subcommand to `app`; the returned callback runs it after parsing and gives the exit code.
using CommandSetup = std::function<std::function<int()>(CLI::App& app)>;

/// Registers a subcommand; `order` sorts the help listing. Call from a static initializer.
bool register_command(int order, CommandSetup setup);

/// Set by SIGINT/SIGTERM; long-running commands poll it and finish their outputs cleanly.
const std::atomic<bool>& stop_requested();

/// Progress on a terminal: "label  43.2 %  1234 s sim  eta 12 s". Silent when stderr is no tty.
class Progress {
 public:
  explicit Progress(std::string label);
  ~Progress();
  /// fraction in [0,1]; `detail` is appended (e.g. simulated seconds).
  void update(double fraction, const std::string& detail = {});
  void done(const std::string& detail = {});

 private:
  std::string label_;
  bool tty_;
  double start_s_;
  double last_print_s_ = -1.0;
  bool finished_ = false;
};

}  // namespace driftless::cli
