// driftless check: validate a measurement log (the same validation every reader applies,
// docs/log-format.md "Validation") and summarise what it holds.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <fmt/core.h>

#include "cli/command.hpp"
#include "cli/estimate_health.hpp"
#include "estimator/health.hpp"
#include "estimator/log.hpp"
#include "estimator/numbers.hpp"

namespace driftless::cli {
namespace {

struct Span {
  double t0 = kNaN, t1 = kNaN;
  double min_dt = std::numeric_limits<double>::infinity(), max_dt = 0.0;
};

std::string groups_text(std::uint32_t fields) {
  static constexpr std::pair<std::uint32_t, const char*> kGroups[] = {
      {kFieldRefQ, "ref_q"},         {kFieldRefP, "ref_p"},         {kFieldAccel, "accel"},
      {kFieldTemp, "temp"},          {kFieldTrueBias, "true_bias"}, {kFieldTrueRate, "true_rate"},
      {kFieldTruePlat, "true_plat"},
  };
  std::string out;
  for (const auto& [bit, name] : kGroups) {
    if ((fields & bit) != 0) out += std::string(" ") + name;
  }
  return out.empty() ? " none" : out;
}

// the findings that make the log unusable as it is (check exits 1): no data rows, stamps in
// another unit than seconds; printed first, each with its fix
bool print_unusable(const log::LogReader& reader) {
  if (reader.rows_read() == 0) {
    fmt::print("  error: the log has no data rows (a header only): nothing to estimate; check that the logger "
               "wrote its samples\n");
    return true;
  }
  const double median_hz = reader.stamp_rate_median_hz(), stated_hz = reader.metadata().sample_rate_hz();
  const double to_s = median_hz > 0.0 ? est::stamp_unit_to_s(1.0 / median_hz, reader.rows_read()) : kNaN;
  if (std::isnan(to_s)) return false;
  if (std::isfinite(stated_hz)) {
    fmt::print("  error: the stamps step {:.6g} \"s\" (median interval) where sample_rate_hz says {:g} Hz: t is in "
               "{}? divide t by {:g}\n",
               1.0 / median_hz, stated_hz, to_s == 1e-3 ? "milliseconds" : to_s == 1e-6 ? "microseconds" : "nanoseconds",
               1.0 / to_s);
  } else {
    fmt::print("  error: {}\n", stamp_unit_text(1.0 / median_hz, to_s));
  }
  return true;
}

void print_findings(const log::LogReader& reader) {
  for (const auto& e : reader.events()) fmt::print("  event (line {}): {}\n", e.line, e.text);
  const double stated_hz = reader.metadata().sample_rate_hz();
  if (est::stamp_rate_off(stated_hz, reader.stamp_rate_median_hz(), reader.stamp_rate_mean_hz())) {
    fmt::print("  warning: sample_rate_hz says {:g} Hz, but the stamps step {:.6g} s ({:.6g} Hz; {:.6g} Hz from their "
               "mean interval): fix the sample_rate_hz line, or convert t to seconds\n",
               stated_hz, 1.0 / reader.stamp_rate_median_hz(), reader.stamp_rate_median_hz(),
               reader.stamp_rate_mean_hz());
  }
  if (reader.gap_count() > 0) {
    const auto& g = reader.gaps();
    const auto largest = std::max_element(g.begin(), g.end(), [](const auto& a, const auto& b) {
      return a.length_s < b.length_s;
    });
    fmt::print("  warning: {} time gap(s) longer than {:g} s; the largest {:g} s after t = {:.6f} s (line {})\n",
               reader.gap_count(), reader.gap_threshold_s(), largest->length_s, largest->t_before_s,
               largest->line);
    for (std::size_t i = 0; i < std::min<std::size_t>(g.size(), 5); ++i) {
      fmt::print("    gap of {:g} s after t = {:.6f} s (line {})\n", g[i].length_s, g[i].t_before_s, g[i].line);
    }
  }
  if (reader.rows_saturated() > 0) {
    const auto& m = reader.metadata();
    fmt::print("  warning: {} rows have a gyro value at the stated full scale of {} / {} deg/s (sensor 1 / 2; "
               "saturated)\n",
               reader.rows_saturated(), m.gyro_full_scale_dps(1), m.gyro_full_scale_dps(2));
  }
  for (const est::ClippedChannel& c : reader.suspected_clipping()) {
    fmt::print("  warning: {} repeats its largest value, +-{:g} deg/s, in runs ({} samples): it clips there "
               "(the sensor's range)\n",
               log::gyro_column_name(c.channel), c.level_dps, c.samples);
  }
  if (reader.rows_with_missing_gyro() > 0) {
    fmt::print("  warning: {} rows have a missing or NaN gyro value\n", reader.rows_with_missing_gyro());
  }
  for (const est::DeadChannel& d : reader.dead_channels()) {
    if (d.kind == est::DeadChannel::Kind::kEmpty) {
      fmt::print("  warning: {} is empty in all {} rows: a dead axis, or a column the logger did not fill\n",
                 log::gyro_column_name(d.channel), d.rows);
    } else {
      fmt::print("  warning: {} reads {} deg/s in all {} rows while its sensor's other axes move: a dead or "
                 "stuck axis\n",
                 log::gyro_column_name(d.channel), exact_number(d.value_dps), d.rows);
    }
  }
  if (reader.dropped_truncated_row()) fmt::print("  warning: last row was cut off and dropped\n");
  const auto& meta = reader.metadata();
  if (!meta.complete()) {
    fmt::print("  warning: the log says 'complete: false' ({})\n",
               meta.get("incomplete_reason").value_or("no reason given"));
  }
}

int run_check(const std::string& path) {
  log::ReaderOptions opts;
  opts.accept_single_sensor = true;
  log::LogReader reader(path, opts);
  Sample s;
  Span span;
  double prev = kNaN;
  while (reader.next(s)) {
    if (std::isnan(span.t0)) span.t0 = s.t_s;
    if (!std::isnan(prev)) {
      span.min_dt = std::min(span.min_dt, s.t_s - prev);
      span.max_dt = std::max(span.max_dt, s.t_s - prev);
    }
    prev = span.t1 = s.t_s;
  }
  fmt::print("{}: driftless log{}, {} rows", path, reader.sensors() == 1 ? " (single-sensor form)" : "",
             reader.rows_read());
  if (reader.rows_read() > 0) fmt::print(", t = {:.3f} .. {:.3f} s", span.t0, span.t1);
  fmt::print("\n");
  for (const auto& [k, v] : reader.metadata().entries()) fmt::print("  {}: {}\n", k, v);
  if (reader.rows_read() > 1) fmt::print("  sample interval: {:.6f} .. {:.6f} s\n", span.min_dt, span.max_dt);
  fmt::print("  columns: {}\n", reader.columns().size());
  fmt::print("  optional groups:{}\n", groups_text(reader.fields()));
  const bool unusable = print_unusable(reader);
  print_findings(reader);
  if (unusable) fmt::print(stderr, "driftless check: {}: not usable as it is (see 'error:' above)\n", path);
  return unusable ? 1 : 0;
}

const bool registered_check = register_command(90, [](CLI::App& app) {
  auto* cmd = app.add_subcommand("check", "Validate a measurement log (docs/log-format.md, the same validation "
                                          "every command applies) and summarise it; exit 1 on a refused log, one "
                                          "without data rows, or stamps in another unit than seconds");
  auto path = std::make_shared<std::string>();
  cmd->add_option("--log", *path, "Measurement log (CSV, driftless-log 1; also the single-sensor form)")
      ->required()
      ->check(CLI::ExistingFile);
  return [path] { return run_check(*path); };
});

}  // namespace
}  // namespace driftless::cli
