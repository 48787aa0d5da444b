// Confidence intervals: Greenhall's equivalent degrees of freedom against NIST SP 1065 table 5 and
// Monte Carlo, and the intervals of a corrected (high-passed) channel, which collapsed to +-0.1 %
// when its steep slope was read as white phase noise of the whole record (issue 16).
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/allan.hpp"

namespace driftless::est {
namespace {

TEST(AllanEdf, GreenhallMatchesNistTableFiveForWhiteFrequencyNoise) {
  // NIST SP 1065 table 5 is the closed form for white FM; Greenhall's algorithm is general
  for (const std::size_t n : {4096u, 100000u}) {
    for (const std::size_t m : {1u, 2u, 8u, 64u, 512u}) {
      const double nist = allan_edf(n, m, NoiseType::kWhiteFM);
      EXPECT_NEAR(greenhall_edf(0, 2, m, n + 1, true, false) / nist, 1.0, 0.02) << "n " << n << " m " << m;
    }
  }
  // random-walk FM, away from the shortest m where the simplified formula is rough
  for (const std::size_t m : {8u, 64u, 512u}) {
    EXPECT_NEAR(greenhall_edf(-2, 2, m, 100001, true, false) / allan_edf(100000, m, NoiseType::kRandomWalkFM), 1.0, 0.1) << m;
  }
  // the modified variance at m = 1 is the Allan variance itself
  EXPECT_DOUBLE_EQ(greenhall_edf(0, 2, 1, 4097, true, true), greenhall_edf(0, 2, 1, 4097, true, false));
  EXPECT_THROW(greenhall_edf(-3, 2, 4, 1000, true, false), std::invalid_argument);  // no Allan variance for alpha -3
}

// fraction of seeds whose interval at point i holds the ensemble's Allan deviation
double coverage(const std::vector<AllanCurve>& runs, std::size_t i) {
  double mean_var = 0.0;
  for (const auto& c : runs) mean_var += c.points[i].adev * c.points[i].adev;
  const double truth = std::sqrt(mean_var / static_cast<double>(runs.size()));
  int in = 0;
  for (const auto& c : runs) in += (c.points[i].adev_lo <= truth && truth <= c.points[i].adev_hi) ? 1 : 0;
  return static_cast<double>(in) / static_cast<double>(runs.size());
}

TEST(AllanIntervals, WhiteNoiseIntervalsCoverAtTheirLevel) {
  std::vector<AllanCurve> runs;
  for (int s = 0; s < 300; ++s) {
    std::mt19937_64 rng(100 + s);
    std::normal_distribution<double> g(0.0, 1.0);
    std::vector<double> x(4096);
    for (auto& v : x) v = g(rng);
    runs.push_back(allan_deviation(x, AllanOptions{}));
  }
  for (std::size_t i = 0; i < 9; ++i) {
    const double c = coverage(runs, i);
    EXPECT_GT(c, 0.58) << "m " << runs[0].points[i].m;
    EXPECT_LT(c, 0.79) << "m " << runs[0].points[i].m;
  }
}

TEST(AllanIntervals, HighPassedChannelKeepsHonestIntervalsAtLongTau) {
  // GIVEN white rate noise minus its own 20 s running mean (what a bias-correcting filter does
  // to the slow part): beyond 20 s the phase stops wandering and the slope falls below -3/4
  const double fs = 10.0, T = 20.0;
  std::vector<AllanCurve> runs;
  for (int s = 0; s < 200; ++s) {
    std::mt19937_64 rng(500 + s);
    std::normal_distribution<double> g(0.0, 1.0);
    std::vector<double> x(1u << 16);
    double b = 0.0;
    for (auto& v : x) {
      const double y = g(rng);
      b += (y - b) / (T * fs);
      v = y - b;
    }
    AllanOptions o;
    o.sample_rate_hz = fs;
    runs.push_back(allan_deviation(x, o));
  }
  // THEN at every tau beyond 100 s (read as phase noise) the intervals still cover at their level,
  // because the edf counts phase points where the phase is white, not every sample
  int checked = 0;
  for (std::size_t i = 0; i < runs[0].points.size(); ++i) {
    const auto& p = runs[0].points[i];
    if (p.tau_s < 100.0 || p.edf < 3.0) continue;
    ++checked;
    EXPECT_GT(p.phase_scale_m, 1u) << p.tau_s;
    const double c = coverage(runs, i);
    EXPECT_GT(c, 0.5) << "tau " << p.tau_s << " edf " << p.edf << " " << to_string(p.noise);
    EXPECT_LT(c, 0.9) << "tau " << p.tau_s;
    // the collapsed form: white PM edf of the whole record, about N/2
    EXPECT_LT(p.edf, allan_edf(runs[0].samples, p.m, NoiseType::kWhitePM) / 20.0);
  }
  EXPECT_GE(checked, 3);
}

}  // namespace
}  // namespace driftless::est
