// Sensor parameter block: presets, validate(), YAML parse with units, emit, round trip.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "estimator/sample.hpp"
#include "twin/sensor/sensor_model.hpp"
#include "twin/yaml_doc.hpp"

using namespace driftless;
using namespace driftless::twin;

namespace {

SensorParams parse_block(const std::string& text, const SensorParams& base, const std::string& file) {
  return read_sensor_params(parse_yaml(text, file), base, fields::Context{file, ""});
}

SensorParams parse(const std::string& text, const SensorParams& base = mpu6050_defaults()) {
  return parse_block(text, base, "sensors.yaml");
}

std::string error_of(const std::string& text) {
  try {
    parse(text);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

std::string emit(const SensorParams& p) { return to_yaml(write_sensor_params(p)); }

}  // namespace

TEST(SensorParams, DefaultsAreValidAndMatchTheDatasheet) {
  const SensorParams p = mpu6050_defaults();
  EXPECT_NO_THROW(p.validate());
  EXPECT_EQ(p.white_noise.density_dps_rthz, Eigen::Vector3d::Constant(0.005));
  EXPECT_EQ(p.quantization.sensitivity_lsb_per_dps, 131.0);
  EXPECT_EQ(p.saturation.full_scale_dps, 250.0);
  EXPECT_EQ(p.lowpass_latency.dlpf_cfg, 3);
  EXPECT_NO_THROW(ideal_sensor().validate());
  for (const auto& id : effect_ids()) EXPECT_FALSE(effect_enabled(ideal_sensor(), id)) << id;
}

TEST(SensorParams, EffectIdsAreTheContract) {
  const std::vector<std::string> want = {
      "constant_bias", "bias_instability", "rate_random_walk", "white_noise", "scale_factor",
      "misalignment", "g_sensitivity", "temperature", "quantization", "saturation",
      "adc_missing_codes", "adc_nonlinearity", "lowpass_latency", "sample_jitter",
      "mounting_misalignment", "accel_bias", "accel_white_noise", "accel_scale_factor",
      "accel_quantization", "sample_delay"};
  EXPECT_EQ(effect_ids(), want);
  SensorParams p = ideal_sensor();
  set_effect_enabled(p, "white_noise", true);
  EXPECT_TRUE(p.white_noise.enabled);
  EXPECT_THROW(set_effect_enabled(p, "whitenoise", true), std::invalid_argument);
}

TEST(SensorParams, EmitThenParseGivesBackTheSameParams) {
  SensorParams p = mpu6050_defaults();
  p.misalignment.matrix_pct << 0, 0.1, -0.2, 0.3, 0, 1.0 / 3.0, -0.5, 0.6, 0;
  p.g_sensitivity.matrix_dps_per_g(2, 1) = 0.07;
  p.constant_bias.value_dps = {1.25, -0.1, 0.3333333333333333};
  p.adc_missing_codes.enabled = true;
  p.adc_missing_codes.codes = {-5, 7, 1024};
  p.sample_jitter.enabled = true;
  p.temperature.profile_file = "/tmp/profile.csv";
  p.bias_instability.stationary_start = false;
  p.lowpass_latency.delay_s = 0.0123;
  p.lowpass_latency.bandwidth_hz = 17.5;
  p.sample_delay.enabled = true;
  p.sample_delay.delay_s = 0.015;
  const std::string text = emit(p);
  const SensorParams q = parse_block(text, ideal_sensor(), "");
  EXPECT_TRUE(q == p) << text;
  // the emitted block holds every effect and its enabled flag explicitly
  const YAML::Node n = YAML::Load(text);
  for (const auto& id : effect_ids()) EXPECT_TRUE(n["effects"][id]["enabled"]) << id;
  // and ideal round-trips as well
  EXPECT_TRUE(parse_block(emit(ideal_sensor()), mpu6050_defaults(), "") ==
              ideal_sensor());
}

TEST(SensorParams, ParseOverridesOnlyTheGivenKeys) {
  const SensorParams p = parse(R"(
preset: mpu6050
effects:
  white_noise: {enabled: true, density_dps_rthz: [0.004, 0.005, 0.006]}
  bias_instability: {sigma_dph: 360, tau_h: 2}
  constant_bias: false
)");
  SensorParams want = mpu6050_defaults();
  want.white_noise.density_dps_rthz = {0.004, 0.005, 0.006};
  want.bias_instability.sigma_dps = Eigen::Vector3d::Constant(0.1);
  want.bias_instability.tau_s = Eigen::Vector3d::Constant(7200.0);
  want.constant_bias.enabled = false;
  EXPECT_NEAR((p.bias_instability.sigma_dps - want.bias_instability.sigma_dps).norm(), 0.0, 1e-15);
  want.bias_instability.sigma_dps = p.bias_instability.sigma_dps;
  EXPECT_TRUE(p == want);
}

TEST(SensorParams, SignalChainKeysTakeTheirUnits) {
  // GIVEN a continuous DLPF delay in ms, a bandwidth in Hz and a sample delay in ms
  const SensorParams p = parse(R"(
preset: mpu6050
effects:
  lowpass_latency: {delay_ms: 8.3, bandwidth_hz: 20}
  sample_delay: {enabled: true, delay_ms: 15}
)");
  // THEN they are stored in s and Hz, and the model runs exactly that filter and delay
  EXPECT_NEAR(p.lowpass_latency.delay_s, 0.0083, 1e-15);
  EXPECT_EQ(p.lowpass_latency.bandwidth_hz, 20.0);
  EXPECT_TRUE(p.sample_delay.enabled);
  EXPECT_NEAR(p.sample_delay.delay_s, 0.015, 1e-15);
  const DlpfSetting d = lowpass_setting(p.lowpass_latency);
  EXPECT_EQ(d.gyro_bandwidth_hz, 20.0);
  EXPECT_NEAR(d.gyro_delay_s, 0.0083, 1e-15);
}

TEST(SensorParams, PresetIdealThenEnableOneEffect) {
  const SensorParams p = parse("{preset: ideal, effects: {white_noise: {enabled: true}}}");
  for (const auto& id : effect_ids()) EXPECT_EQ(effect_enabled(p, id), id == "white_noise") << id;
  EXPECT_EQ(p.white_noise.density_dps_rthz, Eigen::Vector3d::Constant(0.005));
}

TEST(SensorParams, AlternativeUnitsConvert) {
  const SensorParams p = parse(R"(
effects:
  white_noise: {density_deg_rth: 0.3}
  rate_random_walk: {k_dph_rth: 216}
  mounting_misalignment: {angles_arcmin: [60, 0, -30]}
  scale_factor: {value_ppm: [1000, 0, 0]}
  accel_white_noise: {density_ug_rthz: 400}
)");
  EXPECT_NEAR(p.white_noise.density_dps_rthz[0], 0.3 / 60.0, 1e-15);
  EXPECT_NEAR(p.rate_random_walk.k_dps_rts[2], 0.001, 1e-15);
  EXPECT_NEAR(p.mounting_misalignment.angles_deg[0], 1.0, 1e-13);
  EXPECT_NEAR(p.mounting_misalignment.angles_deg[2], -0.5, 1e-13);
  EXPECT_NEAR(p.scale_factor.value_pct[0], 0.1, 1e-15);
  EXPECT_NEAR(p.accel_white_noise.density_mps2_rthz[1], 400e-6 * kStandardGravityMps2, 1e-15);
}

TEST(SensorParams, ErrorsNameFileLineAndKey) {
  // unknown effect id: lists the valid ids
  std::string e = error_of("effects:\n  white_nosie: {enabled: true}\n");
  EXPECT_NE(e.find("sensors.yaml:2:"), std::string::npos) << e;
  EXPECT_NE(e.find("white_nosie"), std::string::npos) << e;
  EXPECT_NE(e.find("valid ids: constant_bias, bias_instability"), std::string::npos) << e;
  // inconsistent unit: an angle where a rate is expected
  e = error_of("effects:\n  bias_instability:\n    sigma_rad: 0.1\n");
  EXPECT_NE(e.find("sensors.yaml:3:"), std::string::npos) << e;
  EXPECT_NE(e.find("effects.bias_instability.sigma_rad"), std::string::npos) << e;
  EXPECT_NE(e.find("inconsistent units: 'sigma_rad' is in rad"), std::string::npos) << e;
  EXPECT_NE(e.find("sigma_dps"), std::string::npos) << e;
  // a rate where a density is expected
  e = error_of("effects: {white_noise: {density_dps: 0.1}}");
  EXPECT_NE(e.find("inconsistent units: 'density_dps' is in deg/s"), std::string::npos) << e;
  // unknown key: lists the valid keys
  e = error_of("effects: {white_noise: {sigma: 0.1}}");
  EXPECT_NE(e.find("unknown key (allowed here: enabled, density_dps_rthz)"), std::string::npos) << e;
  // bad value types
  EXPECT_NE(error_of("effects: {white_noise: {enabled: maybe}}").find("expected true or false"),
            std::string::npos);
  EXPECT_NE(error_of("effects: {white_noise: {density_dps_rthz: [1, 2]}}").find("[x, y, z]"),
            std::string::npos);
  EXPECT_NE(error_of("effects: {misalignment: {matrix_pct: [1, 2, 3]}}").find("3x3"),
            std::string::npos);
  EXPECT_NE(error_of("effects: {white_noise: {density_dps_rthz: abc}}").find("expected a number"),
            std::string::npos);
  EXPECT_NE(error_of("preset: mpu9250").find("valid presets: mpu6050, ideal"), std::string::npos);
  EXPECT_NE(error_of("bogus: 1").find("valid keys: preset, effects"), std::string::npos);
  // a value validate() rejects names the key
  e = error_of("effects: {bias_instability: {tau_s: -1}}");
  EXPECT_NE(e.find("sensors.yaml:1:"), std::string::npos) << e;
  EXPECT_NE(e.find("bias_instability.tau_s must be > 0"), std::string::npos) << e;
  e = error_of("effects:\n  white_noise: {}\n  bias_instability:\n    tau_s: -1\n");
  EXPECT_NE(e.find("sensors.yaml:3:"), std::string::npos) << e;
}

TEST(SensorParams, ValidateRejectsBadValues) {
  auto rejects = [](auto mutate, const std::string& needle) {
    SensorParams p = mpu6050_defaults();
    mutate(p);
    try {
      p.validate();
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
      return;
    }
    ADD_FAILURE() << "validate() accepted a bad value for " << needle;
  };
  rejects([](SensorParams& p) { p.white_noise.density_dps_rthz[1] = -0.1; }, "white_noise.density_dps_rthz");
  rejects([](SensorParams& p) { p.bias_instability.tau_s[2] = 0.0; }, "bias_instability.tau_s");
  rejects([](SensorParams& p) { p.constant_bias.value_dps[0] = NAN; }, "constant_bias.value_dps");
  rejects([](SensorParams& p) { p.misalignment.matrix_pct(1, 1) = 1.0; }, "non-zero diagonal");
  rejects([](SensorParams& p) { p.quantization.sensitivity_lsb_per_dps = 0.0; }, "sensitivity_lsb_per_dps");
  rejects([](SensorParams& p) { p.saturation.full_scale_dps = 500.0; }, "16-bit range");
  rejects([](SensorParams& p) { p.lowpass_latency.dlpf_cfg = 7; }, "dlpf_cfg");
  rejects([](SensorParams& p) { p.adc_missing_codes.fraction = 0.9; }, "adc_missing_codes.fraction");
  rejects([](SensorParams& p) { p.adc_missing_codes.codes = {40000}; }, "adc_missing_codes.codes");
  rejects([](SensorParams& p) {
        p.adc_missing_codes.enabled = true;
        p.quantization.enabled = false;
      }, "needs quantization");
  rejects([](SensorParams& p) { p.scale_factor.value_pct[0] = -150.0; }, "scale_factor.value_pct");
  rejects([](SensorParams& p) { p.temperature.warmup_tau_s = 0.0; }, "temperature.warmup_tau_s");
  rejects([](SensorParams& p) { p.sample_jitter.sigma_s = -1e-3; }, "sample_jitter.sigma_s");
  rejects([](SensorParams& p) { p.sample_delay.delay_s = -0.001; }, "sample_delay.delay_s");
  rejects([](SensorParams& p) { p.lowpass_latency.delay_s = 2.0; }, "lowpass_latency.delay_s");
  rejects([](SensorParams& p) { p.lowpass_latency.bandwidth_hz = -1.0; }, "lowpass_latency.bandwidth_hz");
  rejects([](SensorParams& p) { p.mounting_misalignment.angles_deg[0] = 90.0; }, "angles_deg");
  rejects([](SensorParams& p) { p.accel_quantization.full_scale_g = 16.0; }, "accel_quantization.full_scale_g");
  EXPECT_THROW(SensorModel(mpu6050_defaults(), 0.0, 1), std::invalid_argument);
}
