// Compare/diagnose on logs from the MuJoCo twin itself (pan/tilt scenario, noise on, servo
// flips onto end stops with stop errors the model knows): GIVEN one hidden effect at a datasheet
// magnitude and a model lacking it, WHEN diagnosed, THEN it ranks first within 20 %, and after
// --apply (written to YAML and read back) the systematic residual falls. The full catalogue is
// in slow_test_compare_twin.cpp.
#include <gtest/gtest.h>

#include "tests/diagnose/diagnosis_checks.hpp"

#include <cmath>
#include <cstdio>

#include "diagnose/apply.hpp"
#include "tests/diagnose/compare_twin_log.hpp"

#include "tests/temp_path.hpp"

namespace driftless::diagnose {

using namespace driftless::twin;  // the sensor model, scenario and simulator
namespace {


constexpr double kDuration = 90.0;

void expect_error_falls(const CompareResult& before, const CompareResult& after, int c) {
  const auto& b = before.channels[c];
  const auto& a = after.channels[c];
  EXPECT_TRUE(a.systematic_rms_dps * 5.0 <= b.systematic_rms_dps || a.rms_dps <= 1.1 * a.noise_floor_dps)
      << channel_name(c) << ": systematic " << b.systematic_rms_dps << " -> " << a.systematic_rms_dps
      << " deg/s, rms " << a.rms_dps << " vs floor " << a.noise_floor_dps;
}

TEST(CompareTwin, CleanPanTiltLogIsConsistentWithNoise) {
  // GIVEN a twin log whose sensors and box match the model (noise only)
  const Scenario sc = twinlog::scenario("pan_tilt", kDuration, 3);
  const auto log = twinlog::simulate(sc, "clean");
  const CompareModel m = twinlog::model_of(sc);
  // WHEN compared
  const CompareResult r = compare(twinlog::replay(log, m), m, CompareOptions{});
  // THEN nothing is missing
  EXPECT_EQ(r.verdict, Verdict::kConsistent) << r.statement;
  std::filesystem::remove(log);
}

TEST(CompareTwin, ScaleFactorFoundAppliedThroughYaml) {
  // GIVEN sensor 1 with a +3 % scale error on x (datasheet tolerance), the model without it
  Scenario sc = twinlog::scenario("pan_tilt", kDuration, 4);
  const CompareModel m = twinlog::model_of(sc);
  sc.model.sensor1.scale_factor.value_pct = Eigen::Vector3d(3.0, 0.0, 0.0);
  const auto log = twinlog::simulate(sc, "scale");
  const Replay rp = twinlog::replay(log, m);
  // WHEN diagnosed
  const CompareResult r = compare(rp, m, CompareOptions{});
  // THEN scale_factor on sensor 1 ranks first, within 20 %
  ASSERT_EQ(r.verdict, Verdict::kMissingEffect) << r.statement;
  const Candidate& best = check::top(r);
  EXPECT_EQ(std::string(effect_id(best.effect)), "scale_factor") << r.statement;
  const auto* p = find_param(best, "s1.x.value_pct");
  ASSERT_NE(p, nullptr) << r.statement;
  EXPECT_NEAR(p->new_value(), 3.0, 0.6);
  // AND --apply writes a model that compare reads back, with the systematic residual gone
  CompareModel upd = m;
  apply_candidate(upd, best);
  const auto yaml = test::temp_path("driftless_twin_scale_applied.yaml");
  save_compare_model(upd, yaml);
  const CompareModel back = load_compare_model(yaml);
  EXPECT_NEAR(back.sensor[0].scale_factor.value_pct[0], upd.sensor[0].scale_factor.value_pct[0], 1e-6);
  const CompareResult again = compare(rp, back, CompareOptions{});
  expect_error_falls(r, again, 0);
  EXPECT_EQ(again.verdict, Verdict::kConsistent) << again.statement;
  std::filesystem::remove(log);
  std::filesystem::remove(yaml);
}

TEST(CompareTwin, EndStopErrorFoundAndWrittenToTheBox) {
  // GIVEN platform 2's + stop 0.5 deg off from what the model's box says
  Scenario sc = twinlog::scenario("pan_tilt", kDuration, 5);
  const CompareModel m = twinlog::model_of(sc);
  sc.model.box.stop2_error_deg[1] += 0.5;
  const auto log = twinlog::simulate(sc, "stop");
  const Replay rp = twinlog::replay(log, m);
  const CompareResult r = compare(rp, m, CompareOptions{});
  // THEN end_stop_error ranks first with the + stop error of sensor 2 within 20 %
  ASSERT_EQ(r.verdict, Verdict::kMissingEffect) << r.statement;
  const Candidate& best = check::top(r);
  ASSERT_EQ(std::string(effect_id(best.effect)), "end_stop_error") << r.statement;
  const auto* p = find_param(best, "s2.plus_stop_deg");
  ASSERT_NE(p, nullptr) << r.statement;
  EXPECT_NEAR(p->value, 0.5, 0.1);  // the change to the model's stop error
  // AND --apply writes it into model.box (a scenario simulate reads back) and the error falls
  CompareModel upd = m;
  apply_candidate(upd, best);
  const auto yaml = test::temp_path("driftless_twin_stop_applied.yaml");
  save_compare_model(upd, yaml);
  const Scenario back_sc = load_scenario(yaml.string());
  EXPECT_NEAR(back_sc.model.box.stop2_error_deg[1], sc.model.box.stop2_error_deg[1], 0.1);
  const CompareResult again = compare(rp, load_compare_model(yaml), CompareOptions{});
  for (int c = 3; c < 6; ++c) expect_error_falls(r, again, c);
  EXPECT_EQ(again.verdict, Verdict::kConsistent) << again.statement;
  std::filesystem::remove(log);
  std::filesystem::remove(yaml);
}

// the embedded default model (no --model) for the sensors; the box, rate and latitude are the
// scenario's so that only the sensor model is under test
CompareModel embedded_model_for(const Scenario& sc) {
  CompareModel m = default_compare_model();
  m.box = sc.model.box;
  m.sample_rate_hz = sc.sample_rate_hz;
  m.latitude_deg = sc.latitude_deg;
  return m;
}

TEST(CompareTwin, TheEmbeddedNominalModelFindsADatasheetGSensitivity) {
  // GIVEN a twin log with sensor 1's z axis at the datasheet's 0.1 deg/s/g g-sensitivity, and
  // the embedded nominal MPU6050 model (which has no g-sensitivity spread to absorb it)
  Scenario sc = twinlog::scenario("pan_tilt", kDuration, 6);
  sc.model.sensor1.g_sensitivity.matrix_dps_per_g(2, 2) = 0.1;
  const auto log = twinlog::simulate(sc, "nominal_gsens");
  const CompareModel m = embedded_model_for(sc);
  const CompareResult r = compare(twinlog::replay(log, m), m, CompareOptions{});
  // THEN g_sensitivity on sensor 1 ranks first within 20 %
  ASSERT_EQ(r.verdict, Verdict::kMissingEffect) << r.statement;
  const Candidate& best = check::top(r);
  EXPECT_EQ(std::string(effect_id(best.effect)), "g_sensitivity") << r.statement;
  const auto* p = find_param(best, "s1.matrix_dps_per_g[z][z]");
  ASSERT_NE(p, nullptr) << r.statement;
  EXPECT_NEAR(p->new_value(), 0.1, 0.02);
  std::filesystem::remove(log);
}

TEST(CompareTwin, AnIdealSensorIsConsistentWithTheEmbeddedNominalModel) {
  // GIVEN a twin log from sensors with noise, bias drift and a turn-on bias but no scale,
  // cross-axis or g-sensitivity error: what another simulator's plain gyro produces
  const Scenario sc = twinlog::scenario("pan_tilt", kDuration, 7);
  const auto log = twinlog::simulate(sc, "nominal_clean");
  const CompareModel m = embedded_model_for(sc);
  const CompareResult r = compare(twinlog::replay(log, m), m, CompareOptions{});
  EXPECT_EQ(r.verdict, Verdict::kConsistent) << r.statement;
  std::filesystem::remove(log);
}

}  // namespace
}  // namespace driftless::diagnose
