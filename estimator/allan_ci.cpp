// Confidence intervals of the Allan-family deviations: lag-1 autocorrelation noise identification,
// Greenhall's equivalent degrees of freedom, chi-square intervals (docs/allan.md, intervals).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "estimator/allan.hpp"
#include "estimator/stats.hpp"

namespace driftless::est {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- Greenhall & Riley (2003), "Uncertainty of stability variances based on finite
// differences": the generalised autocovariance of the phase, filtered, then summed ----

// eq. (7): the structure function of a power-law phase noise, up to a constant
double sw(double t, int alpha) {
  const double a = std::fabs(t);
  switch (alpha) {
    case 2: return -a;
    case 1: return t == 0.0 ? 0.0 : t * t * std::log(a);
    case 0: return a * a * a;
    case -1: return t == 0.0 ? 0.0 : t * t * t * t * std::log(a);
    case -2: return a * a * a * a * a;
    case -3: return t == 0.0 ? 0.0 : std::pow(t, 6) * std::log(a);
    case -4: return std::pow(a, 7);
    default: break;
  }
  throw std::invalid_argument("greenhall_edf: alpha must be in +2..-4");
}

// eq. (8): after the averaging filter of factor F (F = infinity: the continuous limit)
double sx(double t, double F, int alpha) {
  if (F == kInf) return sw(t, alpha + 2);
  return F * F * (2.0 * sw(t, alpha) - sw(t - 1.0 / F, alpha) - sw(t + 1.0 / F, alpha));
}

// eq. (9): after the d-th difference: sum_k (-1)^k C(2d, d - |k|) sx(t + k)
double sz(double t, double F, int alpha, int d) {
  static constexpr std::array<std::array<double, 4>, 4> kBinom = {{
      {1, 0, 0, 0}, {2, 1, 0, 0}, {6, 4, 1, 0}, {20, 15, 6, 1}}};  // C(2d, d - k), k = 0..d
  double s = kBinom[d][0] * sx(t, F, alpha);
  for (int k = 1; k <= d; ++k) {
    const double sign = (k % 2 == 1) ? -1.0 : 1.0;
    s += sign * kBinom[d][k] * (sx(t - k, F, alpha) + sx(t + k, F, alpha));
  }
  return s;
}

// eq. (10)
double basic_sum(double J, double M, double S, double F, int alpha, int d) {
  const double z0 = sz(0.0, F, alpha, d);
  const double zj = sz(J / S, F, alpha, d);
  double sum = z0 * z0 + (1.0 - J / M) * zj * zj;
  for (int j = 1; j < static_cast<int>(J); ++j) {
    const double z = sz(j / S, F, alpha, d);
    sum += 2.0 * (1.0 - j / M) * z * z;
  }
  return sum;
}

struct Coef {
  double a0, a1;
};

// tables 1 and 2 (rows alpha = +2..-4, columns d = 1..3); NaN where the variance does not converge
constexpr double kN = std::numeric_limits<double>::quiet_NaN();
constexpr std::array<std::array<Coef, 3>, 7> kTable1 = {{
    {{{2.0 / 3.0, 1.0 / 3.0}, {7.0 / 9.0, 1.0 / 2.0}, {22.0 / 25.0, 2.0 / 3.0}}},
    {{{0.840, 0.345}, {0.997, 0.616}, {1.141, 0.843}}},
    {{{1.079, 0.368}, {1.033, 0.607}, {1.184, 0.848}}},
    {{{kN, kN}, {1.048, 0.534}, {1.180, 0.816}}},
    {{{kN, kN}, {1.302, 0.535}, {1.175, 0.777}}},
    {{{kN, kN}, {kN, kN}, {1.194, 0.703}}},
    {{{kN, kN}, {kN, kN}, {1.489, 0.702}}},
}};
constexpr std::array<std::array<Coef, 3>, 7> kTable2 = {{
    {{{3.0 / 2.0, 1.0 / 2.0}, {35.0 / 18.0, 1.0}, {231.0 / 100.0, 3.0 / 2.0}}},
    {{{78.6, 25.2}, {790.0, 410.0}, {9950.0, 6520.0}}},
    {{{2.0 / 3.0, 1.0 / 6.0}, {2.0 / 3.0, 1.0 / 3.0}, {7.0 / 9.0, 1.0 / 2.0}}},
    {{{kN, kN}, {0.852, 0.375}, {0.997, 0.617}}},
    {{{kN, kN}, {1.079, 0.368}, {1.033, 0.607}}},
    {{{kN, kN}, {kN, kN}, {1.053, 0.553}}},
    {{{kN, kN}, {kN, kN}, {1.302, 0.535}}},
}};
// table 3 (alpha = +1, unmodified): b0 + b1 ln m
constexpr std::array<Coef, 3> kTable3 = {{{6.0, 4.0}, {15.23, 12.0}, {47.8, 40.0}}};

constexpr double kJmax = 100.0;

double inv_edf_basic(double J, double M, double S, double F, int alpha, int d) {
  const double z0 = sz(0.0, F, alpha, d);
  return basic_sum(J, M, S, F, alpha, d) / (z0 * z0 * M);
}

// one degree of freedom is the floor: fewer would make the interval unbounded above
double finish_edf(double inv_edf) {
  const double edf = 1.0 / inv_edf;
  return std::isfinite(edf) && edf > 1.0 ? edf : 1.0;
}

// lag-1 autocorrelation (Riley & Greenhall 2004, eq. 2): mean removed
double lag1_acf(const std::vector<double>& x) {
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(x.size());
  double num = 0.0, den = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double a = x[i] - mean;
    den += a * a;
    if (i + 1 < x.size()) num += a * (x[i + 1] - mean);
  }
  return den > 0.0 ? num / den : 0.0;
}

// removes the least-squares line (frequency drift) from x
void detrend_linear(std::vector<double>& x) {
  const double n = static_cast<double>(x.size());
  const double tm = 0.5 * (n - 1.0);
  double xm = 0.0;
  for (double v : x) xm += v;
  xm /= n;
  double stt = 0.0, sty = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double t = static_cast<double>(i) - tm;
    stt += t * t;
    sty += t * (x[i] - xm);
  }
  const double slope = stt > 0.0 ? sty / stt : 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) x[i] -= xm + slope * (static_cast<double>(i) - tm);
}

int min_alpha(Deviation dev) { return dev == Deviation::kHadamard ? -4 : -2; }
int difference_order(Deviation dev) { return dev == Deviation::kHadamard ? 3 : 2; }

// edf of one point summed over the record's segments; phase points counted at `scale`
double point_edf(const AllanCurve& c, const AllanPoint& p, int alpha, std::size_t scale,
                 const std::vector<std::size_t>& segment_lengths) {
  const int d = difference_order(c.deviation);
  const bool modified = c.deviation == Deviation::kModifiedAllan;
  const bool overlapping = modified || c.overlapping;
  const std::size_t m = std::max<std::size_t>(1, (p.m + scale / 2) / scale);
  double edf = 0.0;
  for (const std::size_t n : segment_lengths) {
    const std::size_t n_scaled = n / scale;
    // a segment contributes only if it holds at least one full difference at this m
    if (n_scaled + 1 < static_cast<std::size_t>(d) * m + (modified ? m : 1)) continue;
    edf += greenhall_edf(alpha, d, m, n_scaled + 1, overlapping, modified);
  }
  return std::max(1.0, edf);
}

}  // namespace

double greenhall_edf(int alpha, int d, std::size_t m_in, std::size_t n_phase, bool overlapping,
                     bool modified) {
  if (d < 1 || d > 3) throw std::invalid_argument("greenhall_edf: d must be 1, 2 or 3");
  if (alpha > 2 || alpha < -4 || alpha + 2 * d <= 1) {
    throw std::invalid_argument("greenhall_edf: the variance does not converge for alpha = " +
                                std::to_string(alpha) + " with d = " + std::to_string(d));
  }
  // at m = 1 the modified variance is the Allan variance itself
  if (modified && m_in == 1) modified = false, overlapping = true;
  const double m = static_cast<double>(m_in);
  const double N = static_cast<double>(n_phase);
  const double F = modified ? 1.0 : m;        // filter factor
  const double S = overlapping ? m : 1.0;     // stride factor
  const double L = m / F + m * d;             // filter length in phase samples
  if (N < L) return 1.0;
  const double M = 1.0 + std::floor(S * (N - L) / m);
  const double J = std::min(M, (d + 1) * S);
  const double r = M / S;
  const int row = 2 - alpha;
  if (modified) {  // case 1: modified variances, every alpha
    if (J <= kJmax) return finish_edf(inv_edf_basic(J, M, S, 1.0, alpha, d));
    if (r > d + 1) {
      const Coef c = kTable1[row][d - 1];
      return finish_edf((c.a0 - c.a1 / r) / r);
    }
    return finish_edf(inv_edf_basic(kJmax, kJmax, kJmax / r, 1.0, alpha, d));
  }
  if (alpha <= 0) {  // case 2: unmodified, alpha <= 0
    // rate samples are exact differences of the sampled phase (no averaging inside a sample):
    // the unfiltered limit F = infinity, which Monte Carlo of sampled white, flicker and random-walk
    // FM confirms at every m (F = m reads white FM at m = 1 17 % too many degrees of freedom)
    if (J <= kJmax) return finish_edf(inv_edf_basic(J, M, S, kInf, alpha, d));
    if (r > d + 1) {
      const Coef c = kTable2[row][d - 1];
      return finish_edf((c.a0 - c.a1 / r) / r);
    }
    return finish_edf(inv_edf_basic(kJmax, kJmax, kJmax / r, kInf, alpha, d));
  }
  if (alpha == 1) {  // case 3: unmodified, flicker PM
    if (J <= kJmax) return finish_edf(inv_edf_basic(J, M, S, m, 1, d));
    const Coef b = kTable3[d - 1];
    const double bl = b.a0 + b.a1 * std::log(m);
    if (r > d + 1) {
      const Coef c = kTable2[row][d - 1];
      return finish_edf((c.a0 - c.a1 / r) / (bl * bl * r));
    }
    const double mp = kJmax / r;
    return finish_edf(basic_sum(kJmax, kJmax, mp, mp, 1, d) / (bl * bl * kJmax));
  }
  // case 4: unmodified, white PM
  if (std::ceil(r) <= d) return finish_edf(inv_edf_basic(J, M, S, m, 2, d));
  static constexpr std::array<double, 4> kA0 = {0.0, 6.0 / 4.0, 70.0 / 36.0, 924.0 / 400.0};  // C(4d,2d)/C(2d,d)^2
  return finish_edf((kA0[d] - 0.5 * d / r) / M);
}

double allan_edf(std::size_t n, std::size_t m, NoiseType noise) {
  // NIST SP 1065 table 5 (Howe's simplified formulas); N counts phase points = rate samples + 1
  const double N = static_cast<double>(n) + 1.0;
  const double M = static_cast<double>(m);
  double edf = 1.0;
  switch (noise) {
    case NoiseType::kWhitePM: edf = (N + 1.0) * (N - 2.0 * M) / (2.0 * (N - M)); break;
    case NoiseType::kFlickerPM:
      edf = std::exp(std::sqrt(std::max(0.0, std::log((N - 1.0) / (2.0 * M)) *
                                                 std::log((2.0 * M + 1.0) * (N - 1.0) / 4.0))));
      break;
    case NoiseType::kWhiteFM:
      edf = (3.0 * (N - 1.0) / (2.0 * M) - 2.0 * (N - 2.0) / N) * 4.0 * M * M / (4.0 * M * M + 5.0);
      break;
    case NoiseType::kFlickerFM:
      edf = m == 1 ? 2.0 * (N - 2.0) * (N - 2.0) / (2.3 * N - 4.9) : 5.0 * N * N / (4.0 * M * (N + 3.0 * M));
      break;
    default:  // random-walk FM and the Hadamard-only types: the RWFM formula
      edf = (N - 2.0) / M * ((N - 1.0) * (N - 1.0) - 3.0 * M * (N - 1.0) + 4.0 * M * M) /
            ((N - 3.0) * (N - 3.0));
      break;
  }
  return std::isfinite(edf) ? std::max(1.0, edf) : 1.0;
}

bool lag1_noise_id(std::span<const double> cluster_means, int dmax, int* alpha_out, double* rho_out) {
  if (cluster_means.size() < 30) return false;
  std::vector<double> x(cluster_means.begin(), cluster_means.end());
  detrend_linear(x);  // frequency drift is not noise
  for (int d = 0;; ++d) {
    const double r1 = lag1_acf(x);
    const double rho = r1 / (1.0 + r1);
    if (rho < 0.25 || d >= dmax || x.size() < 31) {
      *alpha_out = static_cast<int>(-std::lround(2.0 * rho)) - 2 * d;
      if (rho_out != nullptr) *rho_out = rho;
      return true;
    }
    for (std::size_t i = 0; i + 1 < x.size(); ++i) x[i] = x[i + 1] - x[i];
    x.pop_back();
  }
}

void confidence_interval(double dev, double edf, double confidence, double* lo, double* hi) {
  const double a = 1.0 - confidence;
  const double var = dev * dev;
  *lo = std::sqrt(var * edf / chi2_quantile(1.0 - 0.5 * a, edf));
  *hi = std::sqrt(var * edf / chi2_quantile(0.5 * a, edf));
}

const char* to_string(NoiseType t) {
  switch (t) {
    case NoiseType::kWhitePM: return "white_pm";
    case NoiseType::kFlickerPM: return "flicker_pm";
    case NoiseType::kWhiteFM: return "white_fm";
    case NoiseType::kFlickerFM: return "flicker_fm";
    case NoiseType::kRandomWalkFM: return "random_walk_fm";
    case NoiseType::kFlickerWalkFM: return "flicker_walk_fm";
    case NoiseType::kRandomRunFM: return "random_run_fm";
  }
  return "?";
}

int alpha_of(NoiseType t) { return 2 - static_cast<int>(t); }

NoiseType noise_of_alpha(int alpha) { return static_cast<NoiseType>(2 - std::clamp(alpha, -4, 2)); }

void attach_confidence_intervals(AllanCurve& curve, const CiInput& in) {
  const int dmax = difference_order(curve.deviation);
  int alpha = 0;
  bool have = false;
  std::size_t pm_run_scale = 0;  // m where the current run of phase-noise types began (0: none)
  for (std::size_t i = 0; i < curve.points.size(); ++i) {
    AllanPoint& p = curve.points[i];
    int a = 0;
    const bool identified = i < in.cluster_means.size() && lag1_noise_id(in.cluster_means[i], dmax, &a);
    if (identified) {
      alpha = std::clamp(a, min_alpha(curve.deviation), 2);
      have = true;
    }
    p.noise_inherited = !identified;
    if (!have) {
      // nothing identified yet (too few clusters from the first tau on): the type with the
      // fewest degrees of freedom among the drift types keeps the interval honest
      double best = std::numeric_limits<double>::infinity();
      for (int cand : {0, -1, -2}) {
        const double e = point_edf(curve, p, cand, 1, in.segment_lengths);
        if (e < best) best = e, a = cand;
      }
      alpha = a;
    }
    p.noise = noise_of_alpha(alpha);
    // a phase-noise type (alpha >= 1) that appears only from some m on means the phase is white
    // at that spacing but correlated below it (e.g. a corrected channel: the filter removed the
    // slow part): count phase points at that spacing, never per sample
    if (alpha >= 1) {
      if (pm_run_scale == 0) pm_run_scale = (i == 0 && p.m == 1) ? 1 : p.m;
    } else {
      pm_run_scale = 0;
    }
    p.phase_scale_m = std::max<std::size_t>(1, pm_run_scale);
    p.edf = point_edf(curve, p, alpha, p.phase_scale_m, in.segment_lengths);
    confidence_interval(p.adev, p.edf, curve.confidence, &p.adev_lo, &p.adev_hi);
  }
}

}  // namespace driftless::est
