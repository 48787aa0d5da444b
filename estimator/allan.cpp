// Allan, modified Allan and Hadamard deviations of an in-memory record, exact at every tau
// (the bounded-memory streaming pass is estimator/allan_stream.cpp). Docs: docs/allan.md.
#include "estimator/allan.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <thread>

#include "estimator/allan_terms.hpp"
#include "estimator/huge_pages.hpp"

namespace driftless::est {
namespace {

// the largest m a record of n samples allows for a deviation (at least one term)
std::size_t max_cluster(std::size_t n, const AllanOptions& opt) {
  switch (opt.deviation) {
    case Deviation::kAllan: return n / 2;
    case Deviation::kModifiedAllan: return (n + 1) / 3;
    case Deviation::kHadamard: return n / 3;
  }
  return n / 2;
}

void push_unique(std::vector<std::size_t>& ms, std::size_t m) {
  if (ms.empty() || ms.back() != m) ms.push_back(m);
}

std::vector<std::size_t> explicit_sizes(std::size_t m_max, const AllanOptions& opt,
                                        std::vector<std::string>* notes) {
  std::vector<std::size_t> ms;
  for (const double tau : opt.tau_s) {
    const double m_real = tau * opt.sample_rate_hz;
    const auto m = static_cast<std::size_t>(std::max(1.0, std::round(m_real)));
    if (m > m_max) {
      if (notes != nullptr) {
        notes->push_back("tau " + std::to_string(tau) + " s dropped: longer than the record allows (" +
                         std::to_string(static_cast<double>(m_max) / opt.sample_rate_hz) + " s)");
      }
      continue;
    }
    if (notes != nullptr && std::fabs(m_real - static_cast<double>(m)) > 1e-6 * m_real) {
      notes->push_back("tau " + std::to_string(tau) + " s is not a whole number of samples: used " +
                       std::to_string(static_cast<double>(m) / opt.sample_rate_hz) + " s");
    }
    ms.push_back(m);
  }
  std::sort(ms.begin(), ms.end());
  ms.erase(std::unique(ms.begin(), ms.end()), ms.end());
  return ms;
}

// one gap-free segment's phase: the cumulative sum of the mean-removed rate, S[0] = 0 (not
// zero-filled first: every value is written once)
struct Phase {
  std::unique_ptr<double[]> v;
  std::size_t size = 0;
  const double* data() const { return v.get(); }
};

Phase phase_of(const double* r, std::size_t n, double mean) {
  Phase S{std::make_unique_for_overwrite<double[]>(n + 1), n + 1};
  advise_huge_pages(S.v.get(), (n + 1) * sizeof(double));
  double acc = 0.0;
  S.v[0] = 0.0;
  for (std::size_t i = 0; i < n; ++i) S.v[i + 1] = acc += r[i] - mean;
  return S;
}

// the mean of the rate, refusing a NaN or an infinity by its index (four partial sums, so the
// adds do not wait on each other)
double finite_mean(std::span<const double> rate) {
  const std::size_t n = rate.size();
  double s[4] = {0.0, 0.0, 0.0, 0.0};
  bool finite = true;
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    for (std::size_t k = 0; k < 4; ++k) {
      s[k] += rate[i + k];
      finite &= std::isfinite(rate[i + k]);
    }
  }
  for (; i < n; ++i) s[0] += rate[i], finite &= std::isfinite(rate[i]);
  if (!finite) {
    const auto bad = std::find_if(rate.begin(), rate.end(), [](double v) { return !std::isfinite(v); });
    throw std::invalid_argument("allan: sample " + std::to_string(bad - rate.begin()) +
                                " is not a finite number (drop or fill NaN samples first)");
  }
  return ((s[0] + s[1]) + (s[2] + s[3])) / static_cast<double>(n);
}

// the non-overlapping m-averages (mean removed) of a segment from its phase, at most
// kMaxIdClusters of them
std::vector<double> cluster_means(const Phase& S, std::size_t m) {
  const std::size_t k = std::min((S.size - 1) / m, kMaxIdClusters);
  std::vector<double> out(k);
  const double inv_m = 1.0 / static_cast<double>(m);
  for (std::size_t c = 0; c < k; ++c) out[c] = (S.v[(c + 1) * m] - S.v[c * m]) * inv_m;
  return out;
}

// the levels j = first, first + step, ... of one phase array; overlapping Allan and Hadamard sums
// run block by block across the levels, so the stretches of S one level reads are still cached
// for the next (octave m: S[i + 2m] of one level is S[i + m'] of the next)
void accumulate_some_levels(Deviation dev, const Phase& S, const std::vector<std::size_t>& ms, std::size_t first,
                            std::size_t step, std::vector<TermSum>& sums) {
  if (dev == Deviation::kModifiedAllan) {
    for (std::size_t j = first; j < ms.size(); j += step) accumulate_terms(dev, S.data(), S.size, ms[j], 1, sums[j]);
    return;
  }
  constexpr std::size_t kBlock = 2048;
  const std::size_t span = span_in_m(dev);
  for (std::size_t i0 = 0; i0 < S.size; i0 += kBlock) {
    for (std::size_t j = first; j < ms.size(); j += step) {
      if (S.size <= span * ms[j]) break;
      const std::size_t i1 = std::min(i0 + kBlock, S.size - span * ms[j]);
      if (i0 < i1) accumulate_range(dev, S.data(), i0, i1, ms[j], 1, sums[j]);
    }
  }
}

// every level's overlapping terms; a long record shares the levels between this thread and one
// more (every level's sum is formed in the same order either way: the result does not depend on
// the threads)
constexpr std::size_t kThreadFromTerms = 1u << 21;

void accumulate_levels(Deviation dev, const Phase& S, const std::vector<std::size_t>& ms, std::vector<TermSum>& sums) {
  if (S.size * ms.size() < kThreadFromTerms || ms.size() < 2) return accumulate_some_levels(dev, S, ms, 0, 1, sums);
  std::thread helper([&] { accumulate_some_levels(dev, S, ms, 1, 2, sums); });
  accumulate_some_levels(dev, S, ms, 0, 2, sums);
  helper.join();
}

struct Segments {
  std::vector<std::size_t> begin, length;
};

Segments split_segments(std::size_t n, std::span<const std::size_t> starts) {
  Segments s;
  std::vector<std::size_t> b(starts.begin(), starts.end());
  if (b.empty() || b.front() != 0) b.insert(b.begin(), 0);
  for (std::size_t i = 0; i < b.size(); ++i) {
    const std::size_t end = i + 1 < b.size() ? b[i + 1] : n;
    if (b[i] > n || end < b[i] || (i + 1 < b.size() && b[i + 1] <= b[i])) {
      throw std::invalid_argument("allan: segment starts must be ascending sample indices below the record length");
    }
    s.begin.push_back(b[i]);
    s.length.push_back(end - b[i]);
  }
  return s;
}

}  // namespace

const char* to_string(Deviation d) {
  switch (d) {
    case Deviation::kAllan: return "adev";
    case Deviation::kModifiedAllan: return "mdev";
    case Deviation::kHadamard: return "hdev";
  }
  return "?";
}

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
  if (spacing == TauSpacing::kExplicit) {
    if (tau_s.empty()) throw std::invalid_argument("allan: an explicit tau list needs at least one tau (s)");
    for (const double t : tau_s) {
      if (!(t > 0.0) || !std::isfinite(t)) throw std::invalid_argument("allan: every tau must be > 0 s");
    }
  }
  if (deviation == Deviation::kModifiedAllan && !overlapping) {
    throw std::invalid_argument("allan: the modified Allan deviation is overlapping by definition");
  }
}

std::vector<std::size_t> cluster_sizes(std::size_t n, const AllanOptions& opt, std::vector<std::string>* notes) {
  std::size_t m_max = max_cluster(n, opt);
  if (opt.max_tau_s > 0.0) {
    const double m_cap = std::floor(opt.max_tau_s * opt.sample_rate_hz + 1e-9);
    if (m_cap < static_cast<double>(m_max)) m_max = static_cast<std::size_t>(std::max(1.0, m_cap));
  }
  std::vector<std::size_t> ms;
  switch (opt.spacing) {
    case TauSpacing::kOctave:
      for (std::size_t m = 1; m <= m_max; m *= 2) ms.push_back(m);
      break;
    case TauSpacing::kDecade:
      for (std::size_t dec = 1; dec <= m_max; dec *= 10) {
        for (const std::size_t k : {1, 2, 4}) {
          if (k * dec <= m_max) ms.push_back(k * dec);
        }
      }
      break;
    case TauSpacing::kPerDecade: {
      const double step = std::pow(10.0, 1.0 / opt.points_per_decade);
      for (int i = 0;; ++i) {
        const double x = std::pow(step, i);
        if (x > static_cast<double>(m_max) + 0.5) break;
        const auto m = static_cast<std::size_t>(std::llround(x));
        if (m >= 1 && m <= m_max) push_unique(ms, m);
      }
      break;
    }
    case TauSpacing::kAll:
      for (std::size_t m = 1; m <= m_max; ++m) ms.push_back(m);
      break;
    case TauSpacing::kExplicit:
      ms = explicit_sizes(m_max, opt, notes);
      break;
  }
  return ms;
}

AllanCurve allan_deviation(std::span<const double> rate, const AllanOptions& opt,
                           std::span<const std::size_t> segment_starts) {
  opt.validate();
  const std::size_t n = rate.size();
  if (n < 3) throw std::invalid_argument("allan: need at least 3 samples, got " + std::to_string(n));
  // subtract the mean first: keeps the cumulative sum small, so its rounding stays far below noise
  const double mean = finite_mean(rate);
  const Segments segs = split_segments(n, segment_starts);

  // each segment's phase (cumulative sum, starting at 0)
  std::vector<Phase> phase;
  std::size_t longest = 0;
  for (std::size_t s = 0; s < segs.begin.size(); ++s) {
    phase.push_back(phase_of(rate.data() + segs.begin[s], segs.length[s], mean));
    if (segs.length[s] > segs.length[longest]) longest = s;
  }

  AllanCurve curve;
  curve.deviation = opt.deviation;
  curve.sample_rate_hz = opt.sample_rate_hz;
  curve.samples = n;
  curve.segments = phase.size();
  curve.overlapping = opt.overlapping || opt.deviation == Deviation::kModifiedAllan;
  curve.confidence = opt.confidence;
  CiInput ci;
  ci.segment_lengths = segs.length;
  // taus up to what the longest gap-free segment allows
  const std::vector<std::size_t> ms = cluster_sizes(segs.length[longest], opt, &curve.notes);
  std::vector<TermSum> sums(ms.size());
  if (curve.overlapping) {
    for (const auto& S : phase) accumulate_levels(opt.deviation, S, ms, sums);
  } else {
    for (std::size_t j = 0; j < ms.size(); ++j) {
      for (const auto& S : phase) accumulate_terms(opt.deviation, S.data(), S.size, ms[j], ms[j], sums[j]);
    }
  }
  for (std::size_t j = 0; j < ms.size(); ++j) {
    if (sums[j].terms == 0) continue;
    AllanPoint p;
    p.m = ms[j];
    p.tau_s = static_cast<double>(ms[j]) / opt.sample_rate_hz;
    p.terms = sums[j].terms;
    p.adev = deviation_from_sum(opt.deviation, sums[j], ms[j]);
    curve.points.push_back(p);
    ci.cluster_means.push_back(cluster_means(phase[longest], ms[j]));
  }
  if (curve.points.empty()) throw std::invalid_argument("allan: no averaging time fits the record");
  attach_confidence_intervals(curve, ci);
  return curve;
}

}  // namespace driftless::est
