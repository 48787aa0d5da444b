// Allan-family deviations of a rate signal (IEEE Std 952, IEEE Std 1139, NIST SP 1065): overlapping
// Allan, modified Allan and overlapping Hadamard deviations over octave, decade, N-per-decade, every
// or explicit averaging times, gap-aware over record segments, each point with a confidence interval
// from its identified noise type (lag-1 autocorrelation) and Greenhall's equivalent degrees of
// freedom. Standard library only. Fits of the noise terms: estimator/allan_fit.hpp; the bounded-memory
// streaming pass: estimator/allan_stream.hpp. Docs: docs/allan.md.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace driftless::est {

/// Which deviation a curve holds.
enum class Deviation {
  kAllan,          // sigma_y: second difference of the phase (the IEEE 952 noise terms read on it)
  kModifiedAllan,  // Mod sigma_y: second difference of m-averaged phase (tells white from flicker PM)
  kHadamard,       // H sigma_y: third difference of the phase (insensitive to a rate ramp / linear drift)
};
/// "adev", "mdev", "hdev".
const char* to_string(Deviation d);

/// Which averaging times are evaluated (tau = m / rate, m samples per cluster).
enum class TauSpacing {
  kOctave,     // m = 1, 2, 4, 8, ...
  kDecade,     // m = 1, 2, 4, 10, 20, 40, 100, ... (Stable32 / allantools "decade")
  kPerDecade,  // points_per_decade log-spaced m per decade (rounded, unique)
  kAll,        // every m (O(N) per m: slow on long records)
  kExplicit,   // the averaging times in AllanOptions::tau_s, rounded to whole samples
};

/// Options of allan_deviation(). Units: Hz, s.
struct AllanOptions {
  double sample_rate_hz = 100.0;  // Hz, the (uniform) rate of the input samples
  Deviation deviation = Deviation::kAllan;
  bool overlapping = true;        // false: non-overlapping clusters (ADEV: the paper's section 2; HDEV)
  TauSpacing spacing = TauSpacing::kOctave;
  int points_per_decade = 10;     // for kPerDecade
  std::vector<double> tau_s;      // s, for kExplicit (each > 0; rounded to m = round(tau * rate) >= 1)
  double max_tau_s = 0.0;         // s, largest tau evaluated; 0 = as long as the data allow
  double confidence = 0.683;      // two-sided probability of the confidence interval
  /// Throws std::invalid_argument naming the field and its unit on a bad value.
  void validate() const;
};

/// Power-law noise type at one tau: the exponent alpha of the rate spectrum S_y(f) ~ f^alpha.
/// In gyro terms: white PM = angle white noise / quantisation (Q), white FM = angle random walk (N),
/// flicker FM = bias instability (B), random-walk FM = rate random walk (K); the last two are the
/// drift types the Hadamard variance converges for (a rate ramp R reads as random-run FM).
enum class NoiseType {
  kWhitePM,        // alpha = +2
  kFlickerPM,      // alpha = +1
  kWhiteFM,        // alpha =  0
  kFlickerFM,      // alpha = -1
  kRandomWalkFM,   // alpha = -2
  kFlickerWalkFM,  // alpha = -3 (Hadamard only)
  kRandomRunFM,    // alpha = -4 (Hadamard only)
};
const char* to_string(NoiseType t);
/// The spectral exponent alpha of a noise type (+2 .. -4).
int alpha_of(NoiseType t);
/// The noise type of an exponent (clamped to +2 .. -4).
NoiseType noise_of_alpha(int alpha);

/// One averaging time of a deviation curve. Units follow the input (e.g. deg/s).
struct AllanPoint {
  double tau_s = 0.0;        // s, averaging time m / rate
  std::size_t m = 0;         // samples per cluster
  double adev = 0.0;         // the deviation (ADEV, MDEV or HDEV per AllanCurve::deviation), input units
  std::size_t terms = 0;     // number of squared differences averaged (all segments)
  NoiseType noise = NoiseType::kWhiteFM;  // noise type used for the edf
  bool noise_inherited = false;  // too few clusters for the lag-1 test: the type of the next shorter tau
  std::size_t phase_scale_m = 1;  // > 1: the phase looks white only from this m on, so the edf counts
                                  // phase points at that spacing (see docs/allan.md, intervals)
  double edf = 0.0;          // equivalent degrees of freedom (Greenhall; summed over segments)
  double adev_lo = 0.0;      // confidence interval bounds at AllanOptions::confidence
  double adev_hi = 0.0;
};

/// A deviation curve.
struct AllanCurve {
  std::vector<AllanPoint> points;
  Deviation deviation = Deviation::kAllan;
  double sample_rate_hz = 0.0;
  std::size_t samples = 0;    // rate samples used (all segments)
  std::size_t segments = 1;   // contiguous pieces the record was split into at gaps
  bool overlapping = true;
  double confidence = 0.683;
  std::vector<std::string> notes;  // what was dropped or assumed (explicit taus out of range, ...)
};

/// The deviation of `rate` (uniformly sampled, finite). `segment_starts` (ascending sample indices,
/// the first may be 0) splits the record at gaps: no difference spans a gap, and the edf is the sum
/// over segments (gap-aware, not gap-filled). Exact at every tau. Throws std::invalid_argument on
/// fewer than 3 samples, a NaN, or bad options.
///  ADEV  sigma^2 = sum (S[i+2m] - 2 S[i+m] + S[i])^2 / (2 m^2 T)
///  MDEV  sigma^2 = sum (sum_{j<m} (S[i+j+2m] - 2 S[i+j+m] + S[i+j]))^2 / (2 m^4 T)
///  HDEV  sigma^2 = sum (S[i+3m] - 3 S[i+2m] + 3 S[i+m] - S[i])^2 / (6 m^2 T)
/// with S the cumulative sum of the mean-removed rate and T the number of terms (NIST SP 1065 sec. 5).
AllanCurve allan_deviation(std::span<const double> rate, const AllanOptions& opt,
                           std::span<const std::size_t> segment_starts = {});

/// Cluster sizes evaluated for a record of n samples (ascending, unique); notes say what was dropped.
std::vector<std::size_t> cluster_sizes(std::size_t n, const AllanOptions& opt,
                                       std::vector<std::string>* notes = nullptr);

// ---- confidence intervals (estimator/allan_ci.cpp) ----

/// Equivalent degrees of freedom by Greenhall's algorithm (Greenhall & Riley 2003, the method
/// NIST SP 1065 sec. 5.3 refers to for every noise type): alpha +2..-4, d = 2 (Allan, modified
/// Allan) or 3 (Hadamard), m cluster size, n_phase phase points (rate samples + 1).
double greenhall_edf(int alpha, int d, std::size_t m, std::size_t n_phase, bool overlapping,
                     bool modified);

/// Equivalent degrees of freedom of an overlapping Allan variance by NIST SP 1065 table 5 (Howe's
/// simplified formulas) for `n` rate samples, cluster size m and noise type alpha +2..-2.
double allan_edf(std::size_t n, std::size_t m, NoiseType noise);

/// Lag-1 autocorrelation noise identification (Riley & Greenhall 2004, NIST SP 1065 sec. 5.6) on
/// the non-overlapping m-averages of a rate; differences up to dmax times (2 Allan, 3 Hadamard).
/// Needs at least 30 averages (returns false otherwise).
bool lag1_noise_id(std::span<const double> cluster_means, int dmax, int* alpha_out,
                   double* rho_out = nullptr);

/// The two-sided interval [lo, hi] of a deviation `dev` with `edf` degrees of freedom.
void confidence_interval(double dev, double edf, double confidence, double* lo, double* hi);

/// Identifies the noise type of every point from the m-averages and attaches edf and intervals.
/// `cluster_means_of(m)` returns the non-overlapping m-averages of the longest segment (at most
/// kMaxIdClusters of them); `segment_lengths` are the rate samples of each segment.
struct CiInput {
  std::vector<std::vector<double>> cluster_means;  // per point, as above
  std::vector<std::size_t> segment_lengths;
};
inline constexpr std::size_t kMaxIdClusters = 16384;
void attach_confidence_intervals(AllanCurve& curve, const CiInput& in);

}  // namespace driftless::est
