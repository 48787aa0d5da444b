// Tuning from the data (docs/estimator.md section 8): the first pass recovers the noise density N
// and the bias random walk K of seeded synthetic logs, and a filter tuned with them is consistent
// where the defaults were not.
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>

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

// GIVEN 16 seeds of 30 min of the noisy sensor (its wander a random walk over the revisits), only
// platform 1 flipping: each position is revisited 22 s after the last visit's middle, and a visit
// spans 10 s
// WHEN each is tuned
// THEN the mean K^2 over the seeds is K^2 within 3 standard errors of that mean (each run's K^2
// scatters by about 10 %, so 3 SE of 16 is 7.5 %): the revisits' spans are taken off their
// interval (a random walk averaged over spans a and b differs by q (dt - (a + b) / 6): here
// 22 - 20/6 = 18.7 s, so dt alone reads 0.85 K^2)
TEST(TuneTest, TheRandomWalkIsUnbiasedOverSeeds) {
  constexpr int kSeeds = 16;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < kSeeds; ++i) {
    Noisy n(100 + static_cast<std::uint64_t>(i), 1800.0);
    n.p.hold_platform2 = true;
    NoiseTuner tuner(EstimatorConfig{}, test::synth_geometry(n.p));
    test::synth_samples(n.p, [&](const Sample& s) { tuner.push(s); });
    const TuneResult t = tuner.finish();
    ASSERT_TRUE(t.q_estimated);
    const double ratio = t.q_dps2_per_s / Noisy::kK2;
    sum += ratio;
    sum2 += ratio * ratio;
  }
  const double mean = sum / kSeeds, sd = std::sqrt((sum2 - kSeeds * mean * mean) / (kSeeds - 1));
  std::printf("[ info ] K^2 / truth over %d seeds: mean %.4f, SD %.4f\n", kSeeds, mean, sd);
  EXPECT_LT(sd, 0.2);  // the 10 % a run scatters by, with room
  EXPECT_NEAR(mean, 1.0, 0.075);
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

// GIVEN a box turning at up to 30 deg/s with periods of 7-13 s (a pan/tilt unit's pace) whose
// sensors have 0.2-1.2 % scale-factor and cross-axis errors: within one standstill the residual
// of eq. (2) changes by up to ~0.2 deg/s from block to block through them, 10x its noise
// WHEN the first pass runs THEN the noise density is the sensor's (within 5 %: ~2000 block pairs,
// 1.6 % standard error; without the motion fit it read ~10x high on the twin's pan_tilt), and a
// bias that does not wander gives no (or a negligible) random walk
TEST(TuneTest, NoiseOfAnUncalibratedSensorOnATurningBoxIsItsOwn) {
  test::SynthParams p;
  p.duration_s = 1200.0;
  constexpr double kN = 0.005;  // deg/s/sqrt(Hz), the MPU6050's
  p.noise_sigma_dps = kN * std::sqrt(p.rate_hz);
  p.body_rate_dps = [](double t) {
    constexpr double w = 2.0 * 3.14159265358979323846;
    return Eigen::Vector3d(30.0 * std::sin(w * t / 7.0), 25.0 * std::cos(w * t / 11.0),
                           20.0 * std::sin(w * t / 13.0 + 1.0));
  };
  p.E_frac[0] << 0.012, 0.004, -0.006, -0.005, -0.009, 0.003, 0.007, -0.002, 0.010;
  p.E_frac[1] << -0.010, 0.006, 0.002, 0.003, 0.011, -0.007, -0.004, 0.005, -0.008;
  p.seed = 31;
  NoiseTuner tuner(EstimatorConfig{}, test::synth_geometry(p));
  test::synth_samples(p, [&](const Sample& s) { tuner.push(s); });
  const TuneResult t = tuner.finish();
  ASSERT_TRUE(t.noise_estimated);
  EXPECT_GT(t.noise_block_pairs, 1500u);
  EXPECT_NEAR(t.noise_density_dps_rthz, kN, 0.05 * kN);
  if (t.q_estimated) {
    EXPECT_LT(t.q_dps2_per_s, 0.1 * EstimatorConfig{}.q_dps2_per_s());
  }
}

// a still box whose two gyros differ: sensor 1 a FOG-like 0.002 deg/s/sqrt(Hz), sensor 2 a BMI088's
// 0.014 (extra white noise on it), no wander; `seed` for the draws
test::SynthParams unlike_pair(std::uint64_t seed) {
  test::SynthParams p;
  p.duration_s = 1200.0;
  p.noise_sigma_dps = 0.002 * std::sqrt(p.rate_hz);
  const double extra = std::sqrt(0.014 * 0.014 - 0.002 * 0.002) * std::sqrt(p.rate_hz);
  auto rng = std::make_shared<std::mt19937_64>(seed + 1000);
  p.extra_noise_dps = [rng, extra](int sensor, std::size_t) {
    std::normal_distribution<double> n(0.0, extra);
    return sensor == 2 ? Eigen::Vector3d(n(*rng), n(*rng), n(*rng)) : Eigen::Vector3d::Zero();
  };
  p.seed = seed;
  return p;
}

TEST(TuneTest, AnUnlikePairIsTunedToThePairsNoiseNotTheQuieterOnes) {
  // GIVEN 20 min of the unlike pair on a still box
  const test::SynthParams p = unlike_pair(41);
  NoiseTuner tuner(EstimatorConfig{}, test::synth_geometry(p));
  test::synth_samples(p, [&](const Sample& s) { tuner.push(s); });
  const TuneResult t = tuner.finish();
  // THEN N is the density whose R = 2 N^2 rate matches r = y1 - y2's noise, sigma1^2 + sigma2^2:
  // sqrt((0.002^2 + 0.014^2) / 2) = 0.0100, within 3 % (about 2000 block pairs: 1.6 % standard
  // error). The fused rate's noise, correlated with r's, is no motion to fit (it was: 0.0028)
  ASSERT_TRUE(t.noise_estimated);
  const double pair = std::sqrt((0.002 * 0.002 + 0.014 * 0.014) / 2.0);
  EXPECT_NEAR(t.noise_density_dps_rthz, pair, 0.03 * pair);
}

TEST(TuneTest, NoWanderAboveTheNoiseGivesAnUpperBoundOfQNotTheDefault) {
  // GIVEN the quiet FOG-like gyro on both sides (0.002 deg/s/sqrt(Hz)) and biases that hold still
  test::SynthParams p;
  p.duration_s = 1200.0;
  p.noise_sigma_dps = 0.002 * std::sqrt(p.rate_hz);
  p.seed = 42;
  NoiseTuner tuner(EstimatorConfig{}, test::synth_geometry(p));
  test::synth_samples(p, [&](const Sample& s) { tuner.push(s); });
  const TuneResult t = tuner.finish();
  // THEN Q is not measured as a wander but bounded: the bound is the one-sided 97.5 % limit of the
  // revisits' noise, 1.96 sqrt(sum 6 v^2) / sum 6 dt, with v = 2 sigma^2 (1/n_a + 1/n_b) per axis and
  // pair. Closed form here: sigma^2 = 0.002^2 * 100 = 4e-4, n ~ 1000 per visit (v = 1.6e-6), ~105
  // revisits 44 s apart: 1.96 sqrt(105 * 6) 1.6e-6 / (105 * 264) = 2.8e-9; the estimate adds the
  // measured part below the bound (at most as much again): 2e-9 .. 8e-9 (deg/s)^2/s, where the
  // MPU6050 default 1.3e-6 was kept before
  ASSERT_TRUE(t.q_estimated);
  EXPECT_TRUE(t.q_upper_bound);
  EXPECT_GT(t.q_dps2_per_s, 2e-9);
  EXPECT_LT(t.q_dps2_per_s, 8e-9);
  // AND the filter tuned with it is safe (nothing rejected, NIS not above its band, >= 95 % of the
  // updates within 3 sigma of the truth) and its sigma follows the data: below a fifth of the sigma
  // with the default Q
  const auto path = test::temp_path("fog_tuned.csv");
  test::synth_log(p, path);
  auto run = [&](const EstimatorConfig& cfg) {
    log::LogReader reader(path);
    return run_estimate(reader, cfg, nullptr);
  };
  EstimatorConfig tuned;
  apply_tune(t, tuned);
  const EstimateSummary s = run(tuned), dflt = run(EstimatorConfig{});
  EXPECT_EQ(s.health.rejected, 0u);
  EXPECT_LT(s.health.nis_mean, s.health.nis_mean_band_hi);
  EXPECT_GE(s.truth.within_3sigma_fraction, 0.95);
  EXPECT_LT(s.sigma_dps.maxCoeff(), 0.2 * dflt.sigma_dps.maxCoeff());
}

// GIVEN 30 min of a box rocking like a boat (+-20 deg about x every 17 s: up to 7.4 deg/s; yawing
// +-17 deg every 61 s), 1 % scale/cross-axis errors, the MPU6050's noise (0.005 deg/s/sqrt(Hz)) and
// a bias wander that acts as a random walk with K^2 = 2e-6 (deg/s)^2/s, 20 s standstills
// WHEN the first pass runs
// THEN K^2 is measured (not bounded) within 40 % (about 20 revisits, 3 axes: ~20 % standard error).
// The motion fit's coefficient error is what the revisits' regressors (visit means 1-3 deg/s
// apart) pay for it: the consecutive block pairs of a standstill share a block, so for a smooth
// motion their sum telescopes and the fit knows the coefficients far better than independent
// pairs would (the sandwich (X'WX)^-1 X'W S W X (X'WX)^-1, S the pairs' covariance). Taken as
// independent, the error was put at 3-10x the revisits' whole residual and K^2 read as "no wander
// above the noise": an upper bound of 1e-8, 150x low (navgen's rocking MPU6050, issue 13)
TEST(TuneTest, TheRandomWalkOfARockingBoxIsMeasured) {
  constexpr double kK2 = 2e-6, kTau = 2.0e4, kN = 0.005;
  test::SynthParams p;
  p.duration_s = 1800.0;
  p.standstill_s = 20.0;
  p.noise_sigma_dps = kN * std::sqrt(p.rate_hz);
  p.gm_sigma_dps = std::sqrt(kK2 * kTau / 2.0);
  p.gm_tau_s = kTau;
  p.body_rate_dps = [](double t) {
    constexpr double kTwoPi = 2.0 * 3.14159265358979323846;
    return Eigen::Vector3d(20.0 * kTwoPi / 17.0 * std::cos(kTwoPi * t / 17.0), 0.0,
                           17.2 * kTwoPi / 61.0 * std::cos(kTwoPi * t / 61.0));
  };
  p.E_frac[0] << 0.010, 0.004, -0.006, -0.005, -0.009, 0.003, 0.007, -0.002, 0.010;
  p.E_frac[1] << -0.010, 0.006, 0.002, 0.003, 0.011, -0.007, -0.004, 0.005, -0.008;
  p.seed = 57;
  NoiseTuner tuner(EstimatorConfig{}, test::synth_geometry(p));
  test::synth_samples(p, [&](const Sample& s) { tuner.push(s); });
  const TuneResult t = tuner.finish();
  ASSERT_TRUE(t.noise_estimated);
  EXPECT_NEAR(t.noise_density_dps_rthz, kN, 0.05 * kN);
  EXPECT_GE(t.wander_pairs, 15u);
  ASSERT_TRUE(t.q_estimated);
  EXPECT_FALSE(t.q_upper_bound);
  std::printf("[ info ] rocking box: K^2 %.3g against %.3g\n", t.q_dps2_per_s, kK2);
  EXPECT_NEAR(t.q_dps2_per_s, kK2, 0.4 * kK2);
}

}  // namespace
}  // namespace driftless::est
