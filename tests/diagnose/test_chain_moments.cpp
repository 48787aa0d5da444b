// The signal chain's higher-order terms (chain_moments, diagnose/signal_chain.hpp) against the
// chain itself: a cubic passed through a pure delay and a first-order pole, integrated by
// quadrature. For a cubic the Taylor series of the convolution ends at the third derivative, so
// y(t) = x - c1 x' + c2 x'' - c3 x''' holds exactly: any error in c2 or c3 shows.
#include <gtest/gtest.h>

#include <cmath>

#include "diagnose/signal_chain.hpp"

namespace driftless::diagnose {
namespace {

// x(t) = a0 + a1 t + a2 t^2 + a3 t^3
struct Cubic {
  double a0, a1, a2, a3;
  double at(double t) const { return a0 + t * (a1 + t * (a2 + t * a3)); }
};

// the chain's output at t = 0: a pure delay a = D - T + d, then an exponential of mean T
// (impulse response e^(-u/T)/T), by Simpson's rule over u in [0, 60 T] (the tail is e^-60)
double chain_output_at_zero(const Cubic& x, double D, double T, double d) {
  const double a = D - T + d;
  if (T == 0.0) return x.at(-a);
  const int n = 200000;  // even
  const double h = 60.0 * T / n;
  double sum = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double u = i * h;
    const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
    sum += w * std::exp(-u / T) / T * x.at(-a - u);
  }
  return sum * h / 3.0;
}

TEST(ChainMoments, ACubicThroughDelayAndPoleMatchesTheThirdOrderSeries) {
  // GIVEN a cubic whose third derivative dominates at the chain's time scale
  const Cubic x{1.0, 1e2, 1e4, 1e6};
  // WHEN it passes low-passes of group delay D with pole time T (a pure delay, a pole only, and
  // shapes between), then a sample delay d
  struct Case {
    double D, T, d;
  };
  for (const Case c : {Case{4.8e-3, 0.0, 0.0}, Case{4.8e-3, 4.8e-3, 0.0}, Case{4.8e-3, 2.1e-3, 0.0},
                       Case{10e-3, 6e-3, 15e-3}, Case{0.0, 0.0, 12e-3}, Case{20e-3, 9e-3, 3e-3}}) {
    const ChainTerms m = chain_moments(c.D, c.T, c.d);
    const double c1 = c.D + c.d;
    // THEN y(0) = x(0) - c1 x'(0) + c2 x''(0) - c3 x'''(0), x'(0) = a1, x''(0) = 2 a2, x'''(0) = 6 a3
    const double series = x.a0 - c1 * x.a1 + 2.0 * x.a2 * m.c2 - 6.0 * x.a3 * m.c3;
    const double direct = chain_output_at_zero(x, c.D, c.T, c.d);
    EXPECT_NEAR(series, direct, 1e-9 * std::abs(x.a3 * 6.0 * m.c3) + 1e-12)
        << "D " << c.D << " T " << c.T << " d " << c.d;
    // and the third-order term is material here (an error in it would fail the check above)
    EXPECT_GT(6.0 * x.a3 * m.c3, 1e-4);
  }
}

TEST(ChainMoments, APureDelayHasTheTaylorCoefficientsOfAShift) {
  // GIVEN no pole: the chain is a shift by D + d, whose coefficients are (D + d)^n / n!
  const double D = 3e-3, d = 7e-3, s = D + d;
  const ChainTerms m = chain_moments(D, 0.0, d);
  EXPECT_NEAR(m.c2, s * s / 2.0, 1e-18);
  EXPECT_NEAR(m.c3, s * s * s / 6.0, 1e-20);
}

}  // namespace
}  // namespace driftless::diagnose
