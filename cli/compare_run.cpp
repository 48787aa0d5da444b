#include "cli/compare_run.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/core.h>

#include "cli/command.hpp"

namespace driftless::cli {

CompareSetup setup_compare(const CompareArgs& a) {
  CompareSetup s;
  s.model = a.model.empty() ? diagnose::default_compare_model() : diagnose::load_compare_model(a.model);
  s.opt.block_s = a.block_s;
  s.opt.evidence_threshold = a.threshold;
  if (a.resample) {
    if (!std::isfinite(s.model.sample_rate_hz)) {
      throw std::runtime_error(fmt::format("--resample: the model ({}) states no sample_rate_hz to resample to; the model "
                                           "runs at the log's rate without it", s.model.source));
    }
    s.opt.replay.resample_hz = s.model.sample_rate_hz;
  }
  if (std::isfinite(s.model.latitude_deg)) s.opt.replay.default_latitude_deg = s.model.latitude_deg;
  s.replay = diagnose::replay_log(a.log, s.opt.replay);
  if (std::isfinite(s.model.sample_rate_hz) && !a.resample &&
      std::abs(s.replay.sample_rate_hz - s.model.sample_rate_hz) > 0.01 * s.model.sample_rate_hz) {
    s.replay.notes.push_back(fmt::format("the model ({}) states sample_rate_hz {:.3f}; it runs at the log's {:.3f} Hz (its "
                                         "filters are designed for that rate; --resample resamples the log instead)",
                                         s.model.source, s.model.sample_rate_hz, s.replay.sample_rate_hz));
  }
  for (const auto& n : s.replay.notes) fmt::print("note: {}\n", n);
  return s;
}

void print_result(const diagnose::CompareResult& r) {
  fmt::print("{}: {}\n", diagnose::verdict_id(r.verdict), r.statement);
  for (const auto& c : r.selected) {
    fmt::print("  {}. {:<22} {:<12} sensor {:<4} axis {:<14} evidence {:>10.1f}{}\n", c.step, diagnose::effect_id(c.effect),
               diagnose::family_name(c.family()), diagnose::sensor_text(c), diagnose::axis_text(c), c.evidence,
               c.absurd ? "  IMPLAUSIBLE" : "");
  }
  for (const auto& c : r.noise_model) {
    fmt::print("  noise model: {:<17} sensor {:<4} axis {:<14} evidence {:>10.1f}\n", diagnose::effect_id(c.effect),
               diagnose::sensor_text(c), diagnose::axis_text(c), c.evidence);
  }
}

std::string doubt(const diagnose::CompareResult& r) {
  if (r.any_absurd()) {
    return "a selected effect has an implausible value (check the log's units, axes and frame convention, "
           "docs/log-format.md)";
  }
  if (!r.offset_beyond_zro.empty()) {
    return "the gyro differs from the reference by a constant rate beyond the sensor's zero-rate tolerance (the "
           "reference turns where the gyro does not: check ref_q's frame and time base, the latitude, the gyro's units)";
  }
  if (r.verdict == diagnose::Verdict::kUnexplained) return "the residual has structure no candidate effect explains";
  return {};
}

void add_compare_options(CLI::App& cmd, CompareArgs& a) {
  cmd.add_option("--log", a.log, "Measurement log (CSV, driftless-log 1; gyro in deg/s)")->required()->check(CLI::ExistingFile);
  cmd.add_option("--model", a.model, "Model or scenario YAML (its 'model:' block); default: embedded nominal MPU6050 "
                 "(datasheet noise, bias instability, turn-on bias, DLPF_CFG 3; scale, cross-axis, g-sensitivity, "
                 "temperature coefficients at zero; docs/compare.md). The model runs at the log's rate")
      ->check(CLI::ExistingFile);
  cmd.add_option("--out", a.out, "Output directory (report.html, diagnosis.json, plots/)")->required();
  cmd.add_flag("--resample", a.resample, "Resample the log to the sample_rate_hz the model file states (default: "
               "the model runs at the log's rate)");
  cmd.add_option("--block", a.block_s, "Block length of the residual fits, s (default 0.1)")->check(positive_number("s"));
  cmd.add_option("--threshold", a.threshold, "Evidence (2 ln L gain - ln(m) per parameter) above which an effect "
                 "is selected (default 10)")->check(CLI::NonNegativeNumber);
}

int finish_report(const char* command, const CompareArgs& a, const diagnose::CompareResult& r, int code) {
  fmt::print("wrote {}/report.html and {}/diagnosis.json\n", a.out, a.out);
  if (const std::string why = doubt(r); !why.empty()) {
    fmt::print(stderr, "driftless {}: {}; see {}/report.html\n", command, why, a.out);
    return 1;
  }
  return code;
}

}  // namespace driftless::cli
