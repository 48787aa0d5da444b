// A small seeded random stream for motion patterns: SplitMix64, identical on every platform
// and standard library (std:: distributions are not), so a seed gives the same run everywhere.
#pragma once

#include <cstdint>

namespace driftless::twin {

class Rng {
 public:
  /// A stream for `seed`; `stream` separates independent uses of the same seed.
  Rng(std::uint64_t seed, std::uint64_t stream) : state_(seed * 0x9E3779B97F4A7C15ull ^ (stream + 0x632BE59BD9B4E019ull)) {
    next();
  }
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  /// Uniform in [a, b).
  double uniform(double a, double b) { return a + (b - a) * static_cast<double>(next() >> 11) * 0x1.0p-53; }

 private:
  std::uint64_t state_;
};

}  // namespace driftless::twin
