// The comparison as named stages (docs/compare.md): residual -> channel fits -> forward
// selection of the missing effects -> noise model on what is left -> summaries -> verdict.
#include "diagnose/compare.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/core.h>

#include "diagnose/adc.hpp"
#include "diagnose/apply.hpp"
#include "diagnose/channel_fit.hpp"
#include "diagnose/noise_model.hpp"
#include "diagnose/residual.hpp"
#include "diagnose/selection.hpp"
#include "diagnose/signal_chain.hpp"
#include "diagnose/summary.hpp"
#include "estimator/mpu6050.hpp"

namespace driftless::diagnose {
namespace {

CompareResult header(const Replay& r, const CompareModel& model, const CompareOptions& opt) {
  CompareResult out;
  out.model_source = model.source;
  out.log_path = r.log_path;
  out.notes = r.notes;
  out.resampled = r.resampled;
  out.samples = r.size();
  out.sample_rate_hz = r.sample_rate_hz;
  out.sensors = r.sensors;
  out.duration_s = r.t_s.back() - r.t_s.front();
  out.threshold = opt.evidence_threshold;
  return out;
}

// the block series the report draws: the residual after the selection minus its smoothed bias
// (so the structure is visible), and that bias
void plot_series(const Residual& res, const AfterFit& after, CompareResult& out) {
  out.block_t_s = res.block_series.t_s;
  for (int c = 0; c < 6; ++c) {
    out.block_bias_dps[c] = after.bias[c];
    out.block_residual_dps[c].resize(res.blocks);
    for (std::size_t b = 0; b < res.blocks; ++b) out.block_residual_dps[c][b] = after.z[c][b] - after.bias[c][b];
  }
}

std::array<double, 6> noise_floors(const Channels& ch, const CompareModel& model, double fs) {
  std::array<double, 6> f{};
  for (int c = 0; c < 6; ++c) f[static_cast<std::size_t>(c)] = white_noise_floor_dps(model.sensor[ch[c].s], ch[c].j, fs);
  return f;
}

// takes the drift processes (bias instability, rate random walk) the noise model found into the
// channels' nuisance model; true when something changed
bool adopt_drift(const NoiseModelFindings& nm, const Residual& res, Channels& ch) {
  bool changed = false;
  for (const Candidate& c : nm.supported) {
    if (c.effect != Effect::kBiasInstability && c.effect != Effect::kRateRandomWalk) continue;
    for (const FittedParam& p : c.params) {
      ChannelData& C = ch[static_cast<std::size_t>(p.ref.sensor * 3 + p.ref.row)];
      if (p.ref.param == Param::kGmSigmaDps) C.noise.gm_sigma_dps = p.new_value();
      if (p.ref.param == Param::kGmTauS) C.noise.gm_tau_s = p.new_value();
      if (p.ref.param == Param::kRrwDpsRts) C.noise.rrw_dps_rts = p.new_value();
      changed = true;
    }
  }
  if (!changed) return false;
  for (ChannelData& C : ch)
    if (C.present) rebuild_gram(C, res.block_series);
  return true;
}

// a constant offset between gyro and reference larger than the sensor's zero-rate tolerance
// (and 3 sigma of the model's turn-on spread: the MPU6050 default's 20/3 deg/s gives the
// datasheet's +-20 deg/s) is no turn-on bias: the reference shows a rotation the gyro
// does not (a drifting or mis-framed ref_q, a wrong Earth rate) or the gyro is in other units
void flag_offsets_beyond_zro(const CompareModel& model, int channels, CompareResult& out) {
  for (int c = 0; c < channels; ++c) {
    const twin::ConstantBiasParams& cb = model.sensor[c / 3].constant_bias;
    const double spread_dps = cb.enabled ? cb.sigma_dps[c % 3] : 0.0;
    const double limit_dps = std::max(mpu6050::kGyroZroToleranceDps, 3.0 * spread_dps);
    if (std::abs(out.channels[static_cast<std::size_t>(c)].turn_on_bias_dps) > limit_dps) out.offset_beyond_zro.push_back(c);
  }
}

// each sensor's total group delay (low-pass, sample delay, box time offset), s
std::array<double, 2> chain_delays_s(const CompareModel& m) {
  std::array<double, 2> d{};
  for (int s = 0; s < 2; ++s) {
    const twin::SensorParams& p = m.sensor[static_cast<std::size_t>(s)];
    d[static_cast<std::size_t>(s)] = lowpass_delay_s(p) + (p.sample_delay.enabled ? p.sample_delay.delay_s : 0.0) + m.time_offset_s;
  }
  return d;
}

// the model with the selected effects written into it (as --apply writes them)
CompareModel with_selected(const CompareModel& model, const std::vector<Candidate>& selected) {
  CompareModel m = model;
  for (const auto& c : selected) apply_candidate(m, c);
  return m;
}

std::vector<int> axes_of(const Candidate& c, int s) {
  std::vector<int> axes;
  for (const auto& p : c.params) {
    if (p.ref.sensor != s) continue;
    const bool per_axis = p.ref.row >= 0 && p.ref.param != Param::kMountingDeg;
    for (int a = 0; a < 3; ++a)
      if ((!per_axis || p.ref.row == a) && std::find(axes.begin(), axes.end(), a) == axes.end()) axes.push_back(a);
  }
  std::sort(axes.begin(), axes.end());
  return axes;
}

std::string axes_string(const std::vector<int>& axes) {
  std::string out;
  for (int a : axes) out += (out.empty() ? "" : ",") + std::string(1, axis_letter(a));
  return out;
}

}  // namespace

void CompareOptions::validate() const {
  auto pos = [](double v, const char* n) {
    if (!(v > 0) || !std::isfinite(v)) throw std::invalid_argument(fmt::format("CompareOptions.{} must be > 0", n));
  };
  pos(block_s, "block_s");
  if (!(window_s >= 0)) throw std::invalid_argument("CompareOptions.window_s must be >= 0 s");
  if (worst_windows < 0) throw std::invalid_argument("CompareOptions.worst_windows must be >= 0");
  pos(whiteness_alpha, "whiteness_alpha");
  if (ljung_box_lags < 2) throw std::invalid_argument("CompareOptions.ljung_box_lags must be >= 2");
  if (!(min_effect_fraction >= 0 && min_effect_fraction < 1)) {
    throw std::invalid_argument("CompareOptions.min_effect_fraction must be in [0, 1)");
  }
  pos(correlation_z, "correlation_z");
  if (!(evidence_threshold >= 0) || !std::isfinite(evidence_threshold)) {
    throw std::invalid_argument("CompareOptions.evidence_threshold must be >= 0");
  }
  if (max_steps < 1) throw std::invalid_argument("CompareOptions.max_steps must be >= 1");
  replay.validate();
}

const char* verdict_id(Verdict v) {
  switch (v) {
    case Verdict::kConsistent: return "consistent_with_noise";
    case Verdict::kMissingEffect: return "missing_effect";
    case Verdict::kUnexplained: return "unexplained_structure";
  }
  return "?";
}

std::string sensor_text(const Candidate& c) {
  bool s1 = false, s2 = false;
  for (const auto& p : c.params) {
    const bool both = p.ref.param == Param::kLowpassDelayS && p.ref.sensor < 0;  // both sensors' filter
    s1 = s1 || p.ref.sensor == 0 || both, s2 = s2 || p.ref.sensor == 1 || both;
  }
  return s1 && s2 ? "both" : s1 ? "1" : s2 ? "2" : "-";
}

std::string axis_text(const Candidate& c) {
  const std::vector<int> a1 = axes_of(c, 0), a2 = axes_of(c, 1);
  if (a1.empty() && a2.empty()) return "-";
  if (a2.empty()) return axes_string(a1);
  if (a1.empty()) return axes_string(a2);
  return "s1:" + axes_string(a1) + " s2:" + axes_string(a2);
}

const FittedParam* find_param(const Candidate& c, const std::string& name) {
  for (const auto& p : c.params)
    if (p.name() == name) return &p;
  return nullptr;
}

bool CompareResult::any_absurd() const {
  return std::any_of(selected.begin(), selected.end(), [](const Candidate& c) { return c.absurd; });
}

namespace {

// one comparison about `model`: every regressor, the selection and the summaries are linear
// about its prediction
CompareResult compare_about(const Replay& r, const CompareModel& model, const CompareOptions& opt) {
  CompareResult out = header(r, model, opt);
  // 1: the model's prediction and the residual
  const Residual res = make_residual(r, model, opt.block_s);
  out.notes.insert(out.notes.end(), res.notes.begin(), res.notes.end());
  out.samples_used = res.samples_used;
  out.block_s = static_cast<double>(res.block_len) / res.fs_hz;
  // 2: per-channel regressors, whitening, white density (a nuisance)
  const ColumnInputs in{r, res, model.sensor, chain_delays_s(model)};
  Channels ch = build_channels(in, res);
  out.blocks_used = ch[0].m;
  // 3: forward selection of the physical, box, signal-chain and ADC effects; 4: the noise model
  // on what they leave. When that says the bias drifts otherwise than the model's processes, the
  // selection runs again with the drift found (a drift the nuisance model understates would
  // otherwise be read as slow physical effects), at most twice
  // (a resampled log's samples are interpolations: its ADC grid and codes are not the sensor's)
  std::vector<Candidate> adc;
  if (r.resampled) {
    out.notes.push_back("the ADC effects (quantization, saturation, missing codes) are not tested on a resampled log");
  } else {
    adc = adc_candidates(r, res, model, noise_floors(ch, model, res.fs_hz), log_blocks(ch));
  }
  SelectionInput si{ch, r, res, model, measure_noise_colour(r, res), std::move(adc), opt.evidence_threshold, opt.max_steps};
  Selection sel;
  NoiseModelFindings nm;
  AfterFit after;
  for (int pass = 0; pass < 3; ++pass) {
    after = AfterFit{};  // the last pass's per-sample series go before the selection runs again
    sel = select_effects(si);
    after = residual_after(ch, in, res, sel.spec, sel.fit, AfterDetail::kSamples);
    // the noise model is tested on the model with the selected effects: a selected low-pass
    // changes the bandwidth the white density is referred to (its block variance), so a density
    // read against the old filter was written beside the new one and missed after --apply
    nm = noise_model_candidates(r, res, ch, with_selected(model, sel.selected), after, opt.evidence_threshold);
    if (pass == 2 || !adopt_drift(nm, res, ch)) break;
    out.notes.push_back("the bias drifts otherwise than the model's noise processes say: the effects were selected "
                        "again with the drift fitted to this log as the nuisance");
  }
  out.selected = std::move(sel.selected);
  out.not_supported = std::move(sel.not_supported);
  out.notes.insert(out.notes.end(), sel.notes.begin(), sel.notes.end());
  const AfterFit before = residual_after(ch, in, res, FitSpec{}, FitResult{}, AfterDetail::kStats);
  // the summaries need the channels' noise and Gram only: the regressors' block means (18 MB an
  // hour) are given back before they run, where the process would otherwise peak
  for (ChannelData& C : ch) C.block_cols = Eigen::MatrixXf();
  out.noise_model = std::move(nm.supported);
  out.not_supported.insert(out.not_supported.end(), nm.not_supported.begin(), nm.not_supported.end());
  // 5: where it fails, and the verdict
  const CompareModel selected_model = with_selected(model, out.selected);
  summarise_channels(ch, res, model, selected_model, before, after, opt, out);
  summarise_regimes(r, res, ch, after, opt, out);
  flag_offsets_beyond_zro(model, res.channels(), out);
  plot_series(res, after, out);
  decide_verdict(out);
  return out;
}

// a change of a sensor's signal-chain delay beyond which the comparison is made again about it, s
constexpr double kRelineariseDelayS = 1e-3;

bool is_chain_param(Param p) { return p == Param::kLowpassDelayS || p == Param::kSampleDelayS || p == Param::kTimeOffsetS; }

// the model with only the selected signal-chain effects written into it
CompareModel with_selected_chain(const CompareModel& model, const std::vector<Candidate>& selected) {
  std::vector<Candidate> chain;
  for (const Candidate& c : selected)
    if (c.family() == Family::kSignalChain) chain.push_back(c);
  return with_selected(model, chain);
}

// parameters fitted about another model, restated against `model` (the new values stay)
void restate_against(const CompareModel& model, std::vector<Candidate>& cs) {
  for (Candidate& c : cs) {
    for (FittedParam& fp : c.params) {
      if (!is_chain_param(fp.ref.param)) continue;
      const double v = fp.new_value();
      fp.model_value = model_value(model, fp.ref);
      fp.value = v - fp.model_value;
    }
  }
}

// the second comparison, about the chain the first found, stated against the user's model: its
// selection, plus the first's signal-chain effects it did not need again (the model it ran
// about has them); one candidate per effect, in selection order
void merge_chain(const CompareModel& model, const CompareResult& first, CompareResult& second) {
  for (auto* list : {&second.selected, &second.not_supported, &second.noise_model}) restate_against(model, *list);
  std::vector<Candidate> chain;
  for (const Candidate& c : first.selected) {
    if (c.family() != Family::kSignalChain) continue;
    auto again = std::find_if(second.selected.begin(), second.selected.end(), [&](const Candidate& x) { return x.effect == c.effect; });
    if (again == second.selected.end()) {
      chain.push_back(c);
      continue;
    }
    for (const FittedParam& fp : c.params) {
      const bool refitted = std::any_of(again->params.begin(), again->params.end(), [&](const FittedParam& q) { return q.ref == fp.ref; });
      if (!refitted) again->params.push_back(fp);
    }
  }
  second.selected.insert(second.selected.begin(), chain.begin(), chain.end());
  for (std::size_t i = 0; i < second.selected.size(); ++i) second.selected[i].step = static_cast<int>(i) + 1;
  std::erase_if(second.not_supported, [&](const Candidate& c) {
    return std::any_of(second.selected.begin(), second.selected.end(), [&](const Candidate& x) { return x.effect == c.effect; });
  });
  second.model_source = first.model_source;
}

}  // namespace

// A delay enters the residual nonlinearly: its regressors are the chain's Taylor terms to third
// order about the model's chain, exact for small changes only. A change of several ms (another
// DLPF, a sensor sampled 13-19 ms late) left a fourth-order part that read as a scale factor
// (0.012 % at 2 Hz, 18 ms: (w d)^4 / 24) and biased the delay by 0.1 ms (5 sigma), which the
// next --apply undid. So when the selection moves a sensor's chain by more than
// kRelineariseDelayS, the comparison is made again about the chain it found (one Gauss-Newton
// step on the delays) and stated against the user's model.
CompareResult compare(const Replay& r, const CompareModel& model, const CompareOptions& opt) {
  opt.validate();
  CompareResult first = compare_about(r, model, opt);
  const CompareModel about = with_selected_chain(model, first.selected);
  const std::array<double, 2> d0 = chain_delays_s(model), d1 = chain_delays_s(about);
  const double moved_s = std::max(std::abs(d1[0] - d0[0]), std::abs(d1[1] - d0[1]));
  if (!(moved_s > kRelineariseDelayS)) return first;
  CompareResult second = compare_about(r, about, opt);
  merge_chain(model, first, second);
  second.notes.push_back(fmt::format("the signal chain found moves a sensor's delay by {:.1f} ms: the comparison was made "
                                     "again about it (delays enter the residual nonlinearly), and its values are stated "
                                     "against the model given; the residual statistics are those about the chain found",
                                     1e3 * moved_s));
  decide_verdict(second);
  return second;
}

}  // namespace driftless::diagnose
