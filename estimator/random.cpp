// One seed-mixing rule and one portable normal generator (see random.hpp).
#include "estimator/random.hpp"

#include <cmath>

namespace driftless::rnd {

std::uint64_t derive_seed(std::uint64_t seed, std::uint64_t stream) {
  auto mix = [](std::uint64_t z) {  // splitmix64 finaliser
    z += 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  };
  return mix(mix(seed) ^ mix(stream * 0xD1B54A32D192ED03ull + 0x632BE59BD9B4E019ull));
}

double NormalStream::operator()() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  double u, v, s;
  do {
    u = 2.0 * uniform() - 1.0;
    v = 2.0 * uniform() - 1.0;
    s = u * u + v * v;
  } while (s >= 1.0 || s == 0.0);
  const double m = std::sqrt(-2.0 * std::log(s) / s);
  spare_ = v * m;
  has_spare_ = true;
  return u * m;
}

}  // namespace driftless::rnd
