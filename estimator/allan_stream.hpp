// Octave-tau Allan or Hadamard deviations accumulated in one streaming pass at memory that does not
// grow with the record: exact up to m = exact_up_to_m samples, beyond that every s-th difference
// (s = m / exact_up_to_m) of the phase decimated by s. Gap-aware: segment breaks start a new phase.
// Docs: docs/allan.md (streaming).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "estimator/allan.hpp"
#include "estimator/allan_terms.hpp"

namespace driftless::est {

/// Options of StreamingOctaveDeviation. Units: Hz.
struct StreamingOptions {
  double sample_rate_hz = 100.0;          // Hz
  Deviation deviation = Deviation::kAllan;  // kAllan or kHadamard (modified Allan needs the record)
  std::size_t exact_up_to_m = 16384;      // a power of two: every difference is used up to this m
  double confidence = 0.683;
  /// Throws std::invalid_argument naming the field.
  void validate() const;
};

/// Accumulates the deviation sample by sample (in chunks). Memory: about 3 exact_up_to_m doubles
/// per octave beyond exact_up_to_m plus kMaxIdClusters per octave for the noise identification.
class StreamingOctaveDeviation {
 public:
  explicit StreamingOctaveDeviation(const StreamingOptions& opt);
  /// Appends samples (finite; throws std::invalid_argument naming the sample otherwise).
  void push(std::span<const double> rate);
  /// Ends the current gap-free segment: no difference spans the break.
  void break_segment();
  /// The curve with noise types, edf and intervals (the accumulator stays usable). A rate > 0
  /// (Hz) replaces the options' rate (when it is known only after the pass, e.g. from stamps).
  AllanCurve finish(double sample_rate_hz = 0.0) const;
  std::size_t samples() const { return samples_; }

 private:
  struct Level {                 // the phase decimated by 2^j
    std::vector<double> buf;     // the latest values, global indices [base, base + buf.size())
    std::size_t base = 0;
    std::size_t count = 0;       // values produced in this segment
    std::vector<double> id;      // the first values of this segment (noise identification)
    std::vector<double> id_best; // the longest such run over the segments so far
    std::vector<double> half;    // scratch: this block's values handed to the next level
  };
  void append(std::size_t j, const double* v, std::size_t n);
  void accumulate(std::size_t j, std::size_t old_end);
  std::vector<double> level_means(std::size_t k) const;

  StreamingOptions opt_;
  std::size_t span_;             // differences span span_ * m
  std::size_t exact_log2_;       // log2(exact_up_to_m)
  std::vector<Level> levels_;
  std::vector<TermSum> sums_;    // per octave k (m = 2^k)
  std::vector<std::size_t> segment_lengths_;
  std::size_t seg_samples_ = 0, samples_ = 0;
  double offset_ = 0.0;          // subtracted from every sample: the mean of the first samples
  bool have_offset_ = false;
  double phase_ = 0.0;           // cumulative sum of (rate - offset) in this segment
  std::vector<double> scratch_;
};

}  // namespace driftless::est
