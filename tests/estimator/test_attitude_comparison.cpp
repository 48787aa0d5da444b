// GIVEN a synthetic moving run WHEN the attitude comparison is streamed sample by sample (as the
// video overlay does) THEN it starts where `driftless estimate` starts it and reports the same
// errors; before lock it reports nothing.
#include <gtest/gtest.h>

#include "estimator/attitude_comparison.hpp"
#include "estimator/pipeline.hpp"
#include "tests/estimator/synth.hpp"

namespace driftless::est {
namespace {

struct Collect : EstimateSink {
  std::vector<AttitudePoint> points;
  void on_attitude(const AttitudePoint& p) override { points.push_back(p); }
};

TEST(AttitudeComparison, StreamedItMatchesTheEstimatePass) {
  test::SynthParams p;
  p.duration_s = 200.0;
  p.noise_sigma_dps = 0.01;
  p.body_rate_dps = [](double t) { return Eigen::Vector3d(2.0 * std::sin(0.1 * t), 1.0, -3.0 * std::cos(0.07 * t)); };
  const auto path = std::filesystem::temp_directory_path() / "driftless_attitude_comparison.csv";
  test::synth_log(p, path);
  // WHEN run_estimate makes its comparison
  log::LogReader reader(path);
  Collect sink;
  const EstimateSummary sum = run_estimate(reader, EstimatorConfig{}, &sink);
  ASSERT_TRUE(std::isfinite(sum.attitude_start_s));
  ASSERT_GT(sink.points.size(), 10u);
  // AND the stream is fed the same samples
  log::LogReader again(path);
  DriftlessFilter filter(EstimatorConfig{}, box_geometry_from_metadata(again.metadata()));
  AttitudeComparison cmp(again.metadata().latitude_deg(), EstimateRunOptions{}.attitude_start_sigma_dps, 1.0);
  std::vector<AttitudePoint> streamed;
  Sample s;
  while (again.next(s)) {
    filter.push(s);
    const bool locked = filter_locked(filter, EstimateRunOptions{}.attitude_start_sigma_dps);
    AttitudePoint ap;
    const bool point = cmp.push(s, filter, ap);
    // nothing is compared before lock
    if (!locked) {
      EXPECT_FALSE(point) << "t = " << s.t_s;
    }
    if (point) streamed.push_back(ap);
  }
  // THEN both start at the same sample, hold the same bias and give the same errors
  EXPECT_EQ(cmp.start_s(), sum.attitude_start_s);
  EXPECT_EQ(cmp.fixed_bias_dps(), sum.fixed_bias_dps);
  ASSERT_EQ(streamed.size(), sink.points.size());
  for (std::size_t i = 0; i < streamed.size(); ++i) {
    EXPECT_EQ(streamed[i].t_s, sink.points[i].t_s);
    EXPECT_EQ(streamed[i].corrected.angle_deg, sink.points[i].corrected.angle_deg);
    EXPECT_EQ(streamed[i].fixed.angle_deg, sink.points[i].fixed.angle_deg);
  }
  EXPECT_EQ(cmp.drifts().corrected_deg_per_h, sum.drift_corrected_deg_per_h);
  std::filesystem::remove(path);
}

TEST(AttitudeComparison, LockNeedsAnUpdateAndEverySigmaBelowTheLevel) {
  test::SynthParams p;
  DriftlessFilter filter(EstimatorConfig{}, test::synth_geometry(p));
  // no update yet: not locked at any positive level, locked at level 0 (compare from the start)
  EXPECT_FALSE(filter_locked(filter, 0.05));
  EXPECT_FALSE(filter_locked(filter, 1e9));
  EXPECT_TRUE(filter_locked(filter, 0.0));
}

}  // namespace
}  // namespace driftless::est
