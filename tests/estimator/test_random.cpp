// The one random-number module (estimator/random.hpp): reproducible named streams and N(0,1) draws
// whose moments match within seeded statistical bounds.
#include "estimator/random.hpp"

#include <cmath>
#include <set>

#include <gtest/gtest.h>

namespace driftless::rnd {
namespace {

TEST(Random, SameSeedAndStreamGiveTheSameNumbersOtherStreamsDiffer) {
  NormalStream a(42, Stream::kSensor1), b(42, Stream::kSensor1), c(42, Stream::kSensor2), d(43, Stream::kSensor1);
  for (int i = 0; i < 100; ++i) {
    const double x = a();
    EXPECT_EQ(x, b());
    EXPECT_NE(x, c());
    EXPECT_NE(x, d());
  }
  // the named streams are distinct sub-streams of one seed
  std::set<std::uint64_t> seeds;
  for (Stream s : {Stream::kSensor1, Stream::kSensor2, Stream::kPanMoves, Stream::kTiltMoves,
                   Stream::kVehicleDrive, Stream::kVehicleBumps, Stream::kShipPhases, Stream::kFaultInjection})
    seeds.insert(stream_seed(7, s));
  EXPECT_EQ(seeds.size(), 8u);
}

TEST(Random, NormalDrawsHaveUnitVarianceAndUniformDrawsTheirRange) {
  // seeded: mean within 4 sigma/sqrt(n), variance within 4 sqrt(2/n) of 1
  NormalStream g(1234);
  const int n = 200000;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    const double x = g();
    sum += x;
    sum2 += x * x;
  }
  const double mean = sum / n, var = sum2 / n - mean * mean;
  EXPECT_LT(std::abs(mean), 4.0 / std::sqrt(n));
  EXPECT_LT(std::abs(var - 1.0), 4.0 * std::sqrt(2.0 / n));
  NormalStream u(99);
  double lo = 1e9, hi = -1e9;
  for (int i = 0; i < 10000; ++i) {
    const double x = u.uniform(-2.0, 3.0);
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  EXPECT_GE(lo, -2.0);
  EXPECT_LT(hi, 3.0);
  EXPECT_LT(lo, -1.99);
  EXPECT_GT(hi, 2.99);
}

}  // namespace
}  // namespace driftless::rnd
