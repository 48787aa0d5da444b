// Random numbers, defined once for every folder: one seed-mixing rule, one portable generator
// (mt19937_64 with its own uniform and Marsaglia-polar normal draws: the same numbers on every
// platform and standard library, which std:: distributions do not promise), and the named
// sub-streams of a run's seed. Because every user draws through this table, the same seed gives the
// same sensor unit in `simulate`, `calibrate`, the fast path and the HIL generators. std only.
#pragma once

#include <cstdint>
#include <random>

namespace driftless::rnd {

/// The named sub-streams of a run's seed (values are part of the log's reproducibility: changing
/// one changes what a seed draws).
enum class Stream : std::uint64_t {
  kSensor1 = 1001,          // sensor 1: its unit (run-to-run spreads) and its noise
  kSensor2 = 1002,          // sensor 2
  kPanMoves = 101,          // pan/tilt motion: pan axis moves
  kTiltMoves = 102,         // pan/tilt motion: tilt axis moves
  kVehicleDrive = 201,      // ground vehicle: drive segments
  kVehicleBumps = 202,      // ground vehicle: road bumps
  kShipPhases = 301,        // ship: wave phases
  kFaultInjection = 401,    // studies: planted sensor faults
};

/// The splitmix64 step (Steele, Lea, Flood 2014): a bijective 64-bit mix of `z`.
inline std::uint64_t mix64(std::uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/// A seed for sub-stream `stream` of `seed` (splitmix64 mixing; streams never collide in practice).
inline std::uint64_t derive_seed(std::uint64_t seed, std::uint64_t stream) {
  return mix64(mix64(seed) ^ mix64(stream * 0xD1B54A32D192ED03ull + 0x632BE59BD9B4E019ull));
}
/// The seed of a named stream.
inline std::uint64_t stream_seed(std::uint64_t seed, Stream s) {
  return derive_seed(seed, static_cast<std::uint64_t>(s));
}

/// Portable random stream: mt19937_64, uniform from its top 53 bits, N(0,1) by Marsaglia's polar
/// method (same numbers on every platform).
class NormalStream {
 public:
  explicit NormalStream(std::uint64_t seed = 0) : engine_(seed) {}
  /// The stream of a named sub-stream of `seed`.
  NormalStream(std::uint64_t seed, Stream s) : engine_(stream_seed(seed, s)) {}
  /// Next N(0,1) draw.
  double operator()();
  /// Next uniform draw in [0, 1).
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  /// Next uniform draw in [a, b).
  double uniform(double a, double b) { return a + (b - a) * uniform(); }

 private:
  std::mt19937_64 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace driftless::rnd
