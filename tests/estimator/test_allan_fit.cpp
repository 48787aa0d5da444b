// The joint noise fit on each pure term and on coloured noise: recovered within the stated
// uncertainty, "not identifiable" without support, and warnings on records too short for B or K.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/allan.hpp"
#include "estimator/allan_fit.hpp"

namespace driftless::est {
namespace {

constexpr double kFs = 100.0;

NoiseFit fit(const std::vector<double>& x, double fs = kFs) {
  AllanOptions o;
  o.sample_rate_hz = fs;
  return fit_noise_parameters(allan_deviation(x, o));
}

// the estimate within `k` of its stated 1-sigma of the truth
void expect_within(const NoiseParameter& p, double truth, double k, const char* what) {
  ASSERT_TRUE(p.valid) << what << ": " << p.note;
  EXPECT_GT(p.sigma, 0.0) << what;
  EXPECT_LT(std::fabs(p.value - truth), k * p.sigma) << what << " " << p.value << " +- " << p.sigma << " truth " << truth;
  EXPECT_LT(p.sigma, 0.2 * truth) << what;
}

bool warns(const NoiseFit& f, const std::string& what) {
  for (const auto& w : f.warnings) {
    if (w.find(what) != std::string::npos) return true;
  }
  return false;
}

TEST(AllanFit, WhiteNoiseGivesNAndNothingElse) {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> g(0.0, 0.1);
    std::vector<double> x(200000);
    for (auto& v : x) v = 3.0 + g(rng);
    const NoiseFit f = fit(x);
    expect_within(f.N, 0.1 / std::sqrt(kFs), 3.0, "N");
    EXPECT_FALSE(f.K.valid);
    EXPECT_FALSE(f.B.valid);
    EXPECT_FALSE(f.R.valid);
    EXPECT_GT(f.K.upper_95, 0.0);
    EXPECT_TRUE(warns(f, "record too short for K"));
  }
}

TEST(AllanFit, WhiteNoiseIsRarelyCalledLowPassed) {
  // GIVEN 60 seeded records of pure white noise (100 000 samples each)
  int low_passed = 0;
  for (std::uint64_t seed = 100; seed < 160; ++seed) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> g(0.0, 0.1);
    std::vector<double> x(100000);
    for (auto& v : x) v = g(rng);
    const NoiseFit f = fit(x);
    if (warns(f, "low-passed")) ++low_passed;
  }
  // THEN at most 1 is reported low-passed: a 3-sigma test, with the profile over the time constant
  // as its look-elsewhere, gives of the order of 1 % (0 of these 60; the 2-sigma test it replaced
  // reported 3 of them, and on a real-looking 1 kHz record one channel of three)
  EXPECT_LE(low_passed, 1) << low_passed << " of 60 reported low-passed";
}

TEST(AllanFit, RandomWalkGivesK) {
  std::mt19937_64 rng(4);
  std::normal_distribution<double> g(0.0, 1.0);
  const double K = 0.002;
  std::vector<double> x(300000);
  double b = 0.0;
  for (auto& v : x) v = (b += K * std::sqrt(1.0 / kFs) * g(rng));
  const NoiseFit f = fit(x);
  expect_within(f.K, K, 3.0, "K");
  EXPECT_FALSE(f.N.valid) << f.N.note;
}

TEST(AllanFit, RateRampAndQuantisationAreSeparatedFromWhiteNoise) {
  // GIVEN white noise N, angle quantisation Q (white phase noise) and a ramp R
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  const double N = 0.01, Q = 0.002, R = 2e-5;
  std::vector<double> x(400000);
  double prev = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double ph = Q * g(rng);  // angle error, deg: rate error (ph - prev) * fs
    x[i] = N * std::sqrt(kFs) * g(rng) + (ph - prev) * kFs + R * static_cast<double>(i) / kFs;
    prev = ph;
  }
  const NoiseFit f = fit(x);
  // THEN each is read where it dominates: Q (deg) from 3 Q^2 / tau^2, N from N^2 / tau, R from R^2 tau^2 / 2
  expect_within(f.N, N, 3.0, "N");
  expect_within(f.R, R, 3.0, "R");
  expect_within(f.Q, Q, 3.0, "Q");
}

TEST(AllanFit, GaussMarkovBiasIsRecovered) {
  // GIVEN white noise plus a Gauss-Markov bias (sigma 0.02 deg/s, 200 s) over 40 correlation times
  std::mt19937_64 rng(6);
  std::normal_distribution<double> g(0.0, 1.0);
  const double sw = 0.05, sb = 0.02, tc = 200.0;
  const double phi = std::exp(-1.0 / (kFs * tc)), drive = sb * std::sqrt(1.0 - phi * phi);
  std::vector<double> x(800000);
  double b = sb * g(rng);
  for (auto& v : x) {
    b = phi * b + drive * g(rng);
    v = b + sw * g(rng);
  }
  const NoiseFit f = fit(x);
  EXPECT_GT(f.gm_evidence, 2.0);  // the Gauss-Markov model fits better than flicker + K
  expect_within(f.N, sw / std::sqrt(kFs), 3.0, "N");
  ASSERT_TRUE(f.gm_sigma.valid) << f.gm_sigma.note;
  EXPECT_LT(std::fabs(f.gm_sigma.value - sb), 3.0 * f.gm_sigma.sigma);
  // below its correlation time the bias is a random walk K^2 = 2 sigma^2 / T
  expect_within(f.K, sb * std::sqrt(2.0 / tc), 3.0, "K");
  ASSERT_TRUE(std::isfinite(f.gm_tau.value)) << f.gm_tau.note;
  EXPECT_GT(tc, f.gm_tau.value / 3.0);
  EXPECT_LT(tc, f.gm_tau.value * 3.0);
  ASSERT_TRUE(f.B_min.valid) << f.B_min.note;
}

TEST(AllanFit, LowPassedWhiteNoiseKeepsItsLongTauLevel) {
  // GIVEN white noise through a first-order low-pass (pole 0.6, time constant 19.6 ms) at 100 Hz:
  // the shortest taus read below the N line (issue 16: N fitted 10-19 % off with a 0.1 % sigma)
  for (std::uint64_t seed : {7u, 8u}) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> g(0.0, 0.1);
    std::vector<double> x(200000);
    double u = 0.0;
    for (auto& v : x) v = (u = 0.6 * u + 0.4 * g(rng));
    const NoiseFit f = fit(x);
    // THEN N is the level of the unfiltered noise (DC gain 1) within its stated uncertainty
    expect_within(f.N, 0.1 / std::sqrt(kFs), 3.0, "N");
    EXPECT_NEAR(f.white_lowpass_tau_s, -0.01 / std::log(0.6), 0.1 * 0.0196);
    EXPECT_TRUE(warns(f, "low-passed"));
  }
}

TEST(AllanFit, FitIsTheSameOnADenserTauGrid) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<double> x(200000);
  double b = 0.0;
  for (auto& v : x) v = 0.05 * g(rng) + (b += 2e-4 * g(rng));
  AllanOptions o;
  o.sample_rate_hz = kFs;
  const NoiseFit oct = fit_noise_parameters(allan_deviation(x, o));
  o.spacing = TauSpacing::kPerDecade;
  o.points_per_decade = 10;
  const NoiseFit dense = fit_noise_parameters(allan_deviation(x, o));
  ASSERT_TRUE(oct.K.valid && dense.K.valid);
  EXPECT_NEAR(dense.K.value, oct.K.value, 2.0 * oct.K.sigma);
  EXPECT_NEAR(dense.N.value, oct.N.value, 2.0 * oct.N.sigma);
  EXPECT_LT(dense.K.sigma, 2.0 * oct.K.sigma);
  EXPECT_GT(dense.K.sigma, 0.5 * oct.K.sigma);
}

TEST(AllanFit, ShortRecordWarnsForBAndK) {
  // GIVEN 40 s of white noise plus a slow wander (a real sensor's bias)
  std::mt19937_64 rng(10);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<double> x(4000);
  double b = 0.0;
  for (auto& v : x) v = 0.1 * g(rng) + (b += 1e-4 * g(rng));
  const NoiseFit f = fit(x);
  EXPECT_TRUE(warns(f, "record too short for B")) << (f.warnings.empty() ? "" : f.warnings[0]);
  EXPECT_TRUE(warns(f, "record too short for K"));
  EXPECT_FALSE(f.B_min.valid);
  AllanOptions mo;
  mo.deviation = Deviation::kModifiedAllan;
  const AllanCurve mdev = allan_deviation(x, mo);
  EXPECT_THROW(fit_noise_parameters(mdev), std::invalid_argument);
}

}  // namespace
}  // namespace driftless::est
