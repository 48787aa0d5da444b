// Allan deviation and noise fits against closed forms: white noise (-1/2, N), rate random walk
// (+1/2, K), a Gauss-Markov bias (minimum where white noise meets the bias wander), and the
// chi-square helpers behind the confidence intervals.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/allan.hpp"
#include "estimator/allan_fit.hpp"
#include "estimator/stats.hpp"

namespace driftless::est {
namespace {

constexpr double kRateHz = 100.0;

std::vector<double> white_noise(std::size_t n, double sigma, std::uint64_t seed, double offset = 0.0) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, sigma);
  std::vector<double> x(n);
  for (auto& v : x) v = offset + g(rng);
  return x;
}

// log-log slope of the curve between the points nearest to tau_a and tau_b
double slope_between(const AllanCurve& c, double tau_a, double tau_b) {
  auto nearest = [&](double tau) {
    std::size_t best = 0;
    for (std::size_t i = 0; i < c.points.size(); ++i) {
      if (std::fabs(std::log(c.points[i].tau_s / tau)) < std::fabs(std::log(c.points[best].tau_s / tau))) best = i;
    }
    return c.points[best];
  };
  const auto a = nearest(tau_a), b = nearest(tau_b);
  return std::log(b.adev / a.adev) / std::log(b.tau_s / a.tau_s);
}

TEST(StatsTest, ChiSquareQuantilesMatchTables) {
  EXPECT_NEAR(chi2_quantile(0.975, 1.0), 5.023886, 1e-5);
  EXPECT_NEAR(chi2_quantile(0.025, 10.0), 3.246973, 1e-5);
  EXPECT_NEAR(chi2_quantile(0.95, 6.0), 12.591587, 1e-5);
  EXPECT_NEAR(chi2_quantile(0.5, 2.0), 2.0 * std::log(2.0), 1e-9);
  EXPECT_NEAR(chi2_cdf(chi2_quantile(0.3, 6000.0), 6000.0), 0.3, 1e-9);
  EXPECT_NEAR(normal_quantile(0.975), 1.959963985, 1e-8);
}

TEST(AllanTest, WhiteNoiseHasSlopeMinusHalfAndNWithinFivePercent) {
  // GIVEN white rate noise sigma = 0.1 deg/s at 100 Hz: N = sigma / sqrt(rate) = 0.01 deg/sqrt(s)
  const double sigma = 0.1;
  const auto x = white_noise(200000, sigma, 7, 3.0);
  AllanOptions opt;
  opt.sample_rate_hz = kRateHz;
  // WHEN the overlapping octave curve is fitted
  const auto curve = allan_deviation(x, opt);
  const auto fit = fit_noise_parameters(curve);
  // THEN the curve falls as tau^-1/2 and N is read at 1 s within 5 %
  EXPECT_NEAR(slope_between(curve, 0.01, 10.0), -0.5, 0.03);
  ASSERT_TRUE(fit.N.valid) << fit.N.note;
  const double n_true = sigma / std::sqrt(kRateHz);
  EXPECT_NEAR(fit.N.value, n_true, 0.05 * n_true);
  EXPECT_LT(fit.N.sigma, 0.02 * n_true);
  EXPECT_GT(fit.N.sigma, 0.0);
  // the first point is the plain sample deviation
  EXPECT_NEAR(curve.points.front().adev, sigma, 0.01 * sigma);
  // and each point's confidence interval brackets the closed form N / sqrt(tau) mostly
  int inside = 0;
  for (const auto& p : curve.points) {
    const double expect = n_true / std::sqrt(p.tau_s);
    EXPECT_LE(p.adev_lo, p.adev);
    EXPECT_GE(p.adev_hi, p.adev);
    inside += (p.adev_lo <= expect && expect <= p.adev_hi) ? 1 : 0;
  }
  EXPECT_GE(inside, static_cast<int>(curve.points.size()) / 2);
}

TEST(AllanTest, PaperNonOverlappingDefinitionAgreesOnWhiteNoise) {
  const auto x = white_noise(100000, 0.05, 11);
  AllanOptions ov, non;
  ov.sample_rate_hz = non.sample_rate_hz = kRateHz;
  non.overlapping = false;
  const auto a = allan_deviation(x, ov);
  const auto b = allan_deviation(x, non);
  ASSERT_EQ(a.points.size(), b.points.size());
  // m = 1: both are the same estimator up to one difference
  EXPECT_NEAR(a.points[0].adev, b.points[0].adev, 1e-3 * a.points[0].adev);
  for (std::size_t i = 0; i < 8; ++i) {
    EXPECT_NEAR(b.points[i].adev / a.points[i].adev, 1.0, 4.0 / std::sqrt(b.points[i].edf)) << i;
    EXPECT_EQ(b.points[i].terms, 100000 / b.points[i].m - 1);
  }
}

TEST(AllanTest, RandomWalkHasSlopePlusHalfAndKWithinTenPercent) {
  // GIVEN a rate random walk with K = 0.002 deg/s/sqrt(s): sigma(tau) = K sqrt(tau / 3)
  const double K = 0.002;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<double> x(300000);
  double b = 0.0;
  for (auto& v : x) {
    b += K * std::sqrt(1.0 / kRateHz) * g(rng);
    v = b;
  }
  AllanOptions opt;
  opt.sample_rate_hz = kRateHz;
  const auto curve = allan_deviation(x, opt);
  const auto fit = fit_noise_parameters(curve);
  EXPECT_NEAR(slope_between(curve, 0.1, 30.0), 0.5, 0.05);
  ASSERT_TRUE(fit.K.valid) << fit.K.note;
  EXPECT_NEAR(fit.K.value, K, 0.10 * K);
  EXPECT_FALSE(fit.N.valid);  // no white noise in the signal
}

TEST(AllanTest, GaussMarkovBiasPutsTheMinimumWhereWhiteNoiseMeetsTheWander) {
  // GIVEN white noise N plus a first-order Gauss-Markov bias (sigma_b, correlation time Tc)
  const double sigma_w = 0.05, sigma_b = 0.02, tc_s = 2000.0;
  const std::size_t n = 2'000'000;  // 20000 s
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  const double phi = std::exp(-1.0 / (kRateHz * tc_s));
  const double drive = sigma_b * std::sqrt(1.0 - phi * phi);
  std::vector<double> x(n);
  double b = 0.0;
  for (auto& v : x) {
    b = phi * b + drive * g(rng);
    v = b + sigma_w * g(rng);
  }
  AllanOptions opt;
  opt.sample_rate_hz = kRateHz;
  const auto curve = allan_deviation(x, opt);
  const auto fit = fit_noise_parameters(curve);
  // THEN for tau << Tc the bias acts as a rate random walk K^2 = 2 sigma_b^2 / Tc, and
  // N^2 / tau + K^2 tau / 3 is smallest at tau* = sqrt(3) N / K
  const double N = sigma_w / std::sqrt(kRateHz);
  const double K = sigma_b * std::sqrt(2.0 / tc_s);
  const double tau_star = std::sqrt(3.0) * N / K;
  ASSERT_TRUE(fit.B_min.valid) << fit.B_min.note;
  EXPECT_GT(fit.B_min.tau_s, tau_star / 2.1);
  EXPECT_LT(fit.B_min.tau_s, tau_star * 2.1);
  const double min_adev = std::sqrt(2.0 * N * K / std::sqrt(3.0));
  EXPECT_NEAR(fit.B_min.value, min_adev, 0.25 * min_adev);
  EXPECT_NEAR(fit.N.value, N, 0.05 * N);
}

TEST(AllanTest, TauSpacingsAndCaps) {
  const auto x = white_noise(5000, 1.0, 1);
  AllanOptions opt;
  opt.sample_rate_hz = 50.0;
  opt.spacing = TauSpacing::kAll;
  opt.max_tau_s = 1.0;
  const auto all = allan_deviation(x, opt);
  ASSERT_EQ(all.points.size(), 50u);
  EXPECT_DOUBLE_EQ(all.points.back().tau_s, 1.0);
  opt.spacing = TauSpacing::kPerDecade;
  opt.max_tau_s = 0.0;
  const auto log = allan_deviation(x, opt);
  EXPECT_EQ(log.points.back().m, 1995u);  // 10^3.3; the next, 10^3.4, exceeds n / 2
  for (std::size_t i = 1; i < log.points.size(); ++i) EXPECT_GT(log.points[i].m, log.points[i - 1].m);
  // octave results equal the matching m of the all-tau curve
  opt.spacing = TauSpacing::kOctave;
  opt.max_tau_s = 1.0;
  const auto oct = allan_deviation(x, opt);
  EXPECT_DOUBLE_EQ(oct.points[3].adev, all.points[7].adev);  // m = 8
}

TEST(AllanTest, RejectsBadInputWithAClearMessage) {
  AllanOptions opt;
  std::vector<double> two = {1.0, 2.0};
  EXPECT_THROW(allan_deviation(two, opt), std::invalid_argument);
  std::vector<double> bad = {1.0, std::nan(""), 2.0, 3.0};
  try {
    allan_deviation(bad, opt);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sample 1"), std::string::npos);
  }
  opt.sample_rate_hz = 0.0;
  EXPECT_THROW(opt.validate(), std::invalid_argument);
}

TEST(AllanTest, DeterministicOnRerun) {
  const auto x = white_noise(10000, 0.2, 9);
  AllanOptions opt;
  const auto a = fit_noise_parameters(allan_deviation(x, opt));
  const auto b = fit_noise_parameters(allan_deviation(x, opt));
  EXPECT_EQ(a.N.value, b.N.value);
  EXPECT_EQ(a.B_min.value, b.B_min.value);
}

}  // namespace
}  // namespace driftless::est

namespace driftless::est {
namespace {

TEST(AllanTest, EquivalentDegreesOfFreedomFollowNistTable5) {
  // N = 1025 phase points (1024 rate samples); values from the closed forms of NIST SP 1065 table 5
  const std::size_t n = 1024;
  const double N = 1025.0;
  EXPECT_NEAR(allan_edf(n, 4, NoiseType::kWhiteFM), (3.0 * (N - 1) / 8.0 - 2.0 * (N - 2) / N) * 64.0 / 69.0, 1e-9);
  EXPECT_NEAR(allan_edf(n, 1, NoiseType::kFlickerFM), 2.0 * (N - 2) * (N - 2) / (2.3 * N - 4.9), 1e-9);
  EXPECT_NEAR(allan_edf(n, 8, NoiseType::kFlickerFM), 5.0 * N * N / (32.0 * (N + 24.0)), 1e-9);
  EXPECT_NEAR(allan_edf(n, 2, NoiseType::kWhitePM), (N + 1) * (N - 4) / (2.0 * (N - 2)), 1e-9);
  // more data, more degrees of freedom; longer tau, fewer
  for (NoiseType t : {NoiseType::kWhitePM, NoiseType::kFlickerPM, NoiseType::kWhiteFM, NoiseType::kFlickerFM,
                      NoiseType::kRandomWalkFM}) {
    EXPECT_GT(allan_edf(10 * n, 4, t), allan_edf(n, 4, t)) << to_string(t);
    EXPECT_GT(allan_edf(n, 4, t), allan_edf(n, 64, t)) << to_string(t);
  }
}

}  // namespace
}  // namespace driftless::est
