#include "diagnose/adc.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "diagnose/parallel.hpp"
#include "estimator/mpu6050.hpp"
#include "estimator/sample.hpp"

namespace driftless::diagnose {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// the coarsest plausible gyro ADC: 1 LSB per deg/s (a 16-bit ADC over +-32768 deg/s, a 12-bit
// one over +-2048 deg/s); a coarser step fitted is a misread lattice
constexpr double kMinPlausibleLsbPerDps = 1.0;

ParamRef ref_of(Param p, int channel) {
  return ParamRef{p, static_cast<std::int8_t>(channel / 3), static_cast<std::int8_t>(channel % 3)};
}

FittedParam param(Param p, int channel, double new_value, double sigma, double model) {
  FittedParam fp;
  fp.ref = ref_of(p, channel);
  fp.model_value = model;
  fp.value = new_value - model;
  fp.sigma = sigma;
  return fp;
}

// lattice strength |mean exp(2 pi i y / step)|: near 1 when every output sits on the grid. Only
// a strength above `cut` is used: the sum stops (returning 0) once even all remaining samples on
// the grid could not lift it above (an off-grid step is dropped after ~(1 - cut) of the samples)
double lattice(const std::vector<double>& y, double step, double cut) {
  double cr = 0, si = 0;
  const double n = std::max<double>(1.0, static_cast<double>(y.size()));
  for (std::size_t k = 0; k < y.size(); ++k) {
    const double ph = 2.0 * kPi * y[k] / step;
    cr += std::cos(ph);
    si += std::sin(ph);
    if (k % 4096 == 4095 && std::hypot(cr, si) + static_cast<double>(y.size() - k - 1) <= cut * n) return 0.0;
  }
  return std::hypot(cr, si) / n;
}

// the 5-95 % spread of the outputs, deg/s: a lattice is only seen where the outputs cover
// several of its steps (a cluster narrower than the step has one phase for any step, |mean| ~ 1)
double spread_5_95(std::vector<double> u) {
  if (u.size() < 20) return 0.0;
  const auto at = [&](double q) {
    auto it = u.begin() + static_cast<std::ptrdiff_t>(q * static_cast<double>(u.size() - 1));
    std::nth_element(u.begin(), it, u.end());
    return *it;
  };
  const double lo = at(0.05), hi = at(0.95);
  return hi - lo;
}

// the coarsest LSB the outputs lie on: the model's, the common MPU6050 ranges, the data's step.
// `y` are the outputs at rest (the fits' samples): during a flip the few values spread over
// +-360 deg/s, their median spacing is hundreds of LSB, and a step that the resting outputs (a
// narrow cluster) do not span was taken for the LSB (0.655 LSB/(deg/s) on the hinge axes, P14).
// A step is tried only where the outputs span at least two of it
double data_lsb(const std::vector<double>& y, const twin::SensorParams& p, double* strength) {
  std::vector<double> steps;
  if (p.quantization.enabled) steps.push_back(1.0 / p.quantization.sensitivity_lsb_per_dps);
  for (int fs_sel = 0; fs_sel < 4; ++fs_sel) steps.push_back(1.0 / mpu6050::gyro_lsb_per_dps(fs_sel));
  std::vector<double> u(y.begin(), y.begin() + static_cast<std::ptrdiff_t>(std::min<std::size_t>(y.size(), 20000)));
  const double spread = spread_5_95(u);
  std::sort(u.begin(), u.end());
  u.erase(std::unique(u.begin(), u.end(), [](double a, double b) { return std::abs(a - b) < 2e-7; }), u.end());
  std::vector<double> d;
  for (std::size_t i = 1; i < u.size(); ++i) d.push_back(u[i] - u[i - 1]);
  if (d.size() > 10) {
    std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
    steps.push_back(d[d.size() / 2]);
  }
  double best = 0.0;
  *strength = 0.0;
  std::vector<double> tried;
  for (double st : steps) {
    if (!(st > 1e-6) || std::find(tried.begin(), tried.end(), st) != tried.end()) continue;  // a step twice: once
    tried.push_back(st);
    if (spread < 2.0 * st) continue;  // the outputs do not span it: not testable
    const double R = lattice(y, st, 0.9);
    if (R > 0.9 && st > best) best = st, *strength = R;
  }
  return best;
}

// codes with zero count whose neighbours on both sides are well populated
std::vector<long> missing_codes(const std::vector<double>& y, double lsb, double log_m, double* evidence) {
  std::vector<long> out;
  *evidence = 0.0;
  if (y.empty()) return out;
  // the codes are formed twice (range, then counts) instead of stored: 2.9 MB an hour per channel
  auto code_of = [&](double v) { return std::lround(v / lsb); };
  long lo = code_of(y.front()), hi = lo;
  for (double v : y) lo = std::min(lo, code_of(v)), hi = std::max(hi, code_of(v));
  if (hi - lo >= 200000) return out;
  // a dense histogram over [lo, hi] (a tree of 360 000 insertions took a tenth of a 1 h diagnose)
  std::vector<long> hist(static_cast<std::size_t>(hi - lo + 1), 0);
  for (double v : y) ++hist[static_cast<std::size_t>(code_of(v) - lo)];
  auto cnt = [&](long c) { return static_cast<double>(hist[static_cast<std::size_t>(c - lo)]); };
  for (long code = lo + 2; code <= hi - 2; ++code) {
    if (hist[static_cast<std::size_t>(code - lo)] > 0) continue;
    // both sides must be populated (a clipped pile on one side is no evidence)
    const double lam = 0.5 * std::min(cnt(code - 2) + cnt(code - 1), cnt(code + 1) + cnt(code + 2));
    if (lam < 40.0) continue;
    out.push_back(code);
    *evidence += 2.0 * lam - log_m - 2.0 * std::log(static_cast<double>(hi - lo + 1));
  }
  return out;
}

// median of the finite residuals of channel c (0 when none), from their float values (the
// residual is stored as float: the same median, half the copy)
double finite_median(const Residual& res, int c) {
  std::vector<float> v;
  v.reserve(res.n);
  for (std::size_t k = 0; k < res.n; ++k)
    if (const double e = res.e_dps(c, k); std::isfinite(e)) v.push_back(static_cast<float>(e));
  if (v.empty()) return 0.0;
  auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// saturation: repeated extreme outputs where the model, with the channel's turn-on bias (the
// residual's median; a bias of 20 deg/s is normal), predicts beyond them
double saturation_evidence(const Replay& r, const Residual& res, int c, double ymax, double tol, double floor_dps) {
  const int s = c / 3, j = c % 3;
  const double bias_dps = finite_median(res, c);
  double dj = 0.0;
  std::size_t plateau = 0;
  for (std::size_t k = 0; k < res.n; ++k) {
    if (!r.usable[k]) continue;
    const double v = r.gyro_dps[s][k][j], pv = res.pred_dps(s, j, k) + bias_dps;
    if (std::abs(std::abs(v) - ymax) <= tol && std::abs(pv) > ymax + 5.0 * floor_dps) {
      ++plateau;
      dj += std::pow((std::abs(pv) - ymax) / std::max(floor_dps, 1e-3), 2);
    }
  }
  return plateau >= 3 ? dj : 0.0;
}

void finish(Candidate& c, double evidence, double log_m) {
  c.evidence = evidence > 0 ? evidence : -log_m;
  c.chi2 = std::max(0.0, evidence);
  c.dof = static_cast<int>(c.params.size());
  c.p_value = evidence > 0 ? 0.0 : 1.0;
}

}  // namespace

namespace {

// what one channel adds to the three ADC candidates
struct ChannelAdc {
  double ev_q = 0.0, ev_m = 0.0, dj = 0.0;
  std::vector<FittedParam> q, miss, sat;
  std::vector<std::pair<int, int>> codes;
};

ChannelAdc channel_adc(const Replay& r, const Residual& res, const twin::SensorParams& p, int c, double floor_dps,
                       double log_m) {
  ChannelAdc out;
  const int s = c / 3, j = c % 3;
  std::vector<double> y, y_rest;
  y.reserve(res.n);
  for (std::size_t k = 0; k < res.n; ++k) {
    if (!r.usable[k]) continue;
    y.push_back(r.gyro_dps[s][k][j]);
    if (res.mask[k]) y_rest.push_back(y.back());
  }
  double R = 0.0;
  const double lsb = data_lsb(y_rest, p, &R);
  const double ny = static_cast<double>(y_rest.size());
  const double model_lsb = p.quantization.enabled ? 1.0 / p.quantization.sensitivity_lsb_per_dps : 0.0;
  double ev_q = -log_m;
  if (lsb > 0 && (model_lsb == 0.0 || std::abs(lsb - model_lsb) > 1e-3 * model_lsb)) {
    ev_q = std::min(2.0 * ny * R * R, 2.0 * ny) - 2 * log_m;
  } else if (lsb == 0.0 && model_lsb > 0.0) {
    const double Rm = lattice(y_rest, model_lsb, -1.0);  // the model quantises, the data lie on no lattice (the whole sum)
    ev_q = (Rm < 0.5 ? 2.0 * ny * (1.0 - Rm) * 0.01 : 0.0) - log_m;
  }
  if (ev_q > 0) {
    out.ev_q = ev_q;
    out.q.push_back(param(Param::kQuantLsbPerDps, c, lsb > 0 ? 1.0 / lsb : 0.0, 0.0,
                          p.quantization.enabled ? p.quantization.sensitivity_lsb_per_dps : 0.0));
    // a step above 1 deg/s: a 16-bit ADC's range would be +-32768 deg/s, no gyro's
    out.q.back().absurd = lsb > 1.0 / kMinPlausibleLsbPerDps;
  }
  if (lsb > 0 && !p.adc_missing_codes.enabled) {
    double ev_m = 0.0;
    const std::vector<long> codes = missing_codes(y, lsb, log_m, &ev_m);
    if (!codes.empty() && ev_m > 0) {
      out.ev_m = ev_m;
      out.miss.push_back(param(Param::kMissingCodes, c, static_cast<double>(codes.size()), 0.0, 0.0));
      for (long code : codes) out.codes.emplace_back(c, static_cast<int>(code));
    }
  }
  double ymax = 0.0;
  for (double v : y) ymax = std::max(ymax, std::abs(v));
  const double fsm = p.saturation.enabled ? p.saturation.full_scale_dps : kInf;
  const double dj = saturation_evidence(r, res, c, ymax, std::max(lsb, 1e-6) * 0.51, floor_dps);
  if (dj > log_m && ymax < fsm - 1e-6) {
    out.dj = dj - log_m;
    out.sat.push_back(param(Param::kFullScaleDps, c, ymax, lsb, p.saturation.enabled ? p.saturation.full_scale_dps : 0.0));
  }
  return out;
}

}  // namespace

std::vector<Candidate> adc_candidates(const Replay& r, const Residual& res, const CompareModel& model,
                                      const std::array<double, 6>& noise_floor_dps, double log_m) {
  // the channels on the machine's cores, then added up in channel order (the same sums)
  std::array<ChannelAdc, 6> per;
  for_each_index(res.channels(), [&](int c) {
    per[static_cast<std::size_t>(c)] = channel_adc(r, res, model.sensor[c / 3], c, noise_floor_dps[c], log_m);
  });
  Candidate q, sat, miss;
  q.effect = Effect::kQuantization;
  sat.effect = Effect::kSaturation;
  miss.effect = Effect::kAdcMissingCodes;
  double qev = 0, sev = 0, mev = 0;
  for (int c = 0; c < res.channels(); ++c) {
    const ChannelAdc& a = per[static_cast<std::size_t>(c)];
    qev += a.ev_q, mev += a.ev_m, sev += a.dj;
    q.params.insert(q.params.end(), a.q.begin(), a.q.end());
    miss.params.insert(miss.params.end(), a.miss.begin(), a.miss.end());
    miss.codes.insert(miss.codes.end(), a.codes.begin(), a.codes.end());
    sat.params.insert(sat.params.end(), a.sat.begin(), a.sat.end());
  }
  finish(q, qev, log_m);
  for (const auto& fp : q.params) q.absurd = q.absurd || fp.absurd;
  finish(sat, sev, log_m);
  finish(miss, mev, log_m);
  return {q, sat, miss};
}

}  // namespace driftless::diagnose
