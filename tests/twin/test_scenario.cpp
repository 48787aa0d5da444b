// Scenario YAML: built-ins load, the resolved form round-trips, bad input names file, line, key.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "estimator/input_error.hpp"
#include "twin/scenario.hpp"

#include "tests/temp_path.hpp"

namespace driftless::twin {
namespace {

std::string error_of(const std::string& yaml) {
  try {
    parse_scenario(yaml, "test.yaml");
  } catch (const driftless::InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(Scenario, BuiltinsLoadAndValidate) {
  const auto names = builtin_scenarios();
  for (const char* n : {"default", "static", "pan_tilt", "vehicle", "ship"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
    const Scenario s = load_scenario(n);
    EXPECT_EQ(s.name, n);
    EXPECT_NO_THROW(s.validate());
  }
  EXPECT_EQ(load_scenario("static").duration_s, 14 * 3600.0);
  EXPECT_EQ(load_scenario("pan_tilt").motion.type, MotionType::pan_tilt);
  EXPECT_EQ(load_scenario("vehicle").motion.type, MotionType::ground_vehicle);
}

TEST(Scenario, ShippedFilesMatchTheBuiltins) {
  for (const char* n : {"default", "static", "pan_tilt", "vehicle", "ship"}) {
    const auto path = std::filesystem::path(DRIFTLESS_SOURCE_DIR) / "models" / "scenarios" / (std::string(n) + ".yaml");
    EXPECT_EQ(emit_scenario(load_scenario(path.string())), emit_scenario(load_scenario(n))) << n;
  }
}

TEST(Scenario, ResolvedFormRoundTrips) {
  for (const char* n : {"default", "pan_tilt", "vehicle", "ship"}) {
    const Scenario s = load_scenario(n);
    const std::string once = emit_scenario(s);
    const Scenario again = parse_scenario(once, "resolved.yaml");
    EXPECT_EQ(emit_scenario(again), once) << n;
  }
}

TEST(Scenario, MissingKeysKeepDefaults) {
  const Scenario s = parse_scenario("duration_s: 10\n", "t.yaml");
  EXPECT_EQ(s.duration_s, 10);
  EXPECT_EQ(s.latitude_deg, Scenario{}.latitude_deg);
  EXPECT_EQ(s.total_samples(), 1000u);
  EXPECT_EQ(s.steps_per_sample(), 10);
}

TEST(Scenario, UnknownKeyNamesFileLineAndKey) {
  const std::string e = error_of("duration_s: 10\nflip_schedule:\n  standstill_s: 5\n  flip_angel_deg: 90\n");
  EXPECT_NE(e.find("test.yaml:4"), std::string::npos) << e;
  EXPECT_NE(e.find("flip_schedule.flip_angel_deg"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown key"), std::string::npos) << e;
}

TEST(Scenario, InconsistentUnitsAreErrors) {
  std::string e = error_of("duration_s: 10\nflip_schedule:\n  standstill_deg: 5\n");
  EXPECT_NE(e.find("test.yaml:3"), std::string::npos) << e;
  EXPECT_NE(e.find("inconsistent units"), std::string::npos) << e;
  EXPECT_NE(e.find("standstill_s"), std::string::npos) << e;
  e = error_of("duration_s: 10 min\n");
  EXPECT_NE(e.find("test.yaml:1"), std::string::npos) << e;
  EXPECT_NE(e.find("inconsistent units"), std::string::npos) << e;
  e = error_of("duration: 10\n");
  EXPECT_NE(e.find("duration_s"), std::string::npos) << e;
  // the key's own unit written out is fine
  EXPECT_EQ(parse_scenario("duration_s: 10 s\nlatitude_deg: 45 deg\n", "t.yaml").duration_s, 10);
}

TEST(Scenario, KeysInAnotherUnitOfTheSameQuantityConvert) {
  // GIVEN keys in minutes, milliseconds, km/h and kHz (one unit table for every block)
  const Scenario s = parse_scenario(
      "duration_min: 2\nsample_rate_khz: 0.2\nphysics_dt_ms: 1\nflip_schedule:\n  standstill_ms: 5000\n"
      "motion:\n  type: ship\n  speed_kmh: 36\n",
      "t.yaml");
  // THEN they arrive in the fields' units, and the resolved form writes the canonical keys
  EXPECT_EQ(s.duration_s, 120.0);
  EXPECT_EQ(s.sample_rate_hz, 200.0);
  EXPECT_EQ(s.physics_dt_s, 0.001);
  EXPECT_EQ(s.flip_schedule.standstill_s, 5.0);
  EXPECT_NEAR(s.motion.ship.speed_mps, 10.0, 1e-12);
  const std::string out = emit_scenario(s);
  EXPECT_NE(out.find("duration_s: 120"), std::string::npos) << out;
  EXPECT_NE(out.find("standstill_s: 5"), std::string::npos) << out;
}

TEST(Scenario, DuplicateKeysAreRefusedNamingBothLines) {
  // yaml-cpp keeps the first of two equal keys silently; the loader refuses them
  std::string e = error_of("duration_s: 10\nseed: 3\nduration_s: 20\n");
  EXPECT_NE(e.find("test.yaml:3: duration_s: key given twice (lines 1 and 3)"), std::string::npos) << e;
  e = error_of("model:\n  box:\n    end_stop_deg: 90\n    end_stop_deg: 80\n");
  EXPECT_NE(e.find("test.yaml:4: model.box.end_stop_deg: key given twice (lines 3 and 4)"), std::string::npos) << e;
  e = error_of("model:\n  sensor1:\n    effects: {white_noise: {enabled: true, enabled: false}}\n");
  EXPECT_NE(e.find("model.sensor1.effects.white_noise.enabled: key given twice"), std::string::npos) << e;
}

TEST(Scenario, BrokenYamlNamesTheLine) {
  const std::string e = error_of("duration_s: 10\nmotion: {type: static\nseed: 3\n");
  EXPECT_NE(e.find("test.yaml:"), std::string::npos) << e;
  EXPECT_NE(e.find("broken YAML"), std::string::npos) << e;
}

TEST(Scenario, BadValuesNameTheKey) {
  std::string e = error_of("motion:\n  type: boat\n");
  EXPECT_NE(e.find("test.yaml:2"), std::string::npos) << e;
  EXPECT_NE(e.find("motion.type"), std::string::npos) << e;
  e = error_of("latitude_deg: 123\n");
  EXPECT_NE(e.find("latitude_deg"), std::string::npos) << e;
  e = error_of("model:\n  box:\n    hinge1_axis: [0, 1]\n");
  EXPECT_NE(e.find("test.yaml:3"), std::string::npos) << e;
  EXPECT_NE(e.find("model.box.hinge1_axis"), std::string::npos) << e;
  e = error_of("sample_rate_hz: 300\n");  // 3.33 physics steps per sample
  EXPECT_NE(e.find("whole number of physics steps"), std::string::npos) << e;
}

TEST(Scenario, MissingFileSaysSo) {
  try {
    load_scenario("/nonexistent/dir/scenario.yaml");
    FAIL();
  } catch (const driftless::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/scenario.yaml"), std::string::npos);
  }
}

TEST(Scenario, ModelFileHoldsOnlyTheModel) {
  const auto dir = test::temp_path("driftless_test_scenario");
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "model.yaml") << "model:\n  box:\n    end_stop_deg: 80\n";
  const ModelConfig m = load_model_config(dir / "model.yaml", ModelConfig{});
  EXPECT_EQ(m.box.end_stop_deg, 80);
  std::ofstream(dir / "bad_model.yaml") << "model:\n  box: {}\nmotion: {type: static}\n";
  EXPECT_THROW(load_model_config(dir / "bad_model.yaml", ModelConfig{}), driftless::InputError);
}

}  // namespace
}  // namespace driftless::twin
