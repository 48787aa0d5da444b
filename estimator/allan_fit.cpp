// The joint noise fit (docs/allan.md, fits): both bias-instability models fitted over the whole
// curve, coloured shortest taus trimmed, parameters with inflated uncertainties, identifiability.
#include "estimator/allan_fit.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <utility>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Dense>

#include "estimator/allan_fit_solve.hpp"

namespace driftless::est {

using fit_detail::FitData;
using fit_detail::Solution;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kLn2OverPi2 = 2.0 * 0.69314718055994531 / 3.14159265358979324;  // 2 ln 2 / pi
constexpr double kZ95 = 1.6448536269514722;  // one-sided 95 % normal quantile
constexpr double kMinShare = 0.3;            // a term must be this much of the model somewhere

// Gauss-Markov Allan variance per unit sigma^2; x = tau / T (series below 1e-3: no cancellation)
double gm_unit_avar(double tau_s, double T) {
  const double x = tau_s / T;
  if (x < 1e-3) return 2.0 * (x / 3.0 - x * x / 4.0 + 7.0 * x * x * x / 60.0);
  const double g = 3.0 - 4.0 * std::exp(-x) + std::exp(-2.0 * x);
  return 2.0 / x * (1.0 - g / (2.0 * x));
}

// white noise through a first-order low-pass of time constant Tf, sampled every tau0 (an AR(1)
// with pole phi = exp(-tau0/Tf)), per unit N^2: exact Allan variance at m = tau/tau0 samples,
//   sigma_u^2 / m^2 [m + (2 m phi (1-phi) - phi (3 - 4 phi^m + phi^2m)) / (1-phi)^2],
// sigma_u^2 = (1-phi) / ((1+phi) tau0), so that it tends to 1/tau for tau >> Tf
double lowpassed_white_unit_avar(double tau_s, double tau0_s, double Tf) {
  const double m = tau_s / tau0_s;
  const double phi = std::exp(-tau0_s / Tf);
  const double q = 1.0 - phi;
  const double pm = std::pow(phi, m);
  const double A = m + (2.0 * m * phi * q - phi * (3.0 - 4.0 * pm + pm * pm)) / (q * q);
  return q / ((1.0 + phi) * tau0_s * m * m) * A;
}

int idx(NoiseTerm t) { return static_cast<int>(t); }

// correlation of the Allan-variance estimates at neighbouring octaves by noise type (Monte Carlo
// of sampled white PM/FM, flicker FM and random-walk FM: docs/allan.md); a spacing of `octaves`
// gives rho^octaves, capped below 1 so the whitening stays well conditioned
double neighbour_correlation(NoiseType a, NoiseType b, double octaves) {
  auto r = [](NoiseType t) {
    switch (t) {
      case NoiseType::kFlickerFM: return 0.7;
      case NoiseType::kRandomWalkFM:
      case NoiseType::kFlickerWalkFM:
      case NoiseType::kRandomRunFM: return 0.88;
      default: return 0.5;
    }
  };
  return std::min(0.98, std::pow(std::max(r(a), r(b)), std::max(octaves, 1e-3)));
}

FitData make_data(const AllanCurve& c, std::size_t first) {
  FitData d;
  d.tau0_s = 1.0 / c.sample_rate_hz;
  const AllanPoint* prev = nullptr;
  for (std::size_t i = first; i < c.points.size(); ++i) {
    const auto& p = c.points[i];
    if (!(p.adev > 0.0) || !std::isfinite(p.adev)) continue;
    if (prev != nullptr) {
      d.rho_next.push_back(neighbour_correlation(prev->noise, p.noise, std::log2(p.tau_s / prev->tau_s)));
    }
    d.tau_s.push_back(p.tau_s);
    // the fit is in log space, and ln of a chi-square variance estimate is low by about
    // 1/edf + 1/(3 edf^2) on average: undo it, or few-cluster taus (where K lives) pull down
    d.avar.push_back(p.adev * p.adev * std::exp(1.0 / p.edf + 1.0 / (3.0 * p.edf * p.edf)));
    d.edf.push_back(p.edf);
    d.weight.push_back(0.5 * p.edf);
    prev = &p;
  }
  return d;
}

const std::vector<NoiseTerm> kFlickerTerms = {NoiseTerm::kQ, NoiseTerm::kN, NoiseTerm::kB, NoiseTerm::kK, NoiseTerm::kR};
const std::vector<NoiseTerm> kGmTerms = {NoiseTerm::kQ, NoiseTerm::kN, NoiseTerm::kGaussMarkov, NoiseTerm::kK,
                                         NoiseTerm::kR};

// golden-section minimum of f over [lo, hi] (a bracket from a grid), to `tol`
template <class F>
double golden_min(F&& f, double lo, double hi, double tol) {
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
  double f1 = f(x1), f2 = f(x2);
  while (hi - lo > tol) {
    if (f1 < f2) {
      hi = x2, x2 = x1, f2 = f1;
      x1 = hi - g * (hi - lo), f1 = f(x1);
    } else {
      lo = x1, x1 = x2, f1 = f2;
      x2 = lo + g * (hi - lo), f2 = f(x2);
    }
  }
  return 0.5 * (lo + hi);
}

double chi2_of(const Solution& s) { return s.ok ? s.chi2 : std::numeric_limits<double>::infinity(); }

// a fit with one shape parameter (a time, as x = log10 of it in s) profiled over a grid and
// refined by golden section; its 1-sigma interval is where the profile chi2 stays within `delta`
// of the best, and each coefficient's spread over that interval joins its uncertainty
struct Profile {
  Solution best;
  double lo_s = kNaN, hi_s = kNaN;           // interval ends (NaN: not bounded on that side)
  std::array<double, kNoiseTerms> spread{};  // half the range of each coefficient over the interval
};

double chi2_red(const Solution& s) { return s.dof > 0.0 ? s.chi2 / s.dof : 1.0; }

// the variance multiplier of a solution: correlated taus times the model error (Birge ratio)
double inflation(const Solution& s, double kappa) { return kappa * std::max(1.0, chi2_red(s)); }

template <class FitAt>
Profile profile(FitAt&& fit_at, double a, double b, double step, double kappa, const Solution* none) {
  std::vector<double> grid, chi;
  for (double x = a; x <= b + 1e-9; x += step) grid.push_back(x), chi.push_back(chi2_of(fit_at(x)));
  const auto k = static_cast<std::size_t>(std::min_element(chi.begin(), chi.end()) - chi.begin());
  auto at = [&](double x) { return chi2_of(fit_at(x)); };
  const double xb = golden_min(at, grid[k > 0 ? k - 1 : k], grid[k + 1 < grid.size() ? k + 1 : k], 0.01);
  Profile out;
  out.best = none != nullptr ? *none : fit_at(xb);
  const double target = chi2_of(out.best) + inflation(out.best, kappa);
  std::array<double, kNoiseTerms> lo = out.best.model.coef, hi = lo;
  auto widen = [&](const Solution& s) {
    for (int t = 0; t < kNoiseTerms; ++t) lo[t] = std::min(lo[t], s.model.coef[t]), hi[t] = std::max(hi[t], s.model.coef[t]);
  };
  // walk out from the best along the grid to the first point above target, then bisect to the
  // crossing; the coefficients at the crossings bound their spread (NaN: no crossing that side)
  auto cross = [&](int dir) {
    double inside = none != nullptr ? (dir < 0 ? a : a) : xb;
    if (none != nullptr && dir < 0) return kNaN;  // "no low-pass" is the lower end itself
    double outside = kNaN;
    for (std::size_t i = 0; i < grid.size(); ++i) {
      const std::size_t g = dir > 0 ? i : grid.size() - 1 - i;
      if ((dir > 0 && grid[g] <= inside) || (dir < 0 && grid[g] >= inside)) continue;
      if (chi[g] > target) {
        outside = grid[g];
        break;
      }
      widen(fit_at(grid[g]));
      inside = grid[g];
    }
    if (std::isnan(outside)) return kNaN;
    for (int it = 0; it < 10; ++it) {
      const double mid = 0.5 * (inside + outside);
      (at(mid) > target ? outside : inside) = mid;
    }
    widen(fit_at(inside));
    return std::pow(10.0, 0.5 * (inside + outside));
  };
  out.lo_s = cross(-1);
  out.hi_s = cross(+1);
  for (int t = 0; t < kNoiseTerms; ++t) out.spread[t] = 0.5 * (hi[t] - lo[t]);
  return out;
}

// the flicker model; the white noise's low-pass time constant Tf by a profile from tau0/20 to
// 20 tau0, against no low-pass at all (kept unless Tf improves chi2 by more than 9 kappa: 3 sigma;
// at 2 sigma one white-noise channel in 25 was reported low-passed, the profile over Tf being a
// search over many values)
Profile fit_flicker(const FitData& d, double kappa) {
  const Solution none = fit_detail::fit_columns(d, kFlickerTerms, {});
  auto fit_at = [&](double x) { return fit_detail::fit_columns(d, kFlickerTerms, {std::pow(10.0, x), 0.0}, &none.model); };
  const double a = std::log10(d.tau0_s / 20.0), b = std::log10(d.tau0_s * 20.0);
  Profile p = profile(fit_at, a, b, 0.25, kappa, nullptr);
  if (chi2_of(p.best) < chi2_of(none) - 9.0 * kappa) return p;
  Profile q = profile(fit_at, a, b, 0.25, kappa, &none);
  q.lo_s = q.hi_s = kNaN;
  return q;
}

// the Gauss-Markov model: the correlation time from 3x the shortest tau (shorter would only
// mimic white noise) to half the longest (longer would only mimic a rate random walk)
Profile fit_gauss_markov(const FitData& d, double white_tau_s, const NoiseModel& seed, double kappa) {
  auto fit_at = [&](double x) { return fit_detail::fit_columns(d, kGmTerms, {white_tau_s, std::pow(10.0, x)}, &seed); };
  const double a = std::log10(3.0 * d.tau_s.front()), b = std::log10(0.5 * d.tau_s.back());
  if (b < a) return Profile{fit_at(a), kNaN, kNaN, {}};
  return profile(fit_at, a, b, 0.25, kappa, nullptr);
}

// ---- parameters from a solution ----

struct Region {
  double max_share = 0.0, tau_at_max = kNaN, lo = kNaN, hi = kNaN;
};

// where term t is at least half of the model, and its largest share, over [tau_lo, tau_hi]
Region term_region(const NoiseModel& m, NoiseTerm t, double tau_lo, double tau_hi) {
  Region r;
  const int steps = std::max(2, static_cast<int>(40.0 * std::log10(tau_hi / tau_lo)) + 1);
  for (int i = 0; i <= steps; ++i) {
    const double tau = tau_lo * std::pow(tau_hi / tau_lo, static_cast<double>(i) / steps);
    const double total = m.avar(tau);
    const double share = total > 0.0 ? m.term_avar(t, tau) / total : 0.0;
    if (share > r.max_share) r.max_share = share, r.tau_at_max = tau;
    if (share >= 0.5) {
      if (std::isnan(r.lo)) r.lo = tau;
      r.hi = tau;
    }
  }
  return r;
}

int column_of(const Solution& s, NoiseTerm t) {
  for (std::size_t j = 0; j < s.columns.size(); ++j) {
    if (s.columns[j] == t) return static_cast<int>(j);
  }
  return -1;
}

std::string fmt_g(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

// a variance coefficient c = p^2 with its (inflated) variance as a parameter p
NoiseParameter make_param(const Profile& pr, const FitData& d, NoiseTerm t, double kappa) {
  const Solution& s = pr.best;
  NoiseParameter p;
  p.value = p.sigma = p.tau_s = p.tau_lo_s = p.tau_hi_s = p.upper_95 = kNaN;
  const int j = column_of(s, t);
  if (j < 0 || !s.ok) {
    p.note = "not in this model";
    return p;
  }
  const double c = s.free_coef[j];
  const double sc = std::sqrt(std::max(0.0, s.free_var[j] * inflation(s, kappa)) + pr.spread[idx(t)] * pr.spread[idx(t)]);
  const bool active = s.coef[j] > 0.0;
  const Region reg = term_region(s.model, t, d.tau_s.front(), d.tau_s.back());
  p.tau_s = reg.tau_at_max;
  p.tau_lo_s = reg.lo;
  p.tau_hi_s = reg.hi;
  p.upper_95 = std::sqrt(std::max(0.0, c) + kZ95 * sc);
  if (!active) {
    p.note = "not identifiable: no support in the curve (95 % upper bound " + fmt_g(p.upper_95) + ")";
  } else if (!(c > 2.0 * sc)) {
    p.note = "not identifiable: below 2 sigma of its uncertainty (95 % upper bound " + fmt_g(p.upper_95) + ")";
  } else if (reg.max_share < kMinShare) {
    p.note = "not identifiable: at most " + fmt_g(100.0 * reg.max_share) +
             " % of the curve anywhere (95 % upper bound " + fmt_g(p.upper_95) + ")";
  } else {
    p.value = std::sqrt(c);
    p.sigma = sc / (2.0 * p.value);
    p.valid = true;
  }
  return p;
}

// the minimum of the model's Allan deviation over the fitted range (datasheet B), with its sigma
NoiseParameter model_minimum(const Solution& s, const FitData& d, double kappa, double record_s) {
  NoiseParameter p;
  p.sigma = p.upper_95 = p.tau_lo_s = p.tau_hi_s = kNaN;
  const double lo = d.tau_s.front(), hi = d.tau_s.back();
  double best_tau = lo, best = s.model.avar(lo);
  for (int i = 1; i <= 400; ++i) {
    const double tau = lo * std::pow(hi / lo, i / 400.0);
    const double v = s.model.avar(tau);
    if (v < best) best = v, best_tau = tau;
  }
  p.value = std::sqrt(best);
  p.tau_s = best_tau;
  // envelope theorem: d min / d c_j = basis_j(tau*) / (2 adev)
  Eigen::VectorXd g(static_cast<Eigen::Index>(s.columns.size()));
  for (std::size_t j = 0; j < s.columns.size(); ++j) {
    g[static_cast<Eigen::Index>(j)] = fit_detail::basis(s.columns[j], best_tau, d.tau0_s, {s.model.white_tau_s, s.model.gm_tau_s}) / (2.0 * p.value);
  }
  p.sigma = std::sqrt(std::max(0.0, g.dot(s.cov * g) * inflation(s, kappa)));
  p.upper_95 = p.value + kZ95 * p.sigma;
  const bool bracketed = best_tau < hi / 1.5;
  p.valid = bracketed && best_tau > lo * 1.5;
  if (!bracketed) {
    p.note = "upper bound: the Allan deviation still falls at the longest usable tau (" + fmt_g(hi) +
             " s of a " + fmt_g(record_s) + " s record)";
  } else if (!p.valid) {
    p.note = "the curve rises from the shortest tau on: no bias-instability floor";
  }
  return p;
}

// the Gauss-Markov correlation time from its profile interval
NoiseParameter gm_time(const Profile& g, const NoiseParameter& gm_sigma) {
  NoiseParameter p;
  p.value = g.best.model.gm_tau_s;
  p.tau_s = p.value;
  p.tau_lo_s = g.lo_s;
  p.tau_hi_s = g.hi_s;
  p.upper_95 = g.hi_s;
  p.sigma = 0.5 * (g.hi_s - g.lo_s);
  p.valid = gm_sigma.valid && std::isfinite(p.sigma);
  if (!gm_sigma.valid) {
    p.note = "no Gauss-Markov bias in the curve";
    p.value = p.sigma = kNaN;
  } else if (!std::isfinite(p.sigma)) {
    p.note = std::isnan(g.hi_s) ? "not bounded above by the data (longer than the record can tell)"
                                : "not bounded below by the data";
  }
  return p;
}

}  // namespace

const char* to_string(NoiseTerm t) {
  switch (t) {
    case NoiseTerm::kQ: return "Q";
    case NoiseTerm::kN: return "N";
    case NoiseTerm::kB: return "B";
    case NoiseTerm::kK: return "K";
    case NoiseTerm::kR: return "R";
    case NoiseTerm::kGaussMarkov: return "GM";
  }
  return "?";
}

double NoiseModel::term_avar(NoiseTerm t, double tau) const {
  const double c = coef[idx(t)];
  switch (t) {
    case NoiseTerm::kQ: return 3.0 * c / (tau * tau);
    case NoiseTerm::kN: return white_tau_s > 0.0 ? c * lowpassed_white_unit_avar(tau, tau0_s, white_tau_s) : c / tau;
    case NoiseTerm::kB: return kLn2OverPi2 * c;
    case NoiseTerm::kK: return c * (tau / 3.0 + tau0_s * tau0_s / (6.0 * tau));
    case NoiseTerm::kR: return 0.5 * c * tau * tau;
    case NoiseTerm::kGaussMarkov: return c == 0.0 || !(gm_tau_s > 0.0) ? 0.0 : c * gm_unit_avar(tau, gm_tau_s);
  }
  return 0.0;
}

double NoiseModel::avar(double tau) const {
  double s = 0.0;
  for (int t = 0; t < kNoiseTerms; ++t) s += term_avar(static_cast<NoiseTerm>(t), tau);
  return s;
}

}  // namespace driftless::est

namespace driftless::est {
namespace {

// drops the shortest taus while their residual says the model cannot describe them (coloured
// noise beyond the model); at most a third of the points, keeping three more than parameters
std::size_t trim_short_taus(const AllanCurve& c, const NoiseFitOptions& opt, std::vector<std::string>& warn) {
  std::size_t first = 0;
  double worst = 0.0;
  while (first < c.points.size() / 3) {
    const FitData d = make_data(c, first);
    const Solution s = fit_flicker(d, opt.correlation_inflation).best;
    if (!s.ok || d.size() < 8 || std::fabs(s.residual[0]) <= opt.trim_residual) break;
    worst = std::max(worst, std::fabs(s.residual[0]));
    ++first;
  }
  if (first > 0) {
    warn.push_back("tau < " + fmt_g(c.points[first].tau_s) + " s left out of the fit: coloured beyond the model (" +
                   "normalised residual up to " + fmt_g(worst) + ")");
  }
  return first;
}

void record_warnings(NoiseFit& f, double record_s) {
  if (!f.B_min.valid && f.B_min.note.rfind("upper bound", 0) == 0) {
    f.warnings.push_back("record too short for B: the Allan deviation has no minimum within the usable taus; "
                         "record " + fmt_g(record_s) + " s");
  } else if (f.B_min.valid && f.B_min.tau_s > record_s / 10.0) {
    f.warnings.push_back("B rests on few clusters: its minimum lies at " + fmt_g(f.B_min.tau_s) + " s of a " +
                         fmt_g(record_s) + " s record (10x the minimum's tau recommended)");
  }
  if (!f.K.valid) {
    f.warnings.push_back("record too short for K: no rate random walk shows within the usable taus (up to " +
                         fmt_g(f.tau_fit_hi_s) + " s of a " + fmt_g(record_s) + " s record); K < " + fmt_g(f.K.upper_95) +
                         " (95 %)");
  }
}

}  // namespace

NoiseFit fit_noise_parameters(const AllanCurve& curve, const NoiseFitOptions& opt) {
  if (curve.deviation != Deviation::kAllan) {
    throw std::invalid_argument("allan fit: the noise terms are fitted on the Allan deviation, not on " +
                                std::string(to_string(curve.deviation)));
  }
  NoiseFit f;
  const double record_s = static_cast<double>(curve.samples) / curve.sample_rate_hz;
  const std::size_t first = trim_short_taus(curve, opt, f.warnings);
  const FitData d = make_data(curve, first);
  if (d.size() < 3) {
    for (NoiseParameter* p : {&f.Q, &f.N, &f.B, &f.B_min, &f.gm_sigma, &f.gm_tau, &f.K, &f.R}) {
      p->value = p->sigma = p->upper_95 = p->tau_s = p->tau_lo_s = p->tau_hi_s = kNaN;
      p->note = "too few averaging times for a fit";
    }
    f.warnings.push_back("record too short for any fit: fewer than 3 averaging times");
    return f;
  }
  f.tau_fit_lo_s = d.tau_s.front();
  f.tau_fit_hi_s = d.tau_s.back();
  f.points_fitted = d.size();
  const double kappa = opt.correlation_inflation;
  const Profile fl = fit_flicker(d, kappa);
  const Profile gm = fit_gauss_markov(d, fl.best.model.white_tau_s, fl.best.model, kappa);
  f.flicker_model = fl.best.model;
  f.gm_model = gm.best.model;
  // the Gauss-Markov model only when clearly better: its long correlation times mimic K, and the
  // flicker model's B and K are what datasheets and IEEE 952 quote
  f.gm_evidence = (chi2_of(fl.best) - chi2_of(gm.best)) / inflation(fl.best, kappa);
  f.preferred = f.gm_evidence > opt.gm_preference ? BiasModel::kGaussMarkov : BiasModel::kFlicker;
  const bool use_fl = f.preferred == BiasModel::kFlicker;
  const Profile& pref = use_fl ? fl : gm;
  f.chi2_red = chi2_red(pref.best);
  f.white_lowpass_tau_s = fl.best.model.white_tau_s;
  // the IEEE 952 terms always come from the flicker model: a Gauss-Markov bias below its
  // correlation time is the rate random walk K that model reads (and chance bends at the longest
  // taus must not move K); the preferred model only decides the drawn sum and B_min
  f.Q = make_param(fl, d, NoiseTerm::kQ, kappa);
  f.N = make_param(fl, d, NoiseTerm::kN, kappa);
  f.K = make_param(fl, d, NoiseTerm::kK, kappa);
  f.R = make_param(fl, d, NoiseTerm::kR, kappa);
  f.B = make_param(fl, d, NoiseTerm::kB, kappa);
  f.gm_sigma = make_param(gm, d, NoiseTerm::kGaussMarkov, kappa);
  f.gm_tau = gm_time(gm, f.gm_sigma);
  if (use_fl) {
    for (NoiseParameter* p : {&f.gm_sigma, &f.gm_tau}) {
      p->note += std::string(p->note.empty() ? "" : "; ") + "alternative model (the flicker model fits better)";
    }
  } else {
    f.B.note += std::string(f.B.note.empty() ? "" : "; ") + "alternative model (the Gauss-Markov model fits better)";
    if (f.K.valid) f.K.note = "the Gauss-Markov model fits better: K is the random walk its bias shows below the correlation time";
  }
  f.B_min = model_minimum(pref.best, d, kappa, record_s);
  if (f.white_lowpass_tau_s > 0.0) {
    f.warnings.push_back("the white noise is low-passed (time constant " + fmt_g(1e3 * f.white_lowpass_tau_s) +
                         " ms, e.g. a DLPF): the shortest taus read below the N line; N is the long-tau level");
  }
  record_warnings(f, record_s);
  return f;
}

}  // namespace driftless::est
