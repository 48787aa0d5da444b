// Allan deviation of a rate signal and the noise-parameter fits read from it (IEEE Std 952,
// NIST SP 1065). Standard library only; the estimator, `driftless allan` and tests share it.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace driftless::est {

/// Which averaging times are evaluated: m = 1, 2, 4, ... (octave), log-spaced, or every m.
enum class TauSpacing { kOctave, kLogSpaced, kAll };

/// Options of allan_deviation(). Units: Hz, s.
struct AllanOptions {
  double sample_rate_hz = 100.0;        // Hz, the (uniform) rate of the input samples
  bool overlapping = true;              // false: the paper's non-overlapping cluster definition
  TauSpacing spacing = TauSpacing::kOctave;
  int points_per_decade = 10;           // for kLogSpaced
  double max_tau_s = 0.0;               // s, largest tau evaluated; 0 = as long as data allow
  double confidence = 0.683;            // two-sided probability of the confidence interval
  /// Throws std::invalid_argument naming the field on a bad value.
  void validate() const;
};

/// Power-law noise type at one tau, in the frequency (rate) domain of NIST SP 1065.
enum class NoiseType { kWhitePM, kFlickerPM, kWhiteFM, kFlickerFM, kRandomWalkFM };
const char* to_string(NoiseType t);

/// One averaging time of an Allan deviation curve. Units follow the input (e.g. deg/s).
struct AllanPoint {
  double tau_s = 0.0;        // s, averaging time m / rate
  std::size_t m = 0;         // samples per cluster
  double adev = 0.0;         // Allan deviation, input units
  std::size_t terms = 0;     // number of squared differences averaged
  NoiseType noise = NoiseType::kWhiteFM;  // dominant noise type used for the edf
  double edf = 0.0;          // equivalent degrees of freedom (NIST SP 1065 sec. 5.3)
  double adev_lo = 0.0;      // confidence interval bounds at AllanOptions::confidence
  double adev_hi = 0.0;
};

/// An Allan deviation curve.
struct AllanCurve {
  std::vector<AllanPoint> points;
  double sample_rate_hz = 0.0;
  std::size_t samples = 0;
  bool overlapping = true;
};

/// Allan deviation of `rate` (uniformly sampled; NaN-free). Overlapping: from one cumulative sum,
/// sigma^2(tau) = sum (S[i+2m] - 2 S[i+m] + S[i])^2 / (2 m^2 (N + 1 - 2m)), O(N) per tau.
/// Non-overlapping (the paper's section 2): sigma^2 = sum (w_{k+1} - w_k)^2 / (2 (K - 1)) over
/// K = floor(N / m) cluster means. Throws std::invalid_argument on fewer than 3 samples or NaN.
AllanCurve allan_deviation(std::span<const double> rate, const AllanOptions& opt);

/// A fitted noise parameter with its 1-sigma uncertainty. `valid` is false when the curve
/// shows no region of the needed slope (then value is NaN and `note` says why).
struct NoiseParameter {
  double value = 0.0;
  double sigma = 0.0;
  double tau_s = 0.0;      // s: where it was read (1 s for N, the minimum for B, 3 s for K)
  bool valid = false;
  std::string note;
};

/// The IEEE 952 noise parameters of a rate signal, in the units of the input:
///  N  angle random walk, (units)*sqrt(s) = (units)/sqrt(Hz): the -1/2 line read at tau = 1 s
///  B  bias instability, units: the flat minimum of the curve / 0.664 (sqrt(2 ln2 / pi))
///  K  rate random walk, (units)/sqrt(s): the +1/2 line read at tau = 3 s
struct NoiseFit {
  NoiseParameter N;
  NoiseParameter B;
  NoiseParameter K;
};

/// Fits N, B and K to an Allan curve. Slope regions are found from local log-log slopes; each
/// line is fitted with its slope fixed, weighted by edf; sigma follows from the edf.
NoiseFit fit_noise_parameters(const AllanCurve& curve);

/// Equivalent degrees of freedom of an overlapping Allan variance (NIST SP 1065 table 5) for
/// `n` rate samples, cluster size m and noise type.
double allan_edf(std::size_t n, std::size_t m, NoiseType noise);

}  // namespace driftless::est
