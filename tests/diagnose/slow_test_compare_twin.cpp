// Every effect the twin can plant, one at a time, on MuJoCo twin logs (pan/tilt, or vehicle),
// with noise, at MPU6050 datasheet magnitudes: GIVEN a model lacking the effect, WHEN diagnosed,
// THEN it ranks first with its parameter within 20 %, and after --apply the systematic residual
// falls >= 5x or to within 10 % of the noise floor. Plus: clean twin logs are consistent with
// the noise model in >= 95 % of seeds, and two hidden effects are found over two rounds.
#include <gtest/gtest.h>

#include "tests/diagnose/diagnosis_checks.hpp"

#include <cmath>
#include <cstdio>
#include <functional>
#include <set>

#include "diagnose/apply.hpp"
#include "tests/diagnose/compare_twin_log.hpp"

namespace driftless::diagnose {

using namespace driftless::twin;  // the sensor model, scenario and simulator
namespace {


struct Case {
  std::string scenario = "pan_tilt";
  double duration_s = 150.0;
  std::uint64_t seed = 1;
  std::function<void(Scenario&)> model_setup;  // applied to both log and model
  std::function<void(Scenario&)> plant;        // applied to the log only
  Effect effect = Effect::kScaleFactor;
  std::string param;
  double truth = 0.0;
  bool absolute = false;  // truth is the new value (else: the change to the model's value)
  bool check_error_falls = true;
};

struct Outcome {
  CompareResult before, after;
};

Outcome run(const Case& c) {
  Scenario sc = twinlog::scenario(c.scenario, c.duration_s, c.seed);
  if (c.model_setup) c.model_setup(sc);
  const CompareModel m = twinlog::model_of(sc);
  c.plant(sc);
  const auto log = twinlog::simulate(sc, effect_id(c.effect));
  const Replay rp = twinlog::replay(log, m);
  Outcome o;
  o.before = compare(rp, m, CompareOptions{});
  if (o.before.verdict == Verdict::kMissingEffect || !o.before.noise_model.empty()) {
    CompareModel upd = m;
    apply_result(upd, o.before);
    const auto yaml = test::temp_path(std::string("driftless_twin_") + effect_id(c.effect) + ".yaml");
    save_compare_model(upd, yaml);
    o.after = compare(rp, load_compare_model(yaml), CompareOptions{});
    std::filesystem::remove(yaml);
  }
  std::filesystem::remove(log);
  return o;
}

void check(const Case& c) {
  const Outcome o = run(c);
  const CompareResult& r = o.before;
  ASSERT_TRUE(r.verdict == Verdict::kMissingEffect || !r.noise_model.empty()) << effect_id(c.effect) << ": " << r.statement;
  const Candidate& best = check::top(r);
  ASSERT_EQ(best.effect, c.effect) << r.statement;
  if (!c.param.empty()) {
    const auto* p = find_param(best, c.param);
    ASSERT_NE(p, nullptr) << r.statement;
    EXPECT_NEAR(c.absolute ? p->new_value() : p->value, c.truth, 0.2 * std::abs(c.truth)) << c.param << ": " << r.statement;
  }
  if (!c.check_error_falls) return;
  ASSERT_FALSE(o.after.statement.empty()) << "not applied: " << effect_id(best.effect);
  for (int ch = 0; ch < 6; ++ch) {
    const auto& b = r.channels[ch];
    const auto& a = o.after.channels[ch];
    if (b.systematic_rms_dps <= 1.1 * b.noise_floor_dps * 0.5) continue;  // channel not affected
    EXPECT_TRUE(a.systematic_rms_dps * 5.0 <= b.systematic_rms_dps || a.rms_dps <= 1.1 * a.noise_floor_dps)
        << effect_id(c.effect) << " " << channel_name(ch) << ": systematic " << b.systematic_rms_dps << " -> "
        << a.systematic_rms_dps << " deg/s, rms " << a.rms_dps << " floor " << a.noise_floor_dps;
  }
  std::printf("%s: %s\n  after: %s\n", effect_id(c.effect), r.statement.c_str(), o.after.statement.c_str());
}

TEST(CompareTwinEffects, ScaleFactor) {
  Case c;  // datasheet: sensitivity tolerance +-3 %
  c.seed = 11;
  c.plant = [](Scenario& s) { s.model.sensor2.scale_factor.value_pct = Eigen::Vector3d(0.0, -3.0, 0.0); };
  c.effect = Effect::kScaleFactor;
  c.param = "s2.y.value_pct";
  c.truth = -3.0;
  check(c);
}

TEST(CompareTwinEffects, Misalignment) {
  Case c;  // datasheet: cross-axis sensitivity +-2 %
  c.seed = 12;
  c.plant = [](Scenario& s) { s.model.sensor1.misalignment.matrix_pct(0, 1) = 2.0; };
  c.effect = Effect::kMisalignment;
  c.param = "s1.matrix_pct[x][y]";
  c.truth = 2.0;
  check(c);
}

TEST(CompareTwinEffects, GSensitivity) {
  Case c;  // datasheet: linear acceleration sensitivity 0.1 deg/s/g
  c.seed = 13;
  c.plant = [](Scenario& s) { s.model.sensor1.g_sensitivity.matrix_dps_per_g(2, 2) = 0.1; };
  c.effect = Effect::kGSensitivity;
  c.param = "s1.matrix_dps_per_g[z][z]";
  c.truth = 0.1;
  check(c);
}

TEST(CompareTwinEffects, GSensitivityOnVehicle) {
  Case c;
  c.scenario = "vehicle";
  c.duration_s = 200.0;
  c.seed = 14;
  c.plant = [](Scenario& s) { s.model.sensor2.g_sensitivity.matrix_dps_per_g(0, 1) = 0.1; };
  c.effect = Effect::kGSensitivity;
  c.param = "s2.matrix_dps_per_g[x][y]";
  c.truth = 0.1;
  // the vehicle's 27-32 Hz vibration is rebuilt from 100 Hz ref_q only approximately: after
  // --apply a replay residual near Nyquist remains (a known limit, docs/compare.md), so only
  // the ranking and the fitted value are checked here
  c.check_error_falls = false;
  check(c);
}

TEST(CompareTwinEffects, TemperatureBiasCoefficient) {
  Case c;  // 0.1 deg/s/degC with 5 degC self-heating (tau 60 s)
  c.seed = 15;
  c.model_setup = [](Scenario& s) {
    for (auto* p : {&s.model.sensor1, &s.model.sensor2}) {
      p->temperature.warmup_rise_degc = 5.0;
      p->temperature.warmup_tau_s = 60.0;
    }
  };
  c.plant = [](Scenario& s) { s.model.sensor1.temperature.bias_tc_dps_per_degc = Eigen::Vector3d(0.1, 0, 0); };
  c.effect = Effect::kTemperature;
  c.param = "s1.x.bias_tc_dps_per_degc";
  c.truth = 0.1;
  check(c);
}

TEST(CompareTwinEffects, TemperatureScaleCoefficient) {
  Case c;  // 0.3 %/degC with 8 degC self-heating
  c.seed = 16;
  c.model_setup = [](Scenario& s) {
    for (auto* p : {&s.model.sensor1, &s.model.sensor2}) {
      p->temperature.warmup_rise_degc = 8.0;
      p->temperature.warmup_tau_s = 60.0;
    }
  };
  c.plant = [](Scenario& s) { s.model.sensor2.temperature.scale_tc_pct_per_degc = Eigen::Vector3d(0, 0, 0.3); };
  c.effect = Effect::kTemperature;
  c.param = "s2.z.scale_tc_pct_per_degc";
  c.truth = 0.3;
  check(c);
}

TEST(CompareTwinEffects, MountingMisalignment) {
  Case c;  // 0.8 deg about x (not the hinge axis z of platform 1)
  c.seed = 17;
  c.plant = [](Scenario& s) {
    s.model.sensor1.mounting_misalignment.enabled = true;
    s.model.sensor1.mounting_misalignment.angles_deg = Eigen::Vector3d(0.8, 0, 0);
  };
  c.model_setup = [](Scenario& s) { s.model.sensor1.mounting_misalignment.enabled = false; };
  c.effect = Effect::kMountingMisalignment;
  c.param = "s1.angles_deg[x]";
  c.truth = 0.8;
  check(c);
}

TEST(CompareTwinEffects, EndStopError) {
  Case c;  // platform 1's - stop 0.4 deg further than the model's box says
  c.seed = 18;
  c.plant = [](Scenario& s) { s.model.box.stop1_error_deg[0] += 0.4; };
  c.effect = Effect::kEndStopError;
  c.param = "s1.minus_stop_deg";
  c.truth = 0.4;
  check(c);
}

TEST(CompareTwinEffects, TimeOffset) {
  Case c;  // the sensors sample 15 ms before the log's time stamps
  c.seed = 19;
  c.plant = [](Scenario& s) { s.model.time_offset_s = 0.015; };
  c.effect = Effect::kTimeOffset;
  c.param = "offset_s";
  c.truth = 0.015;
  check(c);
}

TEST(CompareTwinEffects, LowpassLatency) {
  Case c;  // the chips run DLPF_CFG 5 (13.4 ms), the model says 3 (4.8 ms)
  c.seed = 20;
  c.plant = [](Scenario& s) {
    s.model.sensor1.lowpass_latency.dlpf_cfg = 5;
    s.model.sensor2.lowpass_latency.dlpf_cfg = 5;
  };
  c.effect = Effect::kLowpass;
  c.param = "delay_s";  // both sensors run the same filter: one shared delay
  c.truth = mpu6050::dlpf_setting(5).gyro_delay_s - mpu6050::dlpf_setting(3).gyro_delay_s;
  check(c);
}

TEST(CompareTwinEffects, ConstantBias) {
  Case c;  // a 3 deg/s turn-on bias where the model claims none (sigma 0)
  c.seed = 21;
  c.plant = [](Scenario& s) { s.model.sensor2.constant_bias.value_dps = Eigen::Vector3d(0, 0, 3.0); };
  c.model_setup = [](Scenario& s) { s.model.sensor2.constant_bias.value_dps.setZero(); };
  c.effect = Effect::kConstantBias;
  c.param = "s2.z.value_dps";
  c.truth = 3.0;
  c.check_error_falls = false;  // a constant is a nuisance either way: rms unchanged by design
  check(c);
}

TEST(CompareTwinEffects, WhiteNoiseLevel) {
  Case c;  // twice the datasheet noise density
  c.seed = 22;
  c.plant = [](Scenario& s) { s.model.sensor1.white_noise.density_dps_rthz = Eigen::Vector3d::Constant(0.01); };
  c.effect = Effect::kWhiteNoise;
  c.absolute = true;
  c.param = "s1.x.density_dps_rthz";
  c.truth = 0.01;
  c.check_error_falls = false;  // noise is not a systematic residual
  check(c);
}

TEST(CompareTwinEffects, Quantization) {
  Case c;  // the chips run at +-500 deg/s (65.5 LSB per deg/s), the model at +-250 (131)
  c.seed = 23;
  c.plant = [](Scenario& s) {
    s.model.sensor1.quantization.sensitivity_lsb_per_dps = 65.5;
    s.model.sensor2.quantization.sensitivity_lsb_per_dps = 65.5;
  };
  c.effect = Effect::kQuantization;
  c.absolute = true;
  c.param = "s1.x.sensitivity_lsb_per_dps";
  c.truth = 65.5;
  c.check_error_falls = false;
  check(c);
}

TEST(CompareTwinEffects, Saturation) {
  Case c;  // a +-30 deg/s range clips the pan/tilt's 50 deg/s moves
  c.seed = 24;
  c.plant = [](Scenario& s) { s.model.sensor1.saturation.full_scale_dps = 30.0; };
  c.effect = Effect::kSaturation;
  c.absolute = true;
  c.param = "s1.x.full_scale_dps";
  c.truth = 30.0;
  c.check_error_falls = false;
  const Outcome o = run(c);
  ASSERT_EQ(o.before.verdict, Verdict::kMissingEffect) << o.before.statement;
  EXPECT_EQ(check::top(o.before).effect, Effect::kSaturation) << o.before.statement;
  ASSERT_FALSE(check::top(o.before).params.empty());
  EXPECT_NEAR(check::top(o.before).params.front().new_value(), 30.0, 6.0);
}

TEST(CompareTwinEffects, CleanLogsFalseAlarmRate) {
  // GIVEN 20 seeds of twin logs matching the model, THEN >= 95 % are consistent
  int ok = 0;
  const int seeds = 20;
  for (int seed = 200; seed < 200 + seeds; ++seed) {
    const Scenario sc = twinlog::scenario("pan_tilt", 90.0, static_cast<std::uint64_t>(seed));
    const auto log = twinlog::simulate(sc, "clean");
    const CompareModel m = twinlog::model_of(sc);
    const CompareResult r = compare(twinlog::replay(log, m), m, CompareOptions{});
    std::filesystem::remove(log);
    if (r.verdict == Verdict::kConsistent) ++ok;
    else std::printf("seed %d: %s\n", seed, r.statement.c_str());
  }
  std::printf("clean twin logs: %d / %d consistent with the noise model\n", ok, seeds);
  EXPECT_GE(ok, 19);
}

TEST(CompareTwinEffects, TwoHiddenEffectsInOneRun) {
  // GIVEN a scale error on sensor 1 and a g-sensitivity on sensor 2, the model lacking both
  Scenario sc = twinlog::scenario("pan_tilt", 150.0, 31);
  CompareModel m = twinlog::model_of(sc);
  sc.model.sensor1.scale_factor.value_pct = Eigen::Vector3d(0.0, 3.0, 0.0);
  sc.model.sensor2.g_sensitivity.matrix_dps_per_g(1, 2) = 0.1;
  const auto log = twinlog::simulate(sc, "two");
  const Replay rp = twinlog::replay(log, m);
  // WHEN diagnosed once and the whole selected set applied
  const CompareResult r1 = compare(rp, m, CompareOptions{});
  ASSERT_EQ(r1.verdict, Verdict::kMissingEffect) << r1.statement;
  apply_result(m, r1);
  const CompareResult r2 = compare(rp, m, CompareOptions{});
  std::filesystem::remove(log);
  // THEN the one run found both effects, and the comparison after --apply finds nothing
  std::set<std::string> found;
  for (const auto& c : r1.selected) found.insert(effect_id(c.effect));
  EXPECT_TRUE(found.count("scale_factor")) << r1.statement;
  EXPECT_TRUE(found.count("g_sensitivity")) << r1.statement;
  EXPECT_EQ(r2.verdict, Verdict::kConsistent) << r2.statement;
}

}  // namespace
}  // namespace driftless::diagnose
