// The verdict of a comparison in one sentence: consistent with the noise model, missing effects
// (each with its values +- 1 sigma), or structure no candidate explains (docs/compare.md 4).
#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "diagnose/summary.hpp"
#include "estimator/mpu6050.hpp"

namespace driftless::diagnose {
namespace {

std::string value_text(const FittedParam& p) {
  return fmt::format("{} = {:.4g} ± {:.2g} {}", p.name(), p.new_value(), p.sigma, p.unit());
}

// "scale_factor on sensor 1 (x): s1.x.value_pct = 3.01 ± 0.02 %"; an effect the model has and
// the data lack is said as such ("the model's quantization (...) is not in the data: remove it"),
// never as a missing effect of "0 ± 0"
std::string effect_text(const Candidate& c) {
  std::string ps;
  std::size_t removed = 0;
  for (const auto& p : c.params) removed += removes_model_effect(p);
  if (removed > 0 && removed == c.params.size()) {
    ps = removal_text(c.effect, c.params.front());
    if (c.params.size() > 1) ps += fmt::format(" (and on {} more {})", c.params.size() - 1, c.params.size() == 2 ? "channel" : "channels");
  } else {
    for (std::size_t i = 0; i < std::min<std::size_t>(c.params.size(), 4); ++i)
      ps += (i ? ", " : "") + (removes_model_effect(c.params[i]) ? removal_text(c.effect, c.params[i]) : value_text(c.params[i]));
    if (c.params.size() > 4) ps += fmt::format(", ... ({} more)", c.params.size() - 4);
  }
  // the white density's bandwidth assumption, where the data cannot tell it (docs/compare.md 3)
  if (c.effect == Effect::kWhiteNoise && !c.note.empty()) ps += " (" + c.note + ")";
  const std::string where = sensor_text(c) == "-" ? "box" : "sensor " + sensor_text(c);
  return fmt::format("{} on {} ({}){}: {}", effect_id(c.effect), where, axis_text(c), c.absurd ? " [IMPLAUSIBLE]" : "", ps);
}

bool all_removals(const Candidate& c) {
  return !c.params.empty() && std::all_of(c.params.begin(), c.params.end(), removes_model_effect);
}

}  // namespace

namespace {

// the verdict from the selection, the noise model and the whiteness tests
void verdict_from_fit(CompareResult& out) {
  bool white_ok = true;
  for (const auto& cs : out.channels) white_ok = white_ok && cs.white;
  std::string noise;
  for (const auto& c : out.noise_model) noise += (noise.empty() ? "" : "; ") + effect_text(c);
  const std::string noise_tail = noise.empty() ? "" : "; the noise model differs (a noise-model change, after the effects): " + noise;
  if (!out.selected.empty()) {
    out.verdict = Verdict::kMissingEffect;
    // the model's effects the data lack are said apart from the missing ones
    std::string missing, extra;
    std::size_t n_missing = 0, n_extra = 0;
    for (const auto& c : out.selected) {
      std::string& list = all_removals(c) ? extra : missing;
      (all_removals(c) ? n_extra : n_missing) += 1;
      list += (list.empty() ? "" : "; ") + effect_text(c);
    }
    std::string text;
    if (n_missing > 0)
      text = fmt::format("{} missing effect{} (evidence > {:g}): {}", n_missing, n_missing == 1 ? "" : "s", out.threshold, missing);
    if (n_extra > 0)
      text += fmt::format("{}{} effect{} of the model not in the data (evidence > {:g}): {}", text.empty() ? "" : "; ",
                          n_extra, n_extra == 1 ? "" : "s", out.threshold, extra);
    out.statement = text + noise_tail;
    if (out.any_absurd()) out.statement += "; IMPLAUSIBLE values: check the log's units, axes and frame (docs/log-format.md)";
    return;
  }
  if (!white_ok || !out.correlations.empty()) {
    out.verdict = Verdict::kUnexplained;
    std::string sig, bad;
    for (std::size_t i = 0; i < std::min<std::size_t>(out.correlations.size(), 4); ++i)
      sig += fmt::format("{}{} on {} (rho {:+.3f})", i ? ", " : "", out.correlations[i].signal,
                         channel_name(out.correlations[i].channel), out.correlations[i].rho);
    for (int c = 0; c < 6; ++c)
      if (!out.channels[c].white) bad += (bad.empty() ? "" : ", ") + channel_name(c);
    out.statement = fmt::format("unexplained structure: no candidate effect explains the residual{}{}{}",
                                bad.empty() ? "" : "; not white on " + bad,
                                sig.empty() ? "" : "; it correlates with " + sig, noise_tail);
    return;
  }
  out.verdict = Verdict::kConsistent;
  out.statement = "consistent with the noise model: the residual is white and no candidate effect is supported by the data" +
                  noise_tail;
}

}  // namespace

bool is_no_lowpass(const FittedParam& p) {
  if (p.ref.param != Param::kLowpassDelayS) return false;
  return p.new_value() <= kNoLowpassDelayS || (std::isfinite(p.sigma) && p.new_value() < 2.0 * p.sigma);
}

bool removes_model_effect(const FittedParam& p) {
  if (p.model_value == 0.0) return false;
  switch (p.ref.param) {
    case Param::kLowpassDelayS: return is_no_lowpass(p);
    case Param::kQuantLsbPerDps:
    case Param::kSampleDelayS:
    case Param::kJitterSigmaS:
    case Param::kFullScaleDps: return p.new_value() == 0.0;
    default: return false;
  }
}

std::string removal_text(Effect e, const FittedParam& p) {
  if (p.ref.param == Param::kLowpassDelayS) {
    const std::string who = p.ref.sensor < 0 ? std::string() : fmt::format("sensor {}: ", p.ref.sensor + 1);
    return fmt::format("{}no low-pass: the model's {} ({} = {:.4g} {}) is not in the data: remove it", who,
                       effect_id(e), p.name(), p.model_value, p.unit());
  }
  return fmt::format("the model's {} ({} = {:.4g} {}) is not in the data: remove it", effect_id(e), p.name(), p.model_value,
                     p.unit());
}

// an offset beyond the sensor's zero-rate tolerance is said, with its cause and fix, and a
// comparison that would otherwise call the log consistent calls it unexplained
void decide_verdict(CompareResult& out) {
  verdict_from_fit(out);
  if (out.offset_beyond_zro.empty()) return;
  std::string list;
  for (int c : out.offset_beyond_zro)
    list += fmt::format("{}{} {:+.2f} deg/s", list.empty() ? "" : ", ", channel_name(c), out.channels[static_cast<std::size_t>(c)].turn_on_bias_dps);
  if (out.verdict == Verdict::kConsistent) out.verdict = Verdict::kUnexplained;
  out.statement += fmt::format(
      "; the gyro differs from the reference by a constant rate beyond the sensor's zero-rate tolerance ({}; an MPU6050 "
      "turns on within +-{:g} deg/s): the reference shows a rotation the gyro does not (check ref_q's frame and time "
      "base, the latitude, the gyro's units; docs/log-format.md)",
      list, mpu6050::kGyroZroToleranceDps);
}

}  // namespace driftless::diagnose
