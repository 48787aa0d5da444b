// One pass over a log: filter + attitude with/without correction + truth statistics.
#include <cmath>

#include <gtest/gtest.h>

#include "estimator/pipeline.hpp"
#include "tests/estimator/synth.hpp"
#include "tests/temp_path.hpp"

namespace driftless::est {
namespace {

std::filesystem::path temp_path(const std::string& name) {
  auto dir = test::temp_path("driftless_test_pipeline");
  std::filesystem::create_directories(dir);
  return dir / name;
}

TEST(PipelineTest, CorrectionCutsAttitudeDriftOnAPanTiltRun) {
  // GIVEN a 10-minute pan/tilt-like run with MPU6050-size biases and noise
  test::SynthParams p;
  p.duration_s = 600.0;
  p.noise_sigma_dps = 0.05;
  p.body_rate_dps = [](double t) {
    return Eigen::Vector3d(3.0 * std::sin(0.05 * t), 2.0 * std::sin(0.031 * t + 1.0), 5.0 * std::cos(0.02 * t));
  };
  const auto path = temp_path("pan_tilt.csv");
  test::synth_log(p, path);
  // WHEN estimate runs over it
  log::LogReader reader(path);
  const auto s = run_estimate(reader, EstimatorConfig{}, nullptr);
  // THEN the attitude drift falls by more than 20x
  EXPECT_EQ(s.rows, 60000u);
  ASSERT_TRUE(s.attitude_available);
  EXPECT_GT(s.drift_raw_deg_per_h, 100.0);  // flipping already averages part of the bias out
  EXPECT_LT(s.drift_corrected_deg_per_h, 0.05 * s.drift_raw_deg_per_h);
  ASSERT_TRUE(s.truth.available);
  EXPECT_GT(s.truth.updates, 40u);
  EXPECT_LT(s.truth.bias_error_rms_second_half_dps, 0.01);
  EXPECT_GT(s.truth.within_3sigma_fraction, 0.95);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
}

TEST(PipelineTest, ComparisonStartsWhenLockedAndAFixedBiasThenDoesNotDrift) {
  // GIVEN a noise-free moving run with constant biases (the estimate is exact once locked)
  test::SynthParams p;
  p.duration_s = 300.0;
  p.body_rate_dps = [](double t) { return Eigen::Vector3d(2.0 * std::sin(0.1 * t), 1.0, -3.0 * std::cos(0.07 * t)); };
  const auto path = temp_path("constant_bias.csv");
  test::synth_log(p, path);
  log::LogReader reader(path);
  const auto s = run_estimate(reader, EstimatorConfig{}, nullptr);
  // THEN the comparison starts after the first standstills, not at t = 0,
  ASSERT_TRUE(std::isfinite(s.attitude_start_s));
  EXPECT_GT(s.attitude_start_s, p.standstill_s);
  EXPECT_LT(s.attitude_start_s, 5.0 * (p.standstill_s + p.flip_s));
  // the bias it fixed there is the truth, and neither corrected integration drifts (closed form:
  // zero; 0.1 deg/h allows for the integrator's discretisation of the varying rate), the two
  // agree with each other, while the uncorrected one drifts at about |b| (~1.5 deg/s = 5400 deg/h)
  Vector6d truth;
  truth << p.b1_dps, p.b2_dps;
  EXPECT_LT((s.fixed_bias_dps - truth).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT(std::fabs(s.drift_corrected_deg_per_h), 0.1);
  EXPECT_LT(std::fabs(s.drift_fixed_deg_per_h), 0.1);
  EXPECT_NEAR(s.drift_fixed_deg_per_h, s.drift_corrected_deg_per_h, 1e-3);
  EXPECT_GT(s.drift_raw_deg_per_h, 1000.0);
}

TEST(PipelineTest, AWanderingBiasMakesTheFixedBiasDriftButNotDriftLess) {
  // GIVEN a static box whose biases wander (Gauss-Markov, 0.05 deg/s over 300 s) with noise
  test::SynthParams p;
  p.duration_s = 1800.0;
  p.noise_sigma_dps = 0.05;
  p.gm_sigma_dps = 0.05;
  p.gm_tau_s = 300.0;
  p.seed = 7;
  const auto path = temp_path("wander.csv");
  test::synth_log(p, path);
  log::LogReader reader(path);
  EstimatorConfig cfg;
  cfg.bias_instability_dps = 0.05;
  cfg.bias_instability_tau_s = 300.0;
  const auto s = run_estimate(reader, cfg, nullptr);
  // THEN a bias calibrated once drifts several times faster than the running DriftLess estimate
  ASSERT_TRUE(std::isfinite(s.drift_fixed_deg_per_h));
  EXPECT_GT(s.drift_fixed_deg_per_h, 3.0 * s.drift_corrected_deg_per_h)
      << "fixed " << s.drift_fixed_deg_per_h << " DriftLess " << s.drift_corrected_deg_per_h;
}

TEST(PipelineTest, AFilterThatNeverLocksGivesNoComparisonAndSaysWhy) {
  // GIVEN a run where platform 2 never flips: one bias component stays unobservable
  test::SynthParams p;
  p.duration_s = 200.0;
  p.hold_platform2 = true;
  const auto path = temp_path("no_lock.csv");
  test::synth_log(p, path);
  {
    log::LogReader reader(path);
    const auto s = run_estimate(reader, EstimatorConfig{}, nullptr);
    EXPECT_TRUE(std::isnan(s.attitude_start_s));
    EXPECT_TRUE(std::isnan(s.drift_corrected_deg_per_h));
    bool said = false;
    for (const auto& w : s.warnings) said = said || w.find("never locked") != std::string::npos;
    EXPECT_TRUE(said);
  }
  // AND a start sigma of 0 compares from the log's first sample
  log::LogReader reader(path);
  EstimateRunOptions opt;
  opt.attitude_start_sigma_dps = 0.0;
  const auto s = run_estimate(reader, EstimatorConfig{}, nullptr, opt);
  EXPECT_DOUBLE_EQ(s.attitude_start_s, 0.0);
  EXPECT_TRUE(std::isfinite(s.drift_corrected_deg_per_h));
}

}  // namespace
}  // namespace driftless::est
