// Tuning from the data (docs/estimator.md section 8): the first pass recovers the noise density N
// and the bias random walk K of seeded synthetic logs, and a filter tuned with them is consistent
// where the defaults were not.
#include <cmath>

#include <gtest/gtest.h>

#include "estimator/pipeline.hpp"
#include "estimator/tune.hpp"
#include "tests/estimator/synth.hpp"
#include "tests/temp_path.hpp"

namespace driftless::est {
namespace {


// 10x the MPU6050's noise (N = 0.05 deg/s/sqrt(Hz)) and 5x its bias instability: a Gauss-Markov
// wander with tau far above the revisit time acts as a random walk with K^2 = 2 sigma^2 / tau
struct Noisy {
  static constexpr double kN = 0.05;        // deg/s/sqrt(Hz)
  static constexpr double kTau = 2.0e4;     // s
  static constexpr double kK2 = 3.3e-5;     // (deg/s)^2/s, 5x the default spec's 1.32e-6 in K
  test::SynthParams p;
  Noisy(std::uint64_t seed, double duration_s) {
    p.duration_s = duration_s;
    p.noise_sigma_dps = kN * std::sqrt(p.rate_hz);
    p.gm_sigma_dps = std::sqrt(kK2 * kTau / 2.0);
    p.gm_tau_s = kTau;
    p.seed = seed;
  }
};

TEST(TuneTest, RecoversNoiseDensityAndRandomWalk) {
  // GIVEN 30 min of the noisy sensor
  Noisy n(21, 1800.0);
  NoiseTuner tuner(EstimatorConfig{}, test::synth_geometry(n.p));
  test::synth_samples(n.p, [&](const Sample& s) { tuner.push(s); });
  // WHEN the first pass runs
  const TuneResult t = tuner.finish();
  // THEN N is within 3 % (about 2700 block pairs: 1.5 % standard error) and K^2 within 35 %
  // (about 160 revisits with the noise a third of the signal: ~10 % standard error)
  ASSERT_TRUE(t.noise_estimated);
  EXPECT_GT(t.noise_block_pairs, 2000u);
  EXPECT_NEAR(t.noise_density_dps_rthz, Noisy::kN, 0.03 * Noisy::kN);
  ASSERT_TRUE(t.q_estimated);
  EXPECT_GT(t.wander_pairs, 150u);
  EXPECT_NEAR(t.q_dps2_per_s, Noisy::kK2, 0.35 * Noisy::kK2);
}

TEST(TuneTest, TooLittleDataKeepsTheConfiguredValues) {
  // GIVEN 30 s: two standstills, no revisit
  Noisy n(22, 30.0);
  NoiseTuner tuner(EstimatorConfig{}, test::synth_geometry(n.p));
  test::synth_samples(n.p, [&](const Sample& s) { tuner.push(s); });
  const TuneResult t = tuner.finish();
  // THEN the noise is measured (enough blocks) but Q is not, and apply_tune leaves Q alone
  EXPECT_TRUE(t.noise_estimated);
  EXPECT_FALSE(t.q_estimated);
  EstimatorConfig cfg;
  apply_tune(t, cfg);
  EXPECT_EQ(cfg.q_override_dps2_per_s, 0.0);
  EXPECT_DOUBLE_EQ(cfg.noise_density_dps_rthz, t.noise_density_dps_rthz);
}

TEST(TuneTest, AutoTunedFilterIsConsistentOnTenTimesTheNoise) {
  // GIVEN the noisy sensor's log and no configuration
  Noisy n(23, 1800.0);
  const auto path = test::temp_path("noisy.csv");
  test::synth_log(n.p, path);
  log::LogReader untuned_reader(path);
  const auto untuned = run_estimate(untuned_reader, EstimatorConfig{}, nullptr);
  // WHEN it is tuned from the data first
  EstimatorConfig cfg;
  log::LogReader first(path);
  apply_tune(tune_from_log(first, cfg), cfg);
  log::LogReader second(path);
  const auto tuned = run_estimate(second, cfg, nullptr);
  // THEN the defaults are degraded, the tuned filter is healthy: NIS mean inside its band,
  // no rejection, >= 95 % of the bias components within 3 sigma of the truth
  EXPECT_NE(untuned.health.verdict, HealthVerdict::kOk);
  EXPECT_EQ(tuned.health.verdict, HealthVerdict::kOk);
  EXPECT_GT(tuned.health.nis_mean, tuned.health.nis_mean_band_lo);
  EXPECT_LT(tuned.health.nis_mean, tuned.health.nis_mean_band_hi);
  EXPECT_EQ(tuned.health.rejected, 0u);
  ASSERT_TRUE(tuned.truth.available);
  EXPECT_GE(tuned.truth.within_3sigma_fraction, 0.95);
}

}  // namespace
}  // namespace driftless::est
