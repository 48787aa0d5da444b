// Sensor parameters: presets, validation, and the sensor block (one table per effect drives
// parse with unit-suffixed keys, the allowed keys and emit; estimator/fields.hpp).
#include <cmath>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>

#include "estimator/fields.hpp"
#include "estimator/input_error.hpp"
#include "estimator/numbers.hpp"
#include "estimator/sample.hpp"
#include "twin/sensor/sensor_model.hpp"

namespace driftless::twin {
namespace {

constexpr double kG = kStandardGravityMps2;

// ---- the effect catalogue as tables: one row per YAML key of an effect ----

struct Effect {
  std::string id;
  std::function<bool&(SensorParams&)> enabled;
  std::function<void(SensorParams&, const fields::Node&, const fields::Context&)> read;  // the effect's map
  std::function<fields::Node(const SensorParams&)> write;
};

// an effect's table gets its `enabled` row first
template <class E>
Effect effect(std::string id, E SensorParams::*m, fields::Table<E> rows) {
  rows.insert(rows.begin(), fields::flag<E>("enabled", &E::enabled));
  auto t = std::make_shared<const fields::Table<E>>(std::move(rows));
  return {std::move(id), [m](SensorParams& p) -> bool& { return (p.*m).enabled; },
          [m, t](SensorParams& p, const fields::Node& n, const fields::Context& c) { fields::read_block(*t, p.*m, n, c); },
          [m, t](const SensorParams& p) { return fields::write_block(*t, p.*m); }};
}

// row shorthands: a per-axis vector also takes one number for all three axes
template <class E>
fields::Row<E> num(const char* stem, const char* unit, double E::*m) {
  return fields::number<E>(stem, unit, m);
}
template <class E>
fields::Row<E> v3(const char* stem, const char* unit, Eigen::Vector3d E::*m) {
  return fields::vector<E>(stem, unit, m, /*broadcast=*/true);
}
template <class E>
fields::Row<E> m3(const char* stem, const char* unit, Eigen::Matrix3d E::*m) {
  return fields::matrix3<E>(stem, unit, m);
}

#define DL_EFFECT(eff, ...) effect(#eff, &SensorParams::eff, {__VA_ARGS__})

const std::vector<Effect>& effects() {
  using TP = TemperatureParams;
  static const std::vector<Effect> e = {
      DL_EFFECT(constant_bias, v3("value", "dps", &ConstantBiasParams::value_dps),
                v3("sigma", "dps", &ConstantBiasParams::sigma_dps)),
      DL_EFFECT(bias_instability, v3("sigma", "dps", &BiasInstabilityParams::sigma_dps),
                v3("tau", "s", &BiasInstabilityParams::tau_s),
                fields::flag<BiasInstabilityParams>("stationary_start", &BiasInstabilityParams::stationary_start)),
      DL_EFFECT(rate_random_walk, v3("k", "dps_rts", &RateRandomWalkParams::k_dps_rts)),
      DL_EFFECT(white_noise, v3("density", "dps_rthz", &WhiteNoiseParams::density_dps_rthz)),
      DL_EFFECT(scale_factor, v3("value", "pct", &ScaleFactorParams::value_pct),
                v3("sigma", "pct", &ScaleFactorParams::sigma_pct)),
      DL_EFFECT(misalignment, m3("matrix", "pct", &MisalignmentParams::matrix_pct),
                num("sigma", "pct", &MisalignmentParams::sigma_pct)),
      DL_EFFECT(g_sensitivity, m3("matrix", "dps_per_g", &GSensitivityParams::matrix_dps_per_g),
                num("sigma", "dps_per_g", &GSensitivityParams::sigma_dps_per_g)),
      DL_EFFECT(temperature, num("ambient", "degc", &TP::ambient_degc),
                num("warmup_rise", "degc", &TP::warmup_rise_degc), num("warmup_tau", "s", &TP::warmup_tau_s),
                fields::text<TP>("profile_file", &TP::profile_file, /*quoted=*/true),
                num("reference", "degc", &TP::reference_degc),
                v3("bias_tc", "dps_per_degc", &TP::bias_tc_dps_per_degc),
                v3("bias_tc_sigma", "dps_per_degc", &TP::bias_tc_sigma_dps_per_degc),
                v3("scale_tc", "pct_per_degc", &TP::scale_tc_pct_per_degc),
                v3("scale_tc_sigma", "pct_per_degc", &TP::scale_tc_sigma_pct_per_degc),
                num("output_sensitivity", "lsb_per_degc", &TP::output_sensitivity_lsb_per_degc),
                num("output_offset", "degc", &TP::output_offset_degc)),
      DL_EFFECT(quantization, num("sensitivity", "lsb_per_dps", &QuantizationParams::sensitivity_lsb_per_dps)),
      DL_EFFECT(saturation, num("full_scale", "dps", &SaturationParams::full_scale_dps)),
      DL_EFFECT(adc_missing_codes, num("fraction", "", &AdcMissingCodesParams::fraction),
                fields::integer_list<AdcMissingCodesParams>("codes", &AdcMissingCodesParams::codes, -2000000000,
                                                            2000000000)),
      DL_EFFECT(adc_nonlinearity, num("quadratic_pct_fs", "", &AdcNonlinearityParams::quadratic_pct_fs),
                num("cubic_pct_fs", "", &AdcNonlinearityParams::cubic_pct_fs)),
      DL_EFFECT(lowpass_latency,
                fields::integer<LowpassLatencyParams>("dlpf_cfg", &LowpassLatencyParams::dlpf_cfg, -2000000000,
                                                      2000000000),
                num("delay", "s", &LowpassLatencyParams::delay_s),
                num("bandwidth", "hz", &LowpassLatencyParams::bandwidth_hz)),
      DL_EFFECT(sample_jitter, num("sigma", "s", &SampleJitterParams::sigma_s)),
      DL_EFFECT(mounting_misalignment, v3("angles", "deg", &MountingMisalignmentParams::angles_deg),
                v3("sigma", "deg", &MountingMisalignmentParams::sigma_deg)),
      DL_EFFECT(accel_bias, v3("value", "mps2", &AccelBiasParams::value_mps2),
                v3("sigma", "mps2", &AccelBiasParams::sigma_mps2)),
      DL_EFFECT(accel_white_noise, v3("density", "mps2_rthz", &AccelWhiteNoiseParams::density_mps2_rthz)),
      DL_EFFECT(accel_scale_factor, v3("value", "pct", &AccelScaleFactorParams::value_pct),
                v3("sigma", "pct", &AccelScaleFactorParams::sigma_pct)),
      DL_EFFECT(accel_quantization,
                num("sensitivity", "lsb_per_g", &AccelQuantizationParams::sensitivity_lsb_per_g),
                num("full_scale", "g", &AccelQuantizationParams::full_scale_g)),
      DL_EFFECT(sample_delay, num("delay", "s", &SampleDelayParams::delay_s)),
  };
  return e;
}
#undef DL_EFFECT

const Effect& find_effect(std::string_view id) {
  for (const auto& e : effects())
    if (e.id == id) return e;
  std::string valid;
  for (const auto& e : effects()) valid += (valid.empty() ? "" : ", ") + e.id;
  throw std::invalid_argument("unknown sensor effect id '" + std::string(id) +
                              "'; valid ids: " + valid);
}


// ---- validation helpers ----

[[noreturn]] void bad(const std::string& what, const std::string& msg) {
  throw std::invalid_argument("sensor effect " + what + " " + msg);
}
void finite(const std::string& what, double v) {
  if (!std::isfinite(v)) bad(what, "must be finite");
}
void non_negative(const std::string& what, double v) {
  finite(what, v);
  if (v < 0.0) bad(what, "must be >= 0 (got " + exact_number(v) + ")");
}
void positive(const std::string& what, double v) {
  finite(what, v);
  if (v <= 0.0) bad(what, "must be > 0 (got " + exact_number(v) + ")");
}
template <class F>
void each(const Eigen::Vector3d& v, F f) {
  for (int i = 0; i < 3; ++i) f(v[i]);
}

}  // namespace

// ---- public ----

const std::vector<std::string>& effect_ids() {
  static const std::vector<std::string> ids = [] {
    std::vector<std::string> v;
    for (const auto& e : effects()) v.push_back(e.id);
    return v;
  }();
  return ids;
}

bool effect_enabled(const SensorParams& p, std::string_view id) {
  return find_effect(id).enabled(const_cast<SensorParams&>(p));
}

void set_effect_enabled(SensorParams& p, std::string_view id, bool enabled) {
  find_effect(id).enabled(p) = enabled;
}

SensorParams mpu6050_defaults() {
  SensorParams p;
  p.preset = "mpu6050";
  // initial ZRO tolerance +-20 deg/s taken as 3 sigma
  p.constant_bias.sigma_dps = Eigen::Vector3d::Constant(20.0 / 3.0);
  // chosen so the bias wanders by hundreds of deg/h over hours (paper Fig. 1)
  p.bias_instability.sigma_dps = Eigen::Vector3d::Constant(0.1);
  p.bias_instability.tau_s = Eigen::Vector3d::Constant(10800.0);
  p.rate_random_walk.k_dps_rts = Eigen::Vector3d::Constant(2e-5);
  // rate noise spectral density 0.005 deg/s/rtHz (datasheet, paper section 4)
  p.white_noise.density_dps_rthz = Eigen::Vector3d::Constant(0.005);
  // sensitivity scale factor tolerance +-3 %, cross-axis sensitivity +-2 %: 3 sigma
  p.scale_factor.sigma_pct = Eigen::Vector3d::Constant(1.0);
  p.misalignment.sigma_pct = 2.0 / 3.0;
  // linear acceleration sensitivity 0.1 deg/s/g: rms row norm of G
  p.g_sensitivity.sigma_dps_per_g = 0.1 / std::sqrt(3.0);
  // ZRO variation +-20 deg/s over -40..85 degC, sensitivity variation +-2 % over the same: 3 sigma
  p.temperature.warmup_rise_degc = 2.0;
  p.temperature.warmup_tau_s = 600.0;
  p.temperature.bias_tc_sigma_dps_per_degc = Eigen::Vector3d::Constant(20.0 / 125.0 / 3.0);
  p.temperature.scale_tc_sigma_pct_per_degc = Eigen::Vector3d::Constant(2.0 / 125.0 / 3.0);
  // off by default; enabling gives the paper's "missing bins" and the datasheet 0.2 % nonlinearity
  p.adc_missing_codes.enabled = false;
  p.adc_missing_codes.fraction = 0.001;
  p.adc_nonlinearity.enabled = false;
  p.adc_nonlinearity.cubic_pct_fs = 0.2;
  p.lowpass_latency.dlpf_cfg = 3;
  p.sample_jitter.enabled = false;
  p.sample_jitter.sigma_s = 1e-4;
  p.mounting_misalignment.sigma_deg = Eigen::Vector3d::Constant(0.2);
  // zero-g offset +-50 mg (x, y), +-80 mg (z); noise 400 ug/rtHz; sensitivity tolerance +-3 %
  p.accel_bias.sigma_mps2 = Eigen::Vector3d(50.0, 50.0, 80.0) * (1e-3 * kG / 3.0);
  p.accel_white_noise.density_mps2_rthz = Eigen::Vector3d::Constant(400e-6 * kG);
  p.accel_scale_factor.sigma_pct = Eigen::Vector3d::Constant(1.0);
  return p;
}

SensorParams ideal_sensor() {
  SensorParams p = mpu6050_defaults();
  p.preset = "ideal";
  for (const auto& e : effects()) e.enabled(p) = false;
  return p;
}

SensorParams sensor_preset(std::string_view name) {
  if (name == "mpu6050") return mpu6050_defaults();
  if (name == "ideal") return ideal_sensor();
  throw std::invalid_argument("unknown sensor preset '" + std::string(name) +
                              "'; valid presets: mpu6050, ideal");
}

void SensorParams::validate() const {
  each(constant_bias.value_dps, [](double v) { finite("constant_bias.value_dps", v); });
  each(constant_bias.sigma_dps, [](double v) { non_negative("constant_bias.sigma_dps", v); });
  each(bias_instability.sigma_dps, [](double v) { non_negative("bias_instability.sigma_dps", v); });
  each(bias_instability.tau_s, [](double v) { positive("bias_instability.tau_s", v); });
  each(rate_random_walk.k_dps_rts, [](double v) { non_negative("rate_random_walk.k_dps_rts", v); });
  each(white_noise.density_dps_rthz,
       [](double v) { non_negative("white_noise.density_dps_rthz", v); });
  each(scale_factor.value_pct, [](double v) {
    finite("scale_factor.value_pct", v);
    if (v <= -100.0) bad("scale_factor.value_pct", "must be > -100 % (got " + exact_number(v) + ")");
  });
  each(scale_factor.sigma_pct, [](double v) { non_negative("scale_factor.sigma_pct", v); });
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      finite("misalignment.matrix_pct", misalignment.matrix_pct(r, c));
      finite("g_sensitivity.matrix_dps_per_g", g_sensitivity.matrix_dps_per_g(r, c));
    }
  if (misalignment.matrix_pct.diagonal().cwiseAbs().maxCoeff() != 0.0)
    bad("misalignment.matrix_pct",
        "has a non-zero diagonal; it must be 0 (per-axis gain errors belong in scale_factor)");
  non_negative("misalignment.sigma_pct", misalignment.sigma_pct);
  if (misalignment.sigma_pct > 20.0) bad("misalignment.sigma_pct", "must be <= 20 %");
  non_negative("g_sensitivity.sigma_dps_per_g", g_sensitivity.sigma_dps_per_g);
  const auto& tp = temperature;
  finite("temperature.ambient_degc", tp.ambient_degc);
  if (tp.ambient_degc < -273.15) bad("temperature.ambient_degc", "is below absolute zero");
  finite("temperature.warmup_rise_degc", tp.warmup_rise_degc);
  positive("temperature.warmup_tau_s", tp.warmup_tau_s);
  finite("temperature.reference_degc", tp.reference_degc);
  each(tp.bias_tc_dps_per_degc, [](double v) { finite("temperature.bias_tc_dps_per_degc", v); });
  each(tp.bias_tc_sigma_dps_per_degc,
       [](double v) { non_negative("temperature.bias_tc_sigma_dps_per_degc", v); });
  each(tp.scale_tc_pct_per_degc, [](double v) { finite("temperature.scale_tc_pct_per_degc", v); });
  each(tp.scale_tc_sigma_pct_per_degc,
       [](double v) { non_negative("temperature.scale_tc_sigma_pct_per_degc", v); });
  positive("temperature.output_sensitivity_lsb_per_degc", tp.output_sensitivity_lsb_per_degc);
  finite("temperature.output_offset_degc", tp.output_offset_degc);
  positive("quantization.sensitivity_lsb_per_dps", quantization.sensitivity_lsb_per_dps);
  positive("saturation.full_scale_dps", saturation.full_scale_dps);
  if (quantization.enabled && saturation.enabled &&
      saturation.full_scale_dps * quantization.sensitivity_lsb_per_dps > 32768.0)
    bad("saturation.full_scale_dps",
        "times quantization.sensitivity_lsb_per_dps exceeds the 16-bit range (32768)");
  non_negative("adc_missing_codes.fraction", adc_missing_codes.fraction);
  if (adc_missing_codes.fraction > 0.5)
    bad("adc_missing_codes.fraction", "must be <= 0.5 (got " + exact_number(adc_missing_codes.fraction) + ")");
  for (int c : adc_missing_codes.codes)
    if (c < -32768 || c > 32767) bad("adc_missing_codes.codes", "holds a code outside -32768..32767");
  if (adc_missing_codes.enabled && !quantization.enabled)
    bad("adc_missing_codes", "needs quantization enabled (missing codes live on the LSB grid)");
  finite("adc_nonlinearity.quadratic_pct_fs", adc_nonlinearity.quadratic_pct_fs);
  finite("adc_nonlinearity.cubic_pct_fs", adc_nonlinearity.cubic_pct_fs);
  if (std::abs(adc_nonlinearity.quadratic_pct_fs) + std::abs(adc_nonlinearity.cubic_pct_fs) > 10.0)
    bad("adc_nonlinearity", "needs |quadratic_pct_fs| + |cubic_pct_fs| <= 10 %");
  if (adc_nonlinearity.enabled && !saturation.enabled)
    bad("adc_nonlinearity", "needs saturation enabled (it is defined relative to full scale)");
  if (lowpass_latency.dlpf_cfg < 0 || lowpass_latency.dlpf_cfg > 6)
    bad("lowpass_latency.dlpf_cfg",
        "must be 0..6 (MPU6050 register 26), got " + std::to_string(lowpass_latency.dlpf_cfg));
  non_negative("lowpass_latency.delay_s", lowpass_latency.delay_s);
  if (lowpass_latency.delay_s > 1.0) bad("lowpass_latency.delay_s", "must be <= 1 s");
  non_negative("lowpass_latency.bandwidth_hz", lowpass_latency.bandwidth_hz);
  non_negative("sample_delay.delay_s", sample_delay.delay_s);
  if (sample_delay.delay_s > 1.0) bad("sample_delay.delay_s", "must be <= 1 s");
  non_negative("sample_jitter.sigma_s", sample_jitter.sigma_s);
  if (sample_jitter.sigma_s > 0.1) bad("sample_jitter.sigma_s", "must be <= 0.1 s");
  each(mounting_misalignment.angles_deg, [](double v) {
    finite("mounting_misalignment.angles_deg", v);
    if (std::abs(v) > 45.0) bad("mounting_misalignment.angles_deg", "must be within +-45 deg");
  });
  each(mounting_misalignment.sigma_deg,
       [](double v) { non_negative("mounting_misalignment.sigma_deg", v); });
  each(accel_bias.value_mps2, [](double v) { finite("accel_bias.value_mps2", v); });
  each(accel_bias.sigma_mps2, [](double v) { non_negative("accel_bias.sigma_mps2", v); });
  each(accel_white_noise.density_mps2_rthz,
       [](double v) { non_negative("accel_white_noise.density_mps2_rthz", v); });
  each(accel_scale_factor.value_pct, [](double v) {
    finite("accel_scale_factor.value_pct", v);
    if (v <= -100.0) bad("accel_scale_factor.value_pct", "must be > -100 %");
  });
  each(accel_scale_factor.sigma_pct,
       [](double v) { non_negative("accel_scale_factor.sigma_pct", v); });
  positive("accel_quantization.sensitivity_lsb_per_g", accel_quantization.sensitivity_lsb_per_g);
  positive("accel_quantization.full_scale_g", accel_quantization.full_scale_g);
  if (accel_quantization.full_scale_g * accel_quantization.sensitivity_lsb_per_g > 32768.0)
    bad("accel_quantization.full_scale_g",
        "times sensitivity_lsb_per_g exceeds the 16-bit range (32768)");
}

namespace {

// the effects map: each id's body is a map of its keys, or a bare true/false for `enabled`
void read_effects(SensorParams& p, const fields::Node& effs, const fields::Context& ctx,
                  std::vector<std::pair<std::string, std::size_t>>& effect_lines) {
  if (!effs.is_map()) ctx.fail(effs, ctx.path, "expected a map of effect id -> parameters");
  for (const auto& e : effs.entries) {
    const fields::Context c = ctx.child(e.key);
    const Effect* eff = nullptr;
    try {
      eff = &find_effect(e.key);
    } catch (const std::invalid_argument& x) {
      c.fail(fields::Node::at_line(e.line), c.path, x.what());
    }
    effect_lines.emplace_back(e.key, e.line);
    if (e.value.is_null()) continue;
    if (e.value.is_scalar()) {  // shorthand: `white_noise: false`
      eff->enabled(p) = fields::read_bool(e.value, fields::Reading{c});
      continue;
    }
    if (!e.value.is_map()) c.fail(e.value, c.path, "expected a map {enabled: bool, ...}");
    eff->read(p, e.value, c);
  }
}

}  // namespace

SensorParams read_sensor_params(const fields::Node& node, const SensorParams& base, const fields::Context& ctx) {
  if (node.is_null()) return base;
  if (!node.is_map()) ctx.fail(node, ctx.path, "expected a map {preset: mpu6050, effects: {<id>: {...}}}");
  SensorParams p = base;
  if (const fields::Node* pre = node.find("preset")) {
    const fields::Reading r{ctx.child("preset")};
    const std::string name = fields::read_text(*pre, r);
    try {
      p = sensor_preset(name);
    } catch (const std::invalid_argument& e) {
      r.fail(*pre, e.what());
    }
  }
  std::vector<std::pair<std::string, std::size_t>> effect_lines;  // to point validate() errors at a line
  for (const auto& e : node.entries) {
    if (e.key == "effects") {
      read_effects(p, e.value, ctx.child("effects"), effect_lines);
    } else if (e.key != "preset") {
      ctx.fail(fields::Node::at_line(e.line), ctx.key(e.key), "unknown key in a sensor block; valid keys: preset, effects");
    }
  }
  // a relative temperature profile is relative to the YAML file's folder
  if (!p.temperature.profile_file.empty() && !ctx.file.empty() &&
      p.temperature.profile_file != base.temperature.profile_file) {
    std::filesystem::path prof(p.temperature.profile_file);
    if (prof.is_relative())
      p.temperature.profile_file = (std::filesystem::path(ctx.file).parent_path() / prof).string();
  }
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    // messages read "sensor effect <id>.<key>: ..."; point at that effect's block when given
    const std::string msg = e.what();
    std::size_t line = node.line;
    for (const auto& [id, l] : effect_lines)
      if (msg.rfind("sensor effect " + id + ".", 0) == 0 || msg.rfind("sensor effect " + id + ":", 0) == 0 ||
          msg.rfind("sensor effect " + id + " ", 0) == 0)
        line = l;
    throw InputError(ctx.file.empty() ? std::string("<yaml>") : ctx.file, line, ctx.path, msg);
  }
  return p;
}

fields::Node write_sensor_params(const SensorParams& p) {
  fields::Node n = fields::Node::map();
  n.add("preset", fields::Node::scalar(p.preset));
  fields::Node& effs = n.add("effects", fields::Node::map());
  for (const auto& e : effects()) effs.add(e.id, e.write(p));
  return n;
}

}  // namespace driftless::twin
