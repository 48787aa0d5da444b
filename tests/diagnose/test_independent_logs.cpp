// The lean, fast part of the acceptance tests on logs this project did not make
// (independent_log.py; the seed sweeps are in slow_test_independent_logs.cpp): diagnosed with
// the embedded default model, as `driftless diagnose` without --model.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "tests/diagnose/independent_logs.hpp"

namespace driftless::diagnose {
namespace {

// every selected effect of `r` other than `e` belongs to the signal chain
bool others_signal_chain(const CompareResult& r, Effect e) {
  for (const auto& c : r.selected)
    if (c.effect != e && c.family() != Family::kSignalChain) return false;
  return true;
}

TEST(IndependentLogsFast, PlantedScaleWithoutDlpfIsFoundFirstAndApplyCloses) {
  // GIVEN a 100 Hz pan/tilt log without any DLPF (the model has DLPF_CFG 3), 1.5x the MPU6050's
  // noise and sensor 1's x axis reading 3 % high
  indep::Source src;
  src.seed = 7;
  src.duration_s = 90.0;
  src.noise_scale = 1.5;
  src.dlpf = "none";
  src.plants = {"scale:1:x:3"};
  const auto log = indep::generate(src, "fast_scale");
  // WHEN it is diagnosed with the embedded model
  const CompareResult r = indep::diagnose_log(log);
  // THEN the scale error is the first non-signal-chain effect, within 20 %, and the missing
  // filter is reported as the signal chain (never instead of the scale error)
  ASSERT_EQ(r.verdict, Verdict::kMissingEffect) << r.statement;
  const Candidate* scale = indep::selected(r, Effect::kScaleFactor);
  ASSERT_NE(scale, nullptr) << r.statement;
  const FittedParam* fp = find_param(*scale, "s1.x.value_pct");
  ASSERT_NE(fp, nullptr) << r.statement;
  EXPECT_NEAR(fp->new_value(), 3.0, 0.6) << r.statement;
  EXPECT_TRUE(others_signal_chain(r, Effect::kScaleFactor)) << r.statement;
  EXPECT_FALSE(r.any_absurd()) << r.statement;
  // AND after --apply (written to YAML and read back) the log is consistent with the model
  const CompareResult again = indep::apply_and_compare(log, r, "fast_scale");
  EXPECT_EQ(again.verdict, Verdict::kConsistent) << again.statement;
  std::filesystem::remove(log);
}

TEST(IndependentLogsFast, CleanLogIsConsistentOrOnlyItsSignalChain) {
  // GIVEN a 200 Hz sweep log with another DLPF (cfg 1) and nothing planted
  indep::Source src;
  src.seed = 11;
  src.rate_hz = 200.0;
  src.duration_s = 60.0;
  src.motion = "sweep";
  src.dlpf = "cfg:1";
  const auto log = indep::generate(src, "fast_clean");
  // WHEN it is diagnosed with the embedded model (DLPF_CFG 3, 100 Hz: one rate policy, the
  // model runs at the log's 200 Hz)
  const CompareResult r = indep::diagnose_log(log);
  std::filesystem::remove(log);
  // THEN nothing physical is reported
  EXPECT_TRUE(r.verdict == Verdict::kConsistent || others_signal_chain(r, Effect::kCount)) << r.statement;
  EXPECT_NE(r.verdict, Verdict::kUnexplained) << r.statement;
}

TEST(IndependentLogsFast, AScaleBesideALateSensorIsIdentified) {
  // GIVEN a 60 s, 50 Hz wobble without a DLPF, sensor 2 sampling 18 ms late and sensor 1's z axis
  // reading 3 % high (temperature logged: a scale tempco is the scale's look-alike)
  indep::Source src;
  src.seed = 315;
  src.rate_hz = 50.0;
  src.duration_s = 60.0;
  src.motion = "wobble";
  src.noise_scale = 1.5;
  src.lag_sensor = 2;
  src.lag_s = 0.018;
  src.temperature = true;
  src.plants = {"scale:1:z:3"};
  const auto log = indep::generate(src, "fast_late");
  // WHEN it is diagnosed (with the sample delay free, a scale's information is ~1e-9 of the
  // delay's in their units: the identifiability test must not compare units)
  const CompareResult r = indep::diagnose_log(log);
  std::filesystem::remove(log);
  // THEN the scale is selected, within 20 %, and no temperature coefficient stands in for it
  const Candidate* scale = indep::selected(r, Effect::kScaleFactor);
  ASSERT_NE(scale, nullptr) << r.statement;
  const FittedParam* fp = find_param(*scale, "s1.z.value_pct");
  ASSERT_NE(fp, nullptr) << r.statement;
  EXPECT_NEAR(fp->new_value(), 3.0, 0.6) << r.statement;
  EXPECT_EQ(indep::selected(r, Effect::kTemperature), nullptr) << r.statement;
  EXPECT_NE(indep::selected(r, Effect::kSampleDelay), nullptr) << r.statement;
}

TEST(IndependentLogsFast, ColumnSweepGivesEveryColumnAsColumnValueDoes) {
  // GIVEN a 30 s pan/tilt log with temperature, made apart from twin/, and its residual against
  // the embedded model
  indep::Source src;
  src.seed = 5;
  src.duration_s = 30.0;
  src.temperature = true;
  const auto log = indep::generate(src, "fast_sweep");
  const Replay r = replay_log(log, ReplayOptions{});
  std::filesystem::remove(log);
  const CompareModel model = default_compare_model();
  const Residual res = make_residual(r, model, 0.1);
  const ColumnInputs in{r, res, model.sensor};
  // WHEN every column of every channel is swept over the fit samples (with the gaps where
  // samples are left out, so the kept stencil is both rolled and rebuilt)
  int compared = 0;
  for (int c = 0; c < 6; ++c) {
    ColumnSweep sweep(in, c / 3, c % 3);
    for (std::size_t k = 0; k < res.n; ++k) {
      if (!res.bmask[k]) continue;
      for (int col = 0; col < kNumCols; ++col) {
        // THEN each value is column_value's (to rounding: the two forms may contract differently)
        const double want = column_value(in, c / 3, c % 3, col, k), got = sweep.value(col, k);
        ASSERT_NEAR(got, want, 1e-12 * std::max(1.0, std::abs(want))) << "channel " << c << " column " << col << " sample " << k;
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 100000);
}

}  // namespace
}  // namespace driftless::diagnose
