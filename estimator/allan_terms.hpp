// The squared-difference sums behind the Allan-family variances, shared by the in-memory pass
// (estimator/allan.cpp) and the streaming pass (estimator/allan_stream.cpp). Internal header.
#pragma once

#include <cstddef>

#include "estimator/allan.hpp"

namespace driftless::est {

/// Sum of squared differences and how many there were.
struct TermSum {
  double sum = 0.0;
  std::size_t terms = 0;
};

/// Adds the terms starting at i = i0, i0 + stride, ... < i1 of phase S (every S[i + k m] the
/// difference needs must exist): Allan (S[i+2m] - 2 S[i+m] + S[i])^2, Hadamard
/// (S[i+3m] - 3 S[i+2m] + 3 S[i+m] - S[i])^2. Not for the modified Allan variance.
void accumulate_range(Deviation dev, const double* S, std::size_t i0, std::size_t i1, std::size_t m,
                      std::size_t stride, TermSum& out);

/// Adds every term of a whole phase array S[0..np) (any deviation; modified Allan: stride 1).
void accumulate_terms(Deviation dev, const double* S, std::size_t np, std::size_t m, std::size_t stride,
                      TermSum& out);

/// The deviation from its sum: sqrt(sum / (2 m^2 T)), sqrt(sum / (2 m^4 T)), sqrt(sum / (6 m^2 T)).
double deviation_from_sum(Deviation dev, const TermSum& s, std::size_t m);

/// Differences (in units of m) a term spans: 2 (Allan), 3 (modified Allan, Hadamard).
std::size_t span_in_m(Deviation dev);

}  // namespace driftless::est
