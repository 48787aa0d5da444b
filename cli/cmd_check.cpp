// driftless check: validate a measurement log and summarise what it holds.
#include <cmath>
#include <limits>
#include <string>

#include <fmt/core.h>

#include "cli/command.hpp"
#include "estimator/log.hpp"

namespace driftless::cli {
namespace {

int run_check(const std::string& path) {
  log::LogReader reader(path);
  Sample s;
  double t0 = kNaN, t1 = kNaN;
  double min_dt = std::numeric_limits<double>::infinity(), max_dt = 0.0;
  double prev = kNaN;
  while (reader.next(s)) {
    if (std::isnan(t0)) t0 = s.t_s;
    if (!std::isnan(prev)) {
      min_dt = std::min(min_dt, s.t_s - prev);
      max_dt = std::max(max_dt, s.t_s - prev);
    }
    prev = t1 = s.t_s;
  }
  const auto& meta = reader.metadata();
  fmt::print("{}: driftless log, {} rows", path, reader.rows_read());
  if (reader.rows_read() > 0) fmt::print(", t = {:.3f} .. {:.3f} s", t0, t1);
  fmt::print("\n");
  for (const auto& [k, v] : meta.entries()) fmt::print("  {}: {}\n", k, v);
  if (reader.rows_read() > 1) fmt::print("  sample interval: {:.6f} .. {:.6f} s\n", min_dt, max_dt);
  fmt::print("  columns: {}\n", reader.columns().size());
  fmt::print("  optional groups:{}{}{}{}{}{}{}\n", (reader.fields() & kFieldRefQ) ? " ref_q" : "",
             (reader.fields() & kFieldRefP) ? " ref_p" : "",
             (reader.fields() & kFieldAccel) ? " accel" : "",
             (reader.fields() & kFieldTemp) ? " temp" : "",
             (reader.fields() & kFieldTrueBias) ? " true_bias" : "",
             (reader.fields() & kFieldTrueRate) ? " true_rate" : "",
             (reader.fields() & kFieldTruePlat) ? " true_plat" : "");
  for (const auto& e : reader.events()) fmt::print("  event (line {}): {}\n", e.line, e.text);
  if (reader.rows_with_missing_gyro() > 0) {
    fmt::print("  warning: {} rows have a missing or NaN gyro value\n",
               reader.rows_with_missing_gyro());
  }
  if (reader.dropped_truncated_row()) fmt::print("  warning: last row was cut off and dropped\n");
  if (!meta.complete()) {
    fmt::print("  warning: the log says 'complete: false' ({})\n",
               meta.get("incomplete_reason").value_or("no reason given"));
  }
  return 0;
}

const bool registered = register_command(90, [](CLI::App& app) {
  auto* cmd = app.add_subcommand("check", "Validate a measurement log (docs/log-format.md) and "
                                          "summarise it; exits non-zero on a malformed log");
  auto path = std::make_shared<std::string>();
  cmd->add_option("--log", *path, "Measurement log (CSV, driftless-log 1)")
      ->required()
      ->check(CLI::ExistingFile);
  return [path] { return run_check(*path); };
});

}  // namespace
}  // namespace driftless::cli
