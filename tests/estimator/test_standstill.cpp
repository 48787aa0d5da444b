// Standstill detection (estimator/standstill.hpp) and the filter's end-of-stream handling.
#include <cmath>

#include <gtest/gtest.h>

#include "estimator/filter.hpp"
#include "estimator/pipeline.hpp"
#include "estimator/standstill.hpp"
#include "tests/estimator/synth.hpp"
#include "tests/temp_path.hpp"

namespace driftless::est {
namespace {

Sample resting(double t, double p1, double p2) {
  Sample s;
  s.t_s = t;
  s.gyro1_dps = Eigen::Vector3d(0.1, 0.2, 0.3);
  s.gyro2_dps = Eigen::Vector3d(-0.1, 0.4, 0.0);
  s.plat1_deg = p1;
  s.plat2_deg = p2;
  return s;
}

BoxGeometry box100() {
  BoxGeometry b;
  b.sample_rate_hz = 100.0;
  b.validate();
  return b;
}

TEST(StandstillTest, SettleAndEndMarginAreLeftOutOfTheSegment) {
  // GIVEN 10 s at rest at (+90, +90), then a move of platform 1
  EstimatorConfig cfg;  // settle 0.5 s, end margin 0.1 s
  StandstillDetector d(cfg, box100());
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  int closed = 0;
  StandstillSegment seg;
  for (int k = 0; k <= 1000; ++k) {
    const double t = 0.01 * k;
    const auto st = d.push(resting(t, k < 1000 ? 90.0 : 80.0, 90.0), 0.01, zero, zero);
    if (st.closed > 0) {
      ++closed;
      seg = d.closed(0);
    }
  }
  // THEN one segment from t = 0.51 s (the first sample only marks rest; 0.5 s settle) to the
  // last sample outside the 0.1 s end margin
  ASSERT_EQ(closed, 1);
  EXPECT_NEAR(seg.t_first_s, 0.51, 1e-9);
  EXPECT_NEAR(seg.t_last_s, 9.89, 1e-9);
  EXPECT_EQ(seg.n, 939u);
  EXPECT_EQ(seg.end, SegmentEnd::kMotion);
  EXPECT_LT((seg.mean_gyro1_dps() - Eigen::Vector3d(0.1, 0.2, 0.3)).norm(), 1e-12);
}

TEST(StandstillTest, AStreamThatEndsAtRestHandsOverItsLastStandstillWithEverySample) {
  EstimatorConfig cfg;
  StandstillDetector d(cfg, box100());
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  for (int k = 0; k < 500; ++k) EXPECT_EQ(d.push(resting(0.01 * k, 90.0, -90.0), 0.01, zero, zero).closed, 0);
  // WHEN the stream ends
  ASSERT_EQ(d.finish(), 1);
  // THEN the end margin is kept: no motion follows
  EXPECT_EQ(d.closed(0).end, SegmentEnd::kFinish);
  EXPECT_NEAR(d.closed(0).t_last_s, 4.99, 1e-9);
  EXPECT_EQ(d.closed(0).n, 449u);
  EXPECT_EQ(d.finish(), 0);  // nothing left
}

TEST(StandstillTest, LongStandstillsAreSplitWhenAsked) {
  EstimatorConfig cfg;
  cfg.max_standstill_s = 2.0;
  StandstillDetector d(cfg, box100());
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  int splits = 0;
  for (int k = 0; k < 1051; ++k) {
    const auto st = d.push(resting(0.01 * k, 90.0, 90.0), 0.01, zero, zero);
    for (int i = 0; i < st.closed; ++i) splits += d.closed(i).end == SegmentEnd::kSplit ? 1 : 0;
  }
  // 10 s of rest after 0.5 s settling: pieces of 2 s (201 samples each: t - t_first >= 2 s)
  EXPECT_EQ(splits, 4);
  EXPECT_EQ(d.finish(), 1);
}

TEST(StandstillTest, AWholeLogStandstillGivesAnUpdateAndSaysWhatStaysUnobservable) {
  // GIVEN a log whose platforms never move (constant angles) and default settings
  test::SynthParams p;
  p.duration_s = 120.0;
  p.standstill_s = 1e9;  // one standstill for the whole log
  p.noise_sigma_dps = 0.05;
  const auto path = test::temp_path("driftless_whole_log_standstill.csv");
  test::synth_log(p, path);
  // WHEN estimate runs
  log::LogReader reader(path);
  const auto s = run_estimate(reader, EstimatorConfig{}, nullptr);
  // THEN the standstill is used once, at the end, and no "no standstill found" warning appears
  EXPECT_EQ(s.counters.updates, 1u);
  for (const auto& w : s.warnings) EXPECT_EQ(w.find("no standstill"), std::string::npos) << w;
  // one position: R1 b1 - R2 b2 is measured (3 of 6 directions), so sigma stays large elsewhere
  EXPECT_GT(s.sigma_dps.maxCoeff(), 1.0);
}

TEST(StandstillTest, TheLastStandstillOfALogIsKept) {
  // GIVEN the synthetic flip cycle cut in the middle of a standstill (10 s rest + 1 s flip)
  test::SynthParams p;
  p.duration_s = 115.5;  // ends 5.5 s into the 11th standstill
  p.noise_sigma_dps = 0.05;
  EstimatorConfig cfg;
  DriftlessFilter f(cfg, test::synth_geometry(p));
  test::synth_samples(p, [&](const Sample& s) { f.push(s); });
  EXPECT_EQ(f.counters().updates, 10u);
  // WHEN the stream ends THEN the 11th standstill becomes the 11th update
  const PushStatus st = f.finish();
  EXPECT_EQ(st, PushStatus::kUpdated);
  EXPECT_EQ(f.counters().updates, 11u);
  EXPECT_TRUE(f.last_update().at_end);
  EXPECT_NEAR(f.last_update().t_s, 115.49, 1e-6);
}

TEST(StandstillTest, ReLocksAreReportedWithTheirTime) {
  // GIVEN a 1 deg/s bias step at t = 250 s in a log
  test::SynthParams p;
  p.duration_s = 600.0;
  p.noise_sigma_dps = 0.05;
  const auto path = test::temp_path("driftless_relock_report.csv");
  {
    log::LogWriter w(path, test::synth_metadata(p), kFieldTrueBias);
    test::synth_samples(p, [&](const Sample& s) {
      Sample x = s;
      if (s.t_s > 250.0) x.gyro1_dps.x() += 1.0;
      w.write(x);
    });
    w.finish(true);
  }
  EstimatorConfig cfg;
  cfg.q_override_dps2_per_s = 1e-14;
  log::LogReader reader(path);
  const auto s = run_estimate(reader, cfg, nullptr);
  // THEN the summary lists the re-lock after the step, and a warning names its time
  ASSERT_GE(s.relocks.size(), 1u);
  EXPECT_GT(s.relocks[0].t_s, 250.0);
  EXPECT_LT(s.relocks[0].t_s, 300.0);
  bool warned = false;
  for (const auto& w : s.warnings) warned = warned || w.find("re-locked at t =") != std::string::npos;
  EXPECT_TRUE(warned);
}

}  // namespace
}  // namespace driftless::est
