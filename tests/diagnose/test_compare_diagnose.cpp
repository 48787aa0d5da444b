// GIVEN a "measured" log with one hidden effect and a model lacking it, WHEN compared,
// THEN that effect ranks first with its parameter within 20 %, and applying it removes the
// systematic residual. Logs: closed-form pan/tilt kinematics + the SensorModel (seeded).
#include <gtest/gtest.h>

#include "tests/diagnose/diagnosis_checks.hpp"

#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include "tests/diagnose/compare_test_log.hpp"
#include "tests/diagnose/compare_twin_log.hpp"
#include "diagnose/apply.hpp"
#include "diagnose/compare.hpp"

namespace driftless::diagnose {

using namespace driftless::twin;  // the sensor model, scenario and simulator
namespace {

constexpr double kDuration = 150.0;

// the log's sensor: MPU6050 defaults with the run-to-run draws fixed at zero, noise kept
SensorParams base_sensor() { return twinlog::base_sensor(); }

CompareResult run(const SensorParams& log1, const SensorParams& log2, const SensorParams& model1,
                  const SensorParams& model2, std::uint64_t seed) {
  const auto lg = testlog::make_log(log1, log2, kDuration, seed);
  const Replay rp = replay_samples(lg.samples, lg.meta, lg.fields, ReplayOptions{}, "test.csv");
  CompareModel m = default_compare_model();
  m.sensor = {model1, model2};
  m.source = "test model";
  return compare(rp, m, CompareOptions{});
}


TEST(CompareDiagnose, CleanLogIsConsistentWithNoise) {
  // GIVEN logs whose sensors match the model exactly (noise only)
  int consistent = 0;
  const int seeds = 3;
  for (int seed = 1; seed <= seeds; ++seed) {
    const SensorParams p = base_sensor();
    // WHEN compared
    const CompareResult res = run(p, p, p, p, static_cast<std::uint64_t>(seed));
    if (res.verdict == Verdict::kConsistent) ++consistent;
    else ADD_FAILURE() << "seed " << seed << ": " << res.statement;
  }
  // THEN every seed is consistent with the noise model
  EXPECT_EQ(consistent, seeds);
}

TEST(CompareDiagnose, OffsetBeyondTheZeroRateToleranceIsLoud) {
  // GIVEN a gyro 30 deg/s off the reference on sensor 1 x (beyond the MPU6050's +-20 deg/s
  // zero-rate tolerance: the reference turns where the gyro does not) and 12 deg/s off on
  // sensor 2 y (a turn-on bias an MPU6050 can have), and a model without either
  const SensorParams p = base_sensor();
  SensorParams off1 = p, off2 = p;
  off1.constant_bias.value_dps += Eigen::Vector3d(30.0, 0.0, 0.0);
  off2.constant_bias.value_dps += Eigen::Vector3d(0.0, 12.0, 0.0);
  // WHEN compared
  const CompareResult res = run(off1, off2, p, p, 4);
  // THEN only gx1 is flagged, the comparison is not called consistent, and the statement says
  // what to check
  ASSERT_EQ(res.offset_beyond_zro, std::vector<int>{0}) << res.statement;
  EXPECT_NEAR(res.channels[0].turn_on_bias_dps, 30.0, 0.5);
  EXPECT_NEAR(res.channels[4].turn_on_bias_dps, 12.0, 0.5);
  EXPECT_NE(res.verdict, Verdict::kConsistent) << res.statement;
  EXPECT_NE(res.statement.find("zero-rate tolerance"), std::string::npos) << res.statement;
  EXPECT_NE(res.statement.find("gyro1_x +30"), std::string::npos) << res.statement;
}

TEST(CompareDiagnose, ScaleFactorFoundAndApplied) {
  // GIVEN sensor 1 with scale errors of +3 % (x) and -2 % (z), and a model without scale errors
  SensorParams truth = base_sensor();
  truth.scale_factor.value_pct = Eigen::Vector3d(3.0, 0.0, -2.0);
  const SensorParams model = base_sensor();
  // WHEN diagnosed
  const CompareResult res = run(truth, model, model, model, 11);
  // THEN scale_factor ranks first, within 20 % of the truth
  ASSERT_EQ(res.verdict, Verdict::kMissingEffect) << res.statement;
  const Candidate& best = check::top(res);
  EXPECT_EQ(std::string(effect_id(best.effect)), "scale_factor") << res.statement;
  // on sensor 1: the candidate may carry a sensor-2 term only at the level of the noise (seed 11
  // of the FastBox log fits s2.z = 0.027 +- 0.009 %, and 'both' then wins by its evidence), far
  // below the planted 2-3 %
  EXPECT_TRUE(sensor_text(best) == "1" || sensor_text(best) == "both") << res.statement;
  for (const FittedParam& p : best.params) {
    if (p.name().rfind("s2.", 0) == 0) {
      EXPECT_LT(std::abs(p.new_value()), 0.1) << p.name() << ": " << res.statement;
    }
  }
  const auto* px = find_param(best, "s1.x.value_pct");
  const auto* pz = find_param(best, "s1.z.value_pct");
  ASSERT_TRUE(px && pz) << res.statement;
  EXPECT_NEAR(px->new_value(), 3.0, 0.6);
  EXPECT_NEAR(pz->new_value(), -2.0, 0.4);
  // AND after applying it the systematic residual falls >= 5x or to within 10 % of the floor
  CompareModel m = default_compare_model();
  m.sensor = {model, model};
  apply_candidate(m, best);
  const auto lg = testlog::make_log(truth, model, kDuration, 11);
  const Replay rp = replay_samples(lg.samples, lg.meta, lg.fields, ReplayOptions{}, "test.csv");
  const CompareResult again = compare(rp, m, CompareOptions{});
  for (int c : {0, 2}) {
    const auto& before = res.channels[c];
    const auto& after = again.channels[c];
    EXPECT_TRUE(after.systematic_rms_dps * 5.0 <= before.systematic_rms_dps ||
                after.rms_dps <= 1.1 * after.noise_floor_dps)
        << channel_name(c) << " systematic " << before.systematic_rms_dps << " -> " << after.systematic_rms_dps;
  }
  EXPECT_EQ(again.verdict, Verdict::kConsistent) << again.statement;
}

TEST(CompareDiagnose, GSensitivityFound) {
  // GIVEN sensor 2 with a g-sensitivity of 0.1 deg/s/g on its y axis from gravity along z
  SensorParams truth = base_sensor();
  truth.g_sensitivity.matrix_dps_per_g(1, 2) = 0.1;
  truth.g_sensitivity.matrix_dps_per_g(0, 0) = -0.1;
  const SensorParams model = base_sensor();
  const CompareResult res = run(model, truth, model, model, 5);
  ASSERT_EQ(res.verdict, Verdict::kMissingEffect) << res.statement;
  const Candidate& best = check::top(res);
  EXPECT_EQ(std::string(effect_id(best.effect)), "g_sensitivity") << res.statement;
  const auto* p = find_param(best, "s2.matrix_dps_per_g[y][z]");
  ASSERT_NE(p, nullptr) << res.statement;
  EXPECT_NEAR(p->new_value(), 0.1, 0.02);
}

TEST(CompareDiagnose, TemperatureBiasCoefficientFound) {
  // GIVEN sensor 1 self-heating by 5 degC (tau 100 s) with a bias tempco of 0.1 deg/s/degC on x
  SensorParams model = base_sensor();
  model.temperature.warmup_rise_degc = 5.0;
  model.temperature.warmup_tau_s = 100.0;
  SensorParams truth = model;
  truth.temperature.bias_tc_dps_per_degc = Eigen::Vector3d(0.1, 0.0, 0.0);
  const CompareResult res = run(truth, model, model, model, 11);
  ASSERT_EQ(res.verdict, Verdict::kMissingEffect) << res.statement;
  const Candidate& best = check::top(res);
  EXPECT_EQ(std::string(effect_id(best.effect)), "temperature") << res.statement;
  const auto* p = find_param(best, "s1.x.bias_tc_dps_per_degc");
  ASSERT_NE(p, nullptr) << res.statement;
  EXPECT_NEAR(p->new_value(), 0.1, 0.02);
}

TEST(CompareDiagnose, MisalignmentFound) {
  // GIVEN sensor 1 with a 2 % cross-axis coupling of y into x and 1.5 % of x into z
  SensorParams truth = base_sensor();
  truth.misalignment.matrix_pct(0, 1) = 2.0;
  truth.misalignment.matrix_pct(2, 0) = 1.5;
  const SensorParams model = base_sensor();
  const CompareResult res = run(truth, model, model, model, 11);
  ASSERT_EQ(res.verdict, Verdict::kMissingEffect) << res.statement;
  const Candidate& best = check::top(res);
  EXPECT_EQ(std::string(effect_id(best.effect)), "misalignment") << res.statement;
  const auto* p = find_param(best, "s1.matrix_pct[x][y]");
  ASSERT_NE(p, nullptr) << res.statement;
  EXPECT_NEAR(p->new_value(), 2.0, 0.4);
}

TEST(CompareDiagnose, TwoHiddenEffectsInOneRun) {
  // GIVEN a scale error on sensor 1 and a g-sensitivity on sensor 2, model lacking both
  SensorParams t1 = base_sensor(), t2 = base_sensor();
  t1.scale_factor.value_pct = Eigen::Vector3d(0.0, 3.0, 0.0);
  t2.g_sensitivity.matrix_dps_per_g(1, 2) = 0.1;
  const SensorParams model = base_sensor();
  const auto lg = testlog::make_log(t1, t2, kDuration, 21);
  const Replay rp = replay_samples(lg.samples, lg.meta, lg.fields, ReplayOptions{}, "test.csv");
  CompareModel m = default_compare_model();
  m.sensor = {model, model};
  // WHEN diagnosed once
  const CompareResult r1 = compare(rp, m, CompareOptions{});
  // THEN both effects are selected with their values, and nothing else
  ASSERT_EQ(r1.verdict, Verdict::kMissingEffect) << r1.statement;
  std::set<std::string> found;
  for (const auto& c : r1.selected) found.insert(effect_id(c.effect));
  EXPECT_EQ(found, (std::set<std::string>{"scale_factor", "g_sensitivity"})) << r1.statement;
  for (const auto& c : r1.selected) {
    if (c.effect == Effect::kScaleFactor) {
      EXPECT_NEAR(check::param(c, "s1.y.value_pct"), 3.0, 0.6);
    }
    if (c.effect == Effect::kGSensitivity) {
      EXPECT_NEAR(check::param(c, "s2.matrix_dps_per_g[y][z]"), 0.1, 0.02);
    }
  }
  // AND after --apply of the whole set the comparison is consistent
  apply_result(m, r1);
  const CompareResult r2 = compare(rp, m, CompareOptions{});
  EXPECT_EQ(r2.verdict, Verdict::kConsistent) << r2.statement;
}

}  // namespace
}  // namespace driftless::diagnose
