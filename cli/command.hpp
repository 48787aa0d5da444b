// The driftless program's subcommand registry, exit codes and option checks. Each cmd_*.cpp
// registers itself, so adding a command touches no shared file.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>

namespace driftless::cli {

/// The exit-code scheme (README "Exit status"): one meaning per number for every command.
enum ExitCode : int {
  kExitOk = 0,         // success
  kExitFailed = 1,     // bad input (a file, a value) or a run that failed (a full disk, a device lost)
  kExitUsage = 2,      // usage error: unknown command or option, a missing or malformed option value
  kExitSigint = 130,   // interrupted by SIGINT (Ctrl-C): outputs say complete: false and where they stopped
  kExitSigterm = 143,  // interrupted by SIGTERM
};

/// Adds a subcommand to `app`; the returned callback runs it after parsing and gives the exit code.
using CommandSetup = std::function<std::function<int()>(CLI::App& app)>;

/// How a command meets SIGINT/SIGTERM. kPolls: it polls stop_requested() and finishes its outputs
/// as incomplete (a second signal kills it at once); kDefault: the signal ends the process (its
/// outputs are still under their partial names, so nothing looks complete).
enum class Interrupt { kDefault, kPolls };

/// Registers a subcommand; `order` sorts the help listing. Call from a static initializer.
bool register_command(int order, CommandSetup setup, Interrupt interrupt = Interrupt::kDefault);

/// Set by SIGINT/SIGTERM; long-running commands poll it and finish their outputs cleanly.
const std::atomic<bool>& stop_requested();
/// The exit code of an interrupted run: 130 after SIGINT, 143 after SIGTERM; 0 when not stopped.
int interrupted_exit_code();

/// Readable number checks for options (CLI11's own print a 309-digit range): "--duration: expected
/// a number > 0 (s), got '-5'".
CLI::Validator positive_number(const std::string& unit);
CLI::Validator non_negative_number(const std::string& unit);
/// A seed: a whole number 0 .. 18446744073709551615 (a sign is refused, not wrapped around).
CLI::Validator seed_number();
/// A count: a whole number lo .. hi (a sign is refused, not wrapped around into an unsigned option).
CLI::Validator count_number(std::uint64_t lo, std::uint64_t hi);

/// Before a run writes about `bytes` under `dir`: a warning on stderr when the file system has
/// less free space (the run would stop with "No space left on device"). Returns true if it warned.
bool warn_if_disk_too_small(const std::string& command, const std::filesystem::path& dir, double bytes,
                            const std::string& what);

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
