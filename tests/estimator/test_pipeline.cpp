// One pass over a log: filter + attitude with/without correction + truth statistics.
#include <cmath>

#include <gtest/gtest.h>

#include "estimator/pipeline.hpp"
#include "tests/estimator/synth.hpp"

namespace driftless::est {
namespace {

std::filesystem::path temp_path(const std::string& name) {
  auto dir = std::filesystem::temp_directory_path() / "driftless_test_pipeline";
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

}  // namespace
}  // namespace driftless::est
