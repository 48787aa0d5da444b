#include "estimator/allan.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "estimator/stats.hpp"

namespace driftless::est {
namespace {

constexpr double kBiasInstabilityFactor = 0.6642824702679600;  // sqrt(2 ln 2 / pi)

// cluster sizes to evaluate, ascending and unique
std::vector<std::size_t> cluster_sizes(std::size_t n, const AllanOptions& opt) {
  // largest m: overlapping needs N + 1 - 2m >= 1 difference; non-overlapping needs 2 clusters
  std::size_t m_max = n / 2;  // overlapping: n + 1 - 2m >= 1; non-overlapping: n / m >= 2
  if (opt.max_tau_s > 0.0) {
    const double m_cap = std::floor(opt.max_tau_s * opt.sample_rate_hz + 1e-9);
    if (m_cap < static_cast<double>(m_max)) m_max = static_cast<std::size_t>(std::max(1.0, m_cap));
  }
  std::vector<std::size_t> ms;
  switch (opt.spacing) {
    case TauSpacing::kOctave:
      for (std::size_t m = 1; m <= m_max; m *= 2) ms.push_back(m);
      break;
    case TauSpacing::kLogSpaced: {
      const double step = std::pow(10.0, 1.0 / opt.points_per_decade);
      for (double x = 1.0; x <= static_cast<double>(m_max) + 0.5; x *= step) {
        const auto m = static_cast<std::size_t>(std::llround(x));
        if (m >= 1 && m <= m_max && (ms.empty() || ms.back() != m)) ms.push_back(m);
      }
      break;
    }
    case TauSpacing::kAll:
      for (std::size_t m = 1; m <= m_max; ++m) ms.push_back(m);
      break;
  }
  return ms;
}

NoiseType noise_from_slope(double slope) {
  // adev ~ tau^slope: WPM -1, WFM -1/2, FFM 0, RWFM +1/2
  if (slope < -0.75) return NoiseType::kWhitePM;
  if (slope < -0.25) return NoiseType::kWhiteFM;
  if (slope < 0.25) return NoiseType::kFlickerFM;
  return NoiseType::kRandomWalkFM;
}

// local log-log slope of the curve at every point (central where possible)
std::vector<double> local_slopes(const std::vector<AllanPoint>& pts) {
  std::vector<double> s(pts.size(), -0.5);
  if (pts.size() < 2) return s;
  auto slope = [&](std::size_t a, std::size_t b) {
    if (!(pts[a].adev > 0.0) || !(pts[b].adev > 0.0)) return 0.0;
    return std::log(pts[b].adev / pts[a].adev) / std::log(pts[b].tau_s / pts[a].tau_s);
  };
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const std::size_t a = i == 0 ? 0 : i - 1;
    const std::size_t b = i + 1 == pts.size() ? i : i + 1;
    s[i] = slope(a, b);
  }
  return s;
}

}  // namespace

void AllanOptions::validate() const {
  if (!(sample_rate_hz > 0.0) || !std::isfinite(sample_rate_hz)) {
    throw std::invalid_argument("allan: sample_rate_hz must be a positive number (Hz)");
  }
  if (points_per_decade < 1 || points_per_decade > 1000) {
    throw std::invalid_argument("allan: points_per_decade must be in 1..1000");
  }
  if (!(max_tau_s >= 0.0)) throw std::invalid_argument("allan: max_tau_s must be >= 0 s (0 = no cap)");
  if (!(confidence > 0.0 && confidence < 1.0)) {
    throw std::invalid_argument("allan: confidence must be in (0, 1), e.g. 0.683");
  }
}

const char* to_string(NoiseType t) {
  switch (t) {
    case NoiseType::kWhitePM: return "white_pm";
    case NoiseType::kFlickerPM: return "flicker_pm";
    case NoiseType::kWhiteFM: return "white_fm";
    case NoiseType::kFlickerFM: return "flicker_fm";
    case NoiseType::kRandomWalkFM: return "random_walk_fm";
  }
  return "?";
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
    case NoiseType::kRandomWalkFM:
      edf = (N - 2.0) / M * ((N - 1.0) * (N - 1.0) - 3.0 * M * (N - 1.0) + 4.0 * M * M) /
            ((N - 3.0) * (N - 3.0));
      break;
  }
  // the simplified formulas lose meaning at the longest taus; one degree is the floor
  return std::isfinite(edf) ? std::max(1.0, edf) : 1.0;
}

AllanCurve allan_deviation(std::span<const double> rate, const AllanOptions& opt) {
  opt.validate();
  const std::size_t n = rate.size();
  if (n < 3) throw std::invalid_argument("allan: need at least 3 samples, got " + std::to_string(n));
  // subtract the mean first: keeps the cumulative sum small, so its rounding stays far below noise
  double mean = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(rate[i])) {
      throw std::invalid_argument("allan: sample " + std::to_string(i) +
                                  " is not a finite number (drop or fill NaN samples first)");
    }
    mean += rate[i];
  }
  mean /= static_cast<double>(n);
  std::vector<double> cum(n + 1);  // cum[i] = sum of the first i samples (phase, in samples)
  cum[0] = 0.0;
  for (std::size_t i = 0; i < n; ++i) cum[i + 1] = cum[i] + (rate[i] - mean);

  AllanCurve curve;
  curve.sample_rate_hz = opt.sample_rate_hz;
  curve.samples = n;
  curve.overlapping = opt.overlapping;
  const double tau0 = 1.0 / opt.sample_rate_hz;
  for (const std::size_t m : cluster_sizes(n, opt)) {
    AllanPoint p;
    p.m = m;
    p.tau_s = static_cast<double>(m) * tau0;
    double sum = 0.0;
    if (opt.overlapping) {
      const std::size_t terms = n + 1 - 2 * m;
      const double* c = cum.data();
      for (std::size_t i = 0; i < terms; ++i) {
        const double d = c[i + 2 * m] - 2.0 * c[i + m] + c[i];
        sum += d * d;
      }
      p.terms = terms;
      p.adev = std::sqrt(sum / (2.0 * double(m) * double(m) * double(terms)));
    } else {
      const std::size_t clusters = n / m;  // K
      for (std::size_t k = 0; k + 1 < clusters; ++k) {
        const double d = cum[(k + 2) * m] - 2.0 * cum[(k + 1) * m] + cum[k * m];
        sum += d * d;
      }
      p.terms = clusters - 1;
      p.adev = std::sqrt(sum / (2.0 * double(m) * double(m) * double(p.terms)));
    }
    curve.points.push_back(p);
  }

  // noise type from the local slope, then edf and the chi-square confidence interval
  const auto slopes = local_slopes(curve.points);
  const double alpha = 1.0 - opt.confidence;
  for (std::size_t i = 0; i < curve.points.size(); ++i) {
    AllanPoint& p = curve.points[i];
    p.noise = noise_from_slope(slopes[i]);
    // non-overlapping differences are nearly independent: edf ~ number of differences
    p.edf = opt.overlapping ? allan_edf(n, p.m, p.noise) : std::max(1.0, double(p.terms));
    const double var = p.adev * p.adev;
    p.adev_lo = std::sqrt(var * p.edf / chi2_quantile(1.0 - 0.5 * alpha, p.edf));
    p.adev_hi = std::sqrt(var * p.edf / chi2_quantile(0.5 * alpha, p.edf));
  }
  return curve;
}

NoiseFit fit_noise_parameters(const AllanCurve& curve) {
  NoiseFit fit;
  const auto& pts = curve.points;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  fit.N.value = fit.B.value = fit.K.value = nan;
  fit.N.sigma = fit.B.sigma = fit.K.sigma = nan;
  fit.N.tau_s = 1.0;
  fit.K.tau_s = 3.0;
  if (pts.size() < 2) {
    fit.N.note = fit.B.note = fit.K.note = "too few averaging times for a fit";
    return fit;
  }
  const auto slopes = local_slopes(pts);

  // the minimum, searched over points with at least 2 degrees of freedom (the last few are noisy)
  std::size_t imin = 0;
  bool found = false;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (pts[i].edf < 2.0 && found) continue;
    if (!found || pts[i].adev < pts[imin].adev) imin = i;
    found = true;
  }
  std::size_t last_searched = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (pts[i].edf >= 2.0) last_searched = i;
  }

  // a line of fixed slope through points [lo, hi] with |slope - target| < 0.25, weighted by edf;
  // returns the value at tau_ref and its relative sigma
  auto fit_line = [&](std::size_t lo, std::size_t hi, double target, double tau_ref,
                      std::size_t m_min, NoiseParameter& out, const char* what) {
    double sw = 0.0, swy = 0.0, edf_max = 0.0;
    for (std::size_t i = lo; i <= hi && i < pts.size(); ++i) {
      if (std::fabs(slopes[i] - target) >= 0.25 || !(pts[i].adev > 0.0)) continue;
      if (pts[i].m < m_min) continue;
      const double w = 2.0 * pts[i].edf;  // var(ln adev) ~ 1 / (2 edf)
      sw += w;
      swy += w * (std::log(pts[i].adev) - target * std::log(pts[i].tau_s / tau_ref));
      edf_max = std::max(edf_max, pts[i].edf);
    }
    if (sw == 0.0) {
      out.note = std::string("no ") + what + " region in the curve";
      return;
    }
    out.value = std::exp(swy / sw);
    // neighbouring taus share data, so the fit is no better than its best single point
    out.sigma = out.value / std::sqrt(2.0 * edf_max);
    out.valid = true;
  };

  // white noise is exact at every m; a sampled random walk reads high by (1 + 1/(2 m^2)) at small
  // m (m = 1: +22 % in adev), so K uses only m >= 10 (< 0.5 % error)
  fit_line(0, imin, -0.5, 1.0, 1, fit.N, "-1/2 slope (white noise)");
  if (imin + 1 < pts.size()) {
    fit_line(imin, pts.size() - 1, 0.5, 3.0, 10, fit.K, "+1/2 slope (rate random walk)");
  }
  else fit.K.note = "curve never rises: no +1/2 slope (rate random walk) region";

  const AllanPoint& pm = pts[imin];
  fit.B.value = pm.adev / kBiasInstabilityFactor;
  fit.B.sigma = fit.B.value / std::sqrt(2.0 * pm.edf);
  fit.B.tau_s = pm.tau_s;
  fit.B.valid = true;
  if (imin == last_searched && slopes[imin] < -0.25) {
    fit.B.note = "upper bound: the curve is still falling at the longest usable tau";
  }
  return fit;
}

}  // namespace driftless::est
