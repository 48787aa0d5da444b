#include "diagnose/selection.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <functional>
#include <map>

#include <fmt/core.h>

#include "diagnose/apply.hpp"
#include "diagnose/parallel.hpp"
#include "estimator/stats.hpp"

namespace driftless::diagnose {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kMaxNoiseRefits = 4;

// one selected parameter; a low-pass delay is held at its 1-D optimum (it also colours noise)
struct Term {
  ParamRef ref;
  int step = 0;
  double delay_s = 0.0;  // low-pass: the filter's absolute group delay (0 = none)
};
using Terms = std::vector<Term>;

bool is_lowpass(const ParamRef& p) { return p.param == Param::kLowpassDelayS; }
bool is_signal_chain(const ParamRef& p) {
  return p.param == Param::kLowpassDelayS || p.param == Param::kSampleDelayS || p.param == Param::kTimeOffsetS;
}
bool contains(const Terms& S, const ParamRef& p) {
  return std::any_of(S.begin(), S.end(), [&](const Term& t) { return t.ref == p; });
}
// a low-pass term of sensor s (0, 1) or both (-1) acts on sensor k
bool lowpass_on(const ParamRef& p, int k) { return p.param == Param::kLowpassDelayS && (p.sensor < 0 || p.sensor == k); }
// at most one low-pass term acts on each sensor
bool lowpass_taken(const Terms& S, const ParamRef& x) {
  return std::any_of(S.begin(), S.end(), [&](const Term& t) {
    return is_lowpass(t.ref) && (x.sensor < 0 || t.ref.sensor < 0 || t.ref.sensor == x.sensor);
  });
}

// every parameter the log excites: per channel, per sensor, box-wide
std::vector<ParamRef> make_universe(const Channels& ch) {
  std::vector<ParamRef> u;
  const bool single = !ch[3].present;  // a single-sensor log
  auto add = [&](Param p, int s, int row, int col) {
    const ParamRef ref{p, static_cast<std::int8_t>(s), static_cast<std::int8_t>(row), static_cast<std::int8_t>(col)};
    for (const ColumnUse& cu : columns_of(ref)) {
      if (ch[cu.channel].index(cu.col) >= 0) {
        u.push_back(ref);
        return;
      }
    }
  };
  for (int s = 0; s < 2; ++s) {
    for (int j = 0; j < 3; ++j) {
      add(Param::kScalePct, s, j, -1);
      for (int a = 0; a < 3; ++a) if (a != j) add(Param::kMisalignmentPct, s, j, a);
      for (int k = 0; k < 3; ++k) add(Param::kGSensDpsPerG, s, j, k);
      add(Param::kBiasTcDpsPerDegc, s, j, -1);
      add(Param::kScaleTcPctPerDegc, s, j, -1);
      add(Param::kNonlinQuadPctFs, s, j, -1);
      add(Param::kNonlinCubicPctFs, s, j, -1);
      for (int b = 0; b < 4; ++b) add(Param::kFlipTransientDps, s, j, b);
    }
    for (int k = 0; k < 3; ++k) add(Param::kMountingDeg, s, k, -1);
    for (int side = 0; side < 2; ++side) add(Param::kStopErrorDeg, s, -1, side);
    add(Param::kLowpassDelayS, s, -1, -1);
    if (!single) add(Param::kSampleDelayS, s, -1, -1);
  }
  // both sensors' filter at once (one chip configuration); with one sensor it is sensor 1's, and
  // that sensor's sample delay is the box time offset: the same signals, one is tested
  if (!single) add(Param::kLowpassDelayS, -1, -1, -1);
  add(Param::kLatitudeDeg, -1, -1, -1);
  add(Param::kTimeOffsetS, -1, -1, -1);
  return u;
}

// the evaluation of one parameter given the selection
struct Eval {
  ParamRef ref;
  double ev = -kInf;           // evidence: gain - ln m
  double value = 0.0, sigma = kInf;
  double delay_s = 0.0;        // low-pass: the filter delay found
};

class Selector {
 public:
  explicit Selector(SelectionInput& in)
      : in_(in), log_m_(log_blocks(in.ch)), universe_(make_universe(in.ch)) {
    for (int s = 0; s < 2; ++s) {
      model_delay_[s] = lowpass_delay_s(in.model.sensor[s]);
      model_sample_delay_[s] = model_value(in.model, ParamRef{Param::kSampleDelayS, static_cast<std::int8_t>(s)});
      null_penalty_[s] = colour_penalty_at(s, model_delay_[s]);
      model_extra_delay_[s] = model_sample_delay_[s] + in.model.time_offset_s;
      model_c_[s] = chain_terms(s, model_delay_[s], model_extra_delay_[s]);
    }
  }
  Selection run();

 private:
  double colour_penalty_at(int s, double delay_s) const {
    const auto& mc = in_.colour[static_cast<std::size_t>(s)];
    const double expected = expected_colour(with_lowpass_delay(in_.model.sensor[s], delay_s), in_.res.fs_hz, mc);
    return colour_penalty(mc, expected);
  }
  FitSpec spec_of(const Terms& S) const;
  FitSpec solve(const Terms& S, FitResult* fit) const;
  std::vector<std::pair<ParamRef, double>> chain_held(const Terms& S, const FitSpec& spec, const FitResult& fit) const;
  std::vector<std::pair<ParamRef, double>> rotation_held(const FitSpec& spec, const FitResult& fit) const;
  ChainTerms chain_terms(int s, double lowpass_delay_s, double extra_delay_s) const;
  double total(const Terms& S, FitResult* fit = nullptr) const;
  double best_delay(int s, const Terms& S, double* best_total) const;
  void optimise_delays(Terms& S) const;
  Eval evaluate(const ParamRef& x, const Terms& S, double base) const;
  std::vector<Eval> evaluate_all(const Terms& S, double base) const;
  std::vector<Terms> options(Effect e, const std::vector<Eval>& evals, const Terms& S, int step_no) const;
  bool step(Terms& S, int step_no, double& base);
  std::vector<FittedParam> new_params(const Terms& trial, std::size_t from) const;
  double added_evidence(const Terms& a, const Terms& b, std::size_t from) const;
  std::size_t choose(const std::vector<std::pair<Effect, Terms>>& opts, const std::vector<double>& score,
                     std::size_t best, const Terms& S);
  void prune(Terms& S, std::size_t from = 0) const;
  bool refit_noise(const Terms& S);
  void set_variances(const Terms& S);
  Candidate make_selected(Effect e, const Terms& S, const FitResult& fit) const;
  std::vector<Candidate> make_not_supported(const Terms& S, double base) const;
  FittedParam fitted(const ParamRef& ref, double value, double sigma) const;
  void add_lowpass(Candidate& c, const Term& t, const Terms& S) const;
  /// 1-sigma of low-pass term t's delay in selection S (which holds t), from the objective's curvature
  double delay_sigma(const Terms& S, const Term& t) const;

  SelectionInput& in_;
  double log_m_;
  std::vector<ParamRef> universe_;
  std::array<double, 2> model_delay_{}, model_sample_delay_{}, null_penalty_{};
  std::array<double, 2> model_extra_delay_{};  // the model's sample delay + time offset
  std::array<ChainTerms, 2> model_c_{};         // the model's chain's higher-order terms
  std::map<Effect, double> evidence_added_, gain_added_;
  std::map<Effect, std::string> notes_;  // why an effect was named instead of another
  std::vector<int> adc_steps_;  // step per entry of in_.adc (0 = not selected)
  int noise_refits_ = 0;
};

FitSpec Selector::spec_of(const Terms& S) const {
  FitSpec spec;
  for (const Term& t : S) {
    if (!is_lowpass(t.ref)) {
      spec.free.push_back(t.ref);
      continue;
    }
    for (int k = 0; k < 2; ++k) {  // the delay change on each sensor it acts on
      if (!lowpass_on(t.ref, k)) continue;
      spec.fixed.emplace_back(ParamRef{Param::kLowpassDelayS, static_cast<std::int8_t>(k)}, t.delay_s - model_delay_[static_cast<std::size_t>(k)]);
    }
  }
  return spec;
}

// the higher-order coefficients of sensor s's signal chain: its low-pass's pole time from the
// filter the model designs at the log's rate (chain_moments, signal_chain.hpp)
ChainTerms Selector::chain_terms(int s, double lowpass_delay_s, double extra_delay_s) const {
  const twin::SensorParams p = with_lowpass_delay(in_.model.sensor[static_cast<std::size_t>(s)], lowpass_delay_s);
  double T = 0.0;
  if (p.lowpass_latency.enabled) {
    const twin::DlpfSetting set = twin::lowpass_setting(p.lowpass_latency);
    const double a = twin::design_lowpass(set.gyro_bandwidth_hz, set.gyro_delay_s, in_.res.fs_hz).pole;
    T = a / (1.0 - a) / in_.res.fs_hz;
  }
  return chain_moments(lowpass_delay_s, T, extra_delay_s);
}

// the MAP fit of a selection. Two parts of it are not linear in the parameters and are held at
// the first solve's values, then the fit is solved again: a changed signal chain's second- and
// third-order terms, and a mounting rotation's second-order part
FitSpec Selector::solve(const Terms& S, FitResult* fit) const {
  FitSpec spec = spec_of(S);
  *fit = map_fit(in_.ch, spec);
  const bool chain = std::any_of(S.begin(), S.end(), [](const Term& t) { return is_signal_chain(t.ref); });
  const bool mount = std::any_of(S.begin(), S.end(), [](const Term& t) { return t.ref.param == Param::kMountingDeg; });
  if (!chain && !mount) return spec;
  std::vector<std::pair<ParamRef, double>> held;
  if (chain) held = chain_held(S, spec, *fit);
  if (mount) {
    const auto rot = rotation_held(spec, *fit);
    held.insert(held.end(), rot.begin(), rot.end());
  }
  spec.fixed.insert(spec.fixed.end(), held.begin(), held.end());
  *fit = map_fit(in_.ch, spec);
  return spec;
}

// the chains' second- and third-order terms where the fit's delays put them
std::vector<std::pair<ParamRef, double>> Selector::chain_held(const Terms& S, const FitSpec& spec, const FitResult& fit) const {
  std::vector<std::pair<ParamRef, double>> held;
  std::array<double, 2> D = model_delay_, d{};
  for (int s = 0; s < 2; ++s) d[s] = model_extra_delay_[static_cast<std::size_t>(s)];
  for (const Term& t : S)
    for (int k = 0; k < 2; ++k)
      if (lowpass_on(t.ref, k)) D[static_cast<std::size_t>(k)] = t.delay_s;
  for (std::size_t i = 0; i < spec.free.size(); ++i) {
    const ParamRef& p = spec.free[i];
    const double v = fit.value[static_cast<Eigen::Index>(i)];
    if (p.param == Param::kTimeOffsetS) d[0] += v, d[1] += v;
    if (p.param == Param::kSampleDelayS) d[static_cast<std::size_t>(p.sensor)] += v;
  }
  for (int s = 0; s < 2; ++s) {
    const auto k = static_cast<std::size_t>(s);
    const ChainTerms c = chain_terms(s, D[k], d[k]);
    const double dc2 = c.c2 - model_c_[k].c2, dc3 = c.c3 - model_c_[k].c3;
    if (dc2 != 0.0) held.emplace_back(ParamRef{Param::kDelaySecondOrderS2, static_cast<std::int8_t>(s)}, dc2);
    if (dc3 != 0.0) held.emplace_back(ParamRef{Param::kDelayThirdOrderS3, static_cast<std::int8_t>(s)}, dc3);
  }
  return held;
}

// a mounting rotation by the rotation vector t is w + t x w + t x (t x w) / 2 + ...; its columns
// are the first-order part, and the second, (t t' - |t|^2 I) / 2, is a scale and a cross-axis
// term on the scale and misalignment columns (held here as the change from the model's angles).
// Left out, a 0.8 deg mounting about z read as a -0.0097 % scale on the other axes (cos t - 1),
// selected at evidence 14-22 and undone by the next --apply, whose model rotates exactly
std::vector<std::pair<ParamRef, double>> Selector::rotation_held(const FitSpec& spec, const FitResult& fit) const {
  std::vector<std::pair<ParamRef, double>> held;
  for (int s = 0; s < 2; ++s) {
    const auto sensor = static_cast<std::int8_t>(s);
    Eigen::Vector3d t0, t;
    for (int k = 0; k < 3; ++k) t0[k] = model_value(in_.model, ParamRef{Param::kMountingDeg, sensor, static_cast<std::int8_t>(k)});
    t = t0;
    bool moved = false;
    for (std::size_t i = 0; i < spec.free.size(); ++i) {
      const ParamRef& p = spec.free[i];
      if (p.param != Param::kMountingDeg || p.sensor != s) continue;
      t[p.row] += fit.value[static_cast<Eigen::Index>(i)];
      moved = true;
    }
    if (!moved) continue;
    auto second = [](const Eigen::Vector3d& deg) {
      const Eigen::Vector3d r = deg * kRadPerDeg;
      return Eigen::Matrix3d(0.5 * (r * r.transpose() - r.squaredNorm() * Eigen::Matrix3d::Identity()));
    };
    const Eigen::Matrix3d M = 100.0 * (second(t) - second(t0));  // %
    for (int j = 0; j < 3; ++j) {
      const auto row = static_cast<std::int8_t>(j);
      held.emplace_back(ParamRef{Param::kScalePct, sensor, row}, M(j, j));
      for (int a = 0; a < 3; ++a)
        if (a != j) held.emplace_back(ParamRef{Param::kMisalignmentPct, sensor, row, static_cast<std::int8_t>(a)}, M(j, a));
    }
  }
  return held;
}

double Selector::total(const Terms& S, FitResult* fit_out) const {
  FitResult fit;
  solve(S, &fit);
  double t = fit.gain;
  for (const Term& term : S) {
    for (int k = 0; k < 2; ++k)
      if (lowpass_on(term.ref, k)) t += null_penalty_[static_cast<std::size_t>(k)] - colour_penalty_at(k, term.delay_s);
  }
  if (fit_out) *fit_out = fit;
  return t;
}

// the low-pass delay of sensor s that fits best given the other terms: a grid, then golden
// section between the best grid point's neighbours
double Selector::best_delay(int s, const Terms& S, double* best_total) const {
  Terms trial = S;
  trial.erase(std::remove_if(trial.begin(), trial.end(),
                             [&](const Term& t) { return is_lowpass(t.ref) && t.ref.sensor == s; }),
              trial.end());
  trial.push_back(Term{ParamRef{Param::kLowpassDelayS, static_cast<std::int8_t>(s)}, 0, 0.0});
  const double model_delay = model_delay_[static_cast<std::size_t>(s < 0 ? 0 : s)];
  auto f = [&](double d) {
    trial.back().delay_s = std::max(0.0, d);
    return total(trial);
  };
  static const std::vector<double> grid_ms = {0, 0.5, 1, 1.5, 2, 3, 4, 5, 6.5, 8, 10, 12.5, 15, 18, 22, 27, 33, 40, 50, 60};
  std::vector<double> grid;
  for (double g : grid_ms) grid.push_back(g * 1e-3);
  grid.push_back(model_delay);
  std::sort(grid.begin(), grid.end());
  std::size_t best = 0;
  std::vector<double> v(grid.size());
  for (std::size_t i = 0; i < grid.size(); ++i) {
    v[i] = f(grid[i]);
    if (v[i] > v[best]) best = i;
  }
  double d = grid[best], vd = v[best];
  if (best > 0 || grid.size() > 1) {
    const double lo = grid[best > 0 ? best - 1 : 0], hi = grid[std::min(best + 1, grid.size() - 1)];
    const double x = golden_min([&](double dd) { return -f(dd); }, lo, hi, 25);
    const double vx = f(x);
    if (vx > vd) d = x, vd = vx;
  }
  // a filter that fits better than none by less than 1 in 2 ln L (its delay within about 1 sigma
  // of 0) is none: the golden search never ends on the boundary itself, and a filter of some
  // microseconds is not "no filter" to the model (its bandwidth, extrapolated from the datasheet
  // relation, refers the white noise to tens of kHz: a density written beside it was 14x low)
  if (d > 0.0 && grid.front() == 0.0 && vd - v.front() < 1.0) d = 0.0, vd = v.front();
  if (best_total) *best_total = vd;
  return d;
}

void Selector::optimise_delays(Terms& S) const {
  for (int pass = 0; pass < 2; ++pass) {
    for (Term& t : S) {
      if (!is_lowpass(t.ref)) continue;
      t.delay_s = best_delay(t.ref.sensor, S, nullptr);
    }
  }
}

Eval Selector::evaluate(const ParamRef& x, const Terms& S, double base) const {
  Eval e;
  e.ref = x;
  if (is_lowpass(x)) {
    if (lowpass_taken(S, x)) return e;
    double t = 0.0;
    e.delay_s = best_delay(x.sensor, S, &t);
    e.value = e.delay_s - model_delay_[static_cast<std::size_t>(x.sensor < 0 ? 0 : x.sensor)];
    e.ev = t - base - log_m_;
    return e;
  }
  Terms trial = S;
  trial.push_back(Term{x, 0, 0.0});
  if (is_signal_chain(x)) optimise_delays(trial);
  FitResult fit;
  const double t = total(trial, &fit);
  const FitSpec spec = spec_of(trial);  // free parameters in the order solve() fits them
  const auto it = std::find(spec.free.begin(), spec.free.end(), x);
  const auto i = static_cast<Eigen::Index>(it - spec.free.begin());
  e.value = fit.value[i];
  e.sigma = fit.sigma[i];
  // a sample delay cannot be negative (the sensor cannot sample before the time stamp), nor can
  // the box's time offset (simulate models offsets >= 0; a negative one is the model's low-pass
  // delay the log does not have, which at a rate where the filter is a pure delay reads the same)
  if (x.param == Param::kSampleDelayS && model_sample_delay_[static_cast<std::size_t>(x.sensor)] + e.value < 0.0) return e;
  if (x.param == Param::kTimeOffsetS && in_.model.time_offset_s + e.value < 0.0) return e;
  if (!std::isfinite(e.sigma)) return e;  // not identified given the selection
  e.ev = t - base - log_m_;
  return e;
}

// the candidates are independent given the selection (each fit reads the channels only): they
// are evaluated on the machine's cores, each into its own slot (the same result on any count)
std::vector<Eval> Selector::evaluate_all(const Terms& S, double base) const {
  std::vector<ParamRef> todo;
  for (const ParamRef& x : universe_)
    if (!contains(S, x)) todo.push_back(x);
  std::vector<Eval> out(todo.size());
  for_each_index(static_cast<int>(todo.size()), [&](int i) {
    out[static_cast<std::size_t>(i)] = evaluate(todo[static_cast<std::size_t>(i)], S, base);
  });
  return out;
}

// the ways an effect can be added: its parameters with positive evidence, per sensor; for the
// low-pass either both sensors' filter at once or each sensor's own (they exclude each other)
std::vector<Terms> Selector::options(Effect e, const std::vector<Eval>& evals, const Terms& S, int step_no) const {
  std::vector<Terms> out;
  auto add_where = [&](const std::function<bool(const Eval&)>& keep) {
    Terms trial = S;
    for (const Eval& ev : evals)
      if (effect_of(ev.ref.param) == e && ev.ev > 0.0 && keep(ev)) trial.push_back(Term{ev.ref, step_no, ev.delay_s});
    if (trial.size() > S.size()) out.push_back(std::move(trial));
  };
  if (e != Effect::kLowpass) {
    // per sensor (two instruments: the same kind of error on each is two findings, and one
    // sensor's parameters must not ride on another's signal), box-wide parameters on their own
    for (int s = -1; s < 2; ++s) add_where([s](const Eval& ev) { return ev.ref.sensor == s; });
    return out;
  }
  add_where([](const Eval& ev) { return ev.ref.sensor < 0; });
  add_where([](const Eval& ev) { return ev.ref.sensor >= 0; });
  return out;
}

// one forward step: the effect whose supported parameters add the most evidence
bool Selector::step(Terms& S, int step_no, double& base) {
  const std::vector<Eval> evals = evaluate_all(S, base);
  // every (effect, sensor) option, scored on the machine's cores into its own slot; the best is
  // then taken in catalogue order (the same choice, bit for bit, on any thread count)
  std::vector<std::pair<Effect, Terms>> opts;
  for (int ei = 0; ei < kEffectCount; ++ei) {
    const auto e = static_cast<Effect>(ei);
    if (effect_info(e).family == Family::kNoiseModel || effect_info(e).family == Family::kAdc) continue;
    for (Terms& trial : options(e, evals, S, step_no)) opts.emplace_back(e, std::move(trial));
  }
  std::vector<double> score(opts.size());
  for_each_index(static_cast<int>(opts.size()), [&](int i) {
    auto& [e, trial] = opts[static_cast<std::size_t>(i)];
    if (e == Effect::kLowpass || e == Effect::kSampleDelay || e == Effect::kTimeOffset) optimise_delays(trial);
    // the effect's parameters that each add evidence alone, less those the others make
    // redundant: an effect is scored by what it explains, not by the noise its spare
    // parameters fit (two names for one signal, a cross-axis pair and a mounting rotation,
    // would otherwise be ranked by their count of spare parameters)
    if (trial.size() > S.size() + 1) prune(trial, S.size());
    const auto added = static_cast<double>(trial.size() - S.size());
    score[static_cast<std::size_t>(i)] = total(trial) - base - added * log_m_;
  });
  double best_ev = in_.threshold;
  Effect best = Effect::kCount;
  Terms best_trial;
  std::size_t best_i = opts.size();
  for (std::size_t i = 0; i < opts.size(); ++i) {
    if (score[i] > best_ev) best_ev = score[i], best_i = i;
  }
  if (best_i < opts.size()) {
    best_i = choose(opts, score, best_i, S);
    best_ev = score[best_i], best = opts[best_i].first, best_trial = opts[best_i].second;
  }
  int best_adc = -1;
  for (std::size_t a = 0; a < in_.adc.size(); ++a) {
    if (adc_steps_[a] == 0 && in_.adc[a].testable && in_.adc[a].evidence > best_ev) {
      best_ev = in_.adc[a].evidence;
      best_adc = static_cast<int>(a);
    }
  }
  if (best_adc >= 0) {
    adc_steps_[static_cast<std::size_t>(best_adc)] = step_no;
    return true;
  }
  if (best == Effect::kCount) return false;
  const double before = base;
  S = std::move(best_trial);
  prune(S);
  optimise_delays(S);
  if (noise_refits_ < kMaxNoiseRefits && refit_noise(S)) ++noise_refits_;
  set_variances(S);
  base = total(S);
  evidence_added_[best] += best_ev;
  gain_added_[best] += base - before;
  return true;
}

// the parameters an option adds to the selection (its terms from index `from` on), fitted jointly
// with it and judged against what a MEMS gyro box can have
std::vector<FittedParam> Selector::new_params(const Terms& trial, std::size_t from) const {
  FitResult fit;
  const FitSpec spec = solve(trial, &fit);
  std::vector<FittedParam> out;
  for (std::size_t t = from; t < trial.size(); ++t) {
    const ParamRef& ref = trial[t].ref;
    if (is_lowpass(ref)) {
      const auto s0 = static_cast<std::size_t>(ref.sensor < 0 ? 0 : ref.sensor);
      out.push_back(fitted(ref, trial[t].delay_s - model_delay_[s0], 0.0));
      continue;
    }
    const auto i = static_cast<Eigen::Index>(std::find(spec.free.begin(), spec.free.end(), ref) - spec.free.begin());
    out.push_back(fitted(ref, fit.value[i], fit.sigma[i]));
  }
  return out;
}

// the evidence option `b`'s new parameters (from index `from` on) add to option `a`
double Selector::added_evidence(const Terms& a, const Terms& b, std::size_t from) const {
  Terms both = a;
  for (std::size_t t = from; t < b.size(); ++t)
    if (!contains(both, b[t].ref)) both.push_back(b[t]);
  if (std::any_of(both.begin() + static_cast<std::ptrdiff_t>(from), both.end(),
                  [](const Term& t) { return is_signal_chain(t.ref); }))
    optimise_delays(both);
  return total(both) - total(a) - static_cast<double>(both.size() - a.size()) * log_m_;
}

// the option a step takes, given the best-scoring one. An option whose fit is implausible (a
// cross-axis term of 2000 %) yields to the best plausible option that explains the same residual,
// i.e. after which the implausible one adds no evidence above the threshold: on a static box the
// Earth rate in the flipping sensor's axes changes sign with the gravity there, so a cross-axis
// term and a g-sensitivity are one signal; scored equal, the catalogue order named the cross-axis
// term at 200-2200 % (probe finding: navgen --gsens 0.05, seeds 30-37). Plausible options the
// data cannot tell from the one taken (neither adds evidence given the other; a coordinated turn's
// lateral force is the yaw rate times the speed) are named in its note: the choice is not the data's
std::size_t Selector::choose(const std::vector<std::pair<Effect, Terms>>& opts, const std::vector<double>& score,
                             std::size_t best, const Terms& S) {
  auto absurd = [&](std::size_t i) {
    const std::vector<FittedParam> ps = new_params(opts[i].second, S.size());
    return std::any_of(ps.begin(), ps.end(), [](const FittedParam& p) { return p.absurd; });
  };
  auto values = [&](std::size_t i) {
    std::string v;
    for (const FittedParam& p : new_params(opts[i].second, S.size()))
      v += fmt::format("{}{} = {:.4g} {}", v.empty() ? "" : ", ", p.name(), p.new_value(), p.unit());
    return v;
  };
  std::vector<std::size_t> order;  // the other supported options, best first
  for (std::size_t i = 0; i < opts.size(); ++i)
    if (i != best && score[i] > in_.threshold) order.push_back(i);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return score[a] > score[b]; });
  const std::size_t from = S.size();
  std::size_t chosen = best;
  std::string note;
  if (absurd(best)) {
    for (std::size_t i : order) {
      if (absurd(i) || added_evidence(opts[i].second, opts[best].second, from) > in_.threshold) continue;
      const bool apart = added_evidence(opts[best].second, opts[i].second, from) > in_.threshold;
      note = fmt::format("{} fits the same residual (evidence {:.1f}) at implausible values ({}); {} {}",
                         effect_id(opts[best].first), score[best], values(best), effect_id(opts[i].first),
                         apart ? "explains all of it and more at plausible values"
                               : "is named instead: this log cannot tell the two apart, and its values are plausible");
      chosen = i;
      break;
    }
  }
  // plausible options of another effect within reach of the chosen one's score that are one signal with it
  const double reach = in_.threshold + 4.0 * log_m_;
  for (std::size_t i : order) {
    if (i == chosen || opts[i].first == opts[chosen].first || score[chosen] - score[i] > reach || absurd(i)) continue;
    if (added_evidence(opts[chosen].second, opts[i].second, from) > in_.threshold) continue;
    if (added_evidence(opts[i].second, opts[chosen].second, from) > in_.threshold) continue;
    note += fmt::format("{}this log cannot tell it from {} (evidence {:.1f}: {})", note.empty() ? "" : "; ",
                        effect_id(opts[i].first), score[i], values(i));
  }
  if (!note.empty()) {
    std::string& kept = notes_[opts[chosen].first];  // an effect taken again at a later step (the other sensor)
    kept += (kept.empty() ? "" : "; ") + note;
  }
  return chosen;
}

// backward: drop the least supported parameter (of those from index `from` on) while its
// removal costs less than its penalty
void Selector::prune(Terms& S, std::size_t from) const {
  for (;;) {
    const double t = total(S);
    double worst = 0.0;
    std::size_t worst_i = S.size();
    for (std::size_t i = from; i < S.size(); ++i) {
      Terms without = S;
      without.erase(without.begin() + static_cast<std::ptrdiff_t>(i));
      const double ev = t - total(without) - log_m_;
      if (ev < worst) worst = ev, worst_i = i;
    }
    if (worst_i == S.size()) return;
    S.erase(S.begin() + static_cast<std::ptrdiff_t>(worst_i));
  }
}

// the white density of each channel refitted without the selected effects (a large missing
// effect would otherwise inflate it and hide itself and others); true when one moved > 2 %
bool Selector::refit_noise(const Terms& S) {
  FitResult fit;
  const FitSpec spec = solve(S, &fit);
  std::array<double, 6> change{};
  for_each_index(in_.res.channels(), [&](int c) {
    const Eigen::VectorXd coef = channel_coefficients(in_.ch[c], c, spec, fit);
    const std::vector<double> z = block_residual(in_.ch[c], coef);
    change[static_cast<std::size_t>(c)] = refit_white(in_.ch[c], in_.res.block_series, z);
  });
  return std::any_of(change.begin(), change.end(), [](double d) { return d > 0.02; });
}

// the unit of every objective becomes each channel's residual variance under the selected set:
// a candidate x is then scored against the variance of the model it extends (the score form of
// the test of S + x against S). Measured against the null fit's variance instead, a mismatch the
// selection has already taken out (a signal chain the log does not share) stayed in the unit and
// deflated every later candidate's evidence
void Selector::set_variances(const Terms& S) {
  FitResult fit;
  const FitSpec spec = solve(S, &fit);
  for_each_index(in_.res.channels(), [&](int c) {
    set_variance(in_.ch[c], channel_coefficients(in_.ch[c], c, spec, fit));
  });
}

Selection Selector::run() {
  adc_steps_.assign(in_.adc.size(), 0);
  Terms S;
  set_variances(S);
  double base = 0.0;
  int step_no = 1;
  for (; step_no <= in_.max_steps; ++step_no) {
    if (!step(S, step_no, base)) break;
  }
  Selection out;
  out.spec = solve(S, &out.fit);
  if (step_no > in_.max_steps) {
    out.notes.push_back(fmt::format("the forward selection stopped after {} steps (its limit)", in_.max_steps));
  }
  // selected effects in the order they first entered
  std::vector<std::pair<int, Effect>> order;
  for (const Term& t : S) {
    const Effect e = effect_of(t.ref.param);
    auto it = std::find_if(order.begin(), order.end(), [&](const auto& o) { return o.second == e; });
    if (it == order.end()) order.emplace_back(t.step, e);
    else it->first = std::min(it->first, t.step);
  }
  for (std::size_t a = 0; a < in_.adc.size(); ++a)
    if (adc_steps_[a] > 0) order.emplace_back(adc_steps_[a], in_.adc[a].effect);
  std::sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [st, e] : order) {
    Candidate c;
    if (effect_info(e).family == Family::kAdc) {
      for (std::size_t a = 0; a < in_.adc.size(); ++a)
        if (in_.adc[a].effect == e) c = in_.adc[a];
    } else {
      c = make_selected(e, S, out.fit);
    }
    c.step = st;
    out.selected.push_back(c);
  }
  out.not_supported = make_not_supported(S, total(S));
  return out;
}

// a selected low-pass: its delay with sigma from the curvature of the objective (-2 ln L) at
// the optimum, and per sensor the measured noise colour against the new filter's
double Selector::delay_sigma(const Terms& S, const Term& t) const {
  const double h = 2e-4;
  // central second difference; within h of the "no filter" boundary (a delay cannot be
  // negative) about h instead (0, h, 2h), not about a clamped point that repeats the centre
  const double c = std::max(t.delay_s, h);
  auto at = [&](double d) {
    Terms v = S;
    for (Term& u : v)
      if (u.ref == t.ref) u.delay_s = d;
    return total(v);
  };
  const double curv = (2.0 * at(c) - at(c + h) - at(c - h)) / (h * h);
  return curv > 0 ? std::sqrt(2.0 / curv) : kInf;
}

void Selector::add_lowpass(Candidate& c, const Term& t, const Terms& S) const {
  const auto s0 = static_cast<std::size_t>(t.ref.sensor < 0 ? 0 : t.ref.sensor);
  c.params.push_back(fitted(t.ref, t.delay_s - model_delay_[s0], delay_sigma(S, t)));
  for (int k = 0; k < 2; ++k) {
    if (!lowpass_on(t.ref, k)) continue;
    const auto& mc = in_.colour[static_cast<std::size_t>(k)];
    const auto sensor = static_cast<std::int8_t>(k);
    FittedParam measured = fitted(ParamRef{Param::kNoiseLag1, sensor}, mc.stat, mc.usable() ? 1.0 / std::sqrt(mc.pairs) : kInf);
    FittedParam expected = fitted(ParamRef{Param::kModelLag1, sensor},
                                  expected_colour(with_lowpass_delay(in_.model.sensor[static_cast<std::size_t>(k)], t.delay_s),
                                                  in_.res.fs_hz, mc), 0.0);
    measured.model_value = expected.model_value = 0.0;
    c.diagnostics.push_back(measured);
    c.diagnostics.push_back(expected);
  }
}

FittedParam Selector::fitted(const ParamRef& ref, double value, double sigma) const {
  FittedParam fp;
  fp.ref = ref;
  fp.value = value;
  fp.sigma = sigma;
  fp.model_value = ref.param == Param::kLatitudeDeg ? in_.r.latitude_deg : model_value(in_.model, ref);
  const double shown = ref.param == Param::kLatitudeDeg ? value : fp.new_value();
  fp.absurd = std::abs(shown) > plausible_limit(ref.param);
  return fp;
}

Candidate Selector::make_selected(Effect e, const Terms& S, const FitResult& fit) const {
  Candidate c;
  c.effect = e;
  const FitSpec spec = spec_of(S);
  double total_j0 = 0.0;
  for (const auto& ch : in_.ch) total_j0 += ch.j0;
  for (const Term& t : S) {
    if (effect_of(t.ref.param) != e) continue;
    if (is_lowpass(t.ref)) {
      add_lowpass(c, t, S);
      continue;
    }
    const auto it = std::find(spec.free.begin(), spec.free.end(), t.ref);
    const auto i = static_cast<Eigen::Index>(it - spec.free.begin());
    c.params.push_back(fitted(t.ref, fit.value[i], fit.sigma[i]));
  }
  for (const auto& p : c.params) c.absurd = c.absurd || p.absurd;
  c.dof = static_cast<int>(c.params.size());
  c.evidence = evidence_added_.count(e) ? evidence_added_.at(e) : 0.0;
  c.chi2 = gain_added_.count(e) ? gain_added_.at(e) : 0.0;
  c.p_value = 1.0 - est::chi2_cdf(std::max(0.0, c.chi2), std::max(1, c.dof));
  c.explained_fraction = total_j0 > 0 ? std::clamp(c.chi2 / total_j0, 0.0, 1.0) : 0.0;
  if (e == Effect::kTimeOffset) {
    c.note = "the same delay on both sensors: the box's time stamps (both sensors' low-pass delays would read "
             "the same where the noise colour cannot tell them apart)";
  }
  if (e == Effect::kLowpass) {
    c.note = "the sensor's low-pass group delay (0 = no filter; bandwidth from the MPU6050 datasheet relation), "
             "told from a sample delay by the lag-1 correlation of the noise";
  }
  if (const auto it = notes_.find(e); it != notes_.end()) c.note += (c.note.empty() ? "" : "; ") + it->second;
  return c;
}

std::vector<Candidate> Selector::make_not_supported(const Terms& S, double base) const {
  const std::vector<Eval> evals = evaluate_all(S, base);
  std::vector<Candidate> out;
  for (int ei = 0; ei < kEffectCount; ++ei) {
    const auto e = static_cast<Effect>(ei);
    const Family fam = effect_info(e).family;
    if (fam == Family::kNoiseModel || fam == Family::kAdc) continue;
    if (std::any_of(S.begin(), S.end(), [&](const Term& t) { return effect_of(t.ref.param) == e; })) continue;
    Candidate c;
    c.effect = e;
    const Eval* best = nullptr;
    for (const Eval& ev : evals) {
      if (effect_of(ev.ref.param) != e) continue;
      if (!best || ev.ev > best->ev) best = &ev;
    }
    if (!best) {
      c.testable = false;
      c.note = "not excited by this log (no variation of the driving signal)";
    } else {
      c.evidence = best->ev;
      c.chi2 = std::max(0.0, best->ev + log_m_);
      c.dof = 1;
      c.p_value = 1.0 - est::chi2_cdf(c.chi2, 1);
      double sigma = best->sigma;
      if (is_lowpass(best->ref) && std::isfinite(best->ev)) {  // a delay's sigma from the curvature at its optimum
        Terms with = S;
        with.push_back(Term{best->ref, 0, best->delay_s});
        sigma = delay_sigma(with, with.back());
      }
      c.params.push_back(fitted(best->ref, best->value, sigma));
    }
    out.push_back(c);
  }
  for (std::size_t a = 0; a < in_.adc.size(); ++a)
    if (adc_steps_[a] == 0) out.push_back(in_.adc[a]);
  std::stable_sort(out.begin(), out.end(), [](const Candidate& a, const Candidate& b) {
    if (a.testable != b.testable) return a.testable;
    return a.evidence > b.evidence;
  });
  return out;
}

}  // namespace

Selection select_effects(SelectionInput& in) { return Selector(in).run(); }

}  // namespace driftless::diagnose
