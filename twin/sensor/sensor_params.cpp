// Sensor parameters: presets, validation, and the YAML block (parse with unit-suffixed keys, emit).
#include <charconv>
#include <cmath>
#include <filesystem>
#include <functional>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "estimator/sample.hpp"
#include "twin/sensor/sensor_model.hpp"

namespace driftless::twin {
namespace {

// ---- units: a key is <name>_<unit>; a unit belongs to one family and converts to its base ----

enum class Family {
  kNone, kRate, kRateDensity, kRateRandomWalk, kTime, kTemp, kRatio, kRatePerG, kRatePerTemp,
  kRatioPerTemp, kAngle, kAccel, kAccelDensity, kGyroSensitivity, kAccelSensitivity,
  kTempSensitivity, kAccelRange, kFrequency
};

struct UnitDef {
  std::string_view suffix;
  Family family;
  double to_base;  // value in this unit * to_base = value in the family's base unit
  std::string_view label;
};

constexpr double kG = kStandardGravityMps2;

// base units: rad/s, rad/s/rtHz, rad/s/rts, s, degC, fraction, rad/s per m/s^2, ...
const std::vector<UnitDef>& units() {
  static const std::vector<UnitDef> u = {
      {"dps", Family::kRate, kRadPerDeg, "deg/s"},
      {"dph", Family::kRate, kRadPerDeg / 3600.0, "deg/h"},
      {"radps", Family::kRate, 1.0, "rad/s"},
      {"dps_rthz", Family::kRateDensity, kRadPerDeg, "deg/s/sqrt(Hz)"},
      {"dph_rthz", Family::kRateDensity, kRadPerDeg / 3600.0, "deg/h/sqrt(Hz)"},
      {"deg_rth", Family::kRateDensity, kRadPerDeg / 60.0, "deg/sqrt(h)"},
      {"radps_rthz", Family::kRateDensity, 1.0, "rad/s/sqrt(Hz)"},
      {"dps_rts", Family::kRateRandomWalk, kRadPerDeg, "deg/s/sqrt(s)"},
      {"dph_rth", Family::kRateRandomWalk, kRadPerDeg / 216000.0, "deg/h/sqrt(h)"},
      {"radps_rts", Family::kRateRandomWalk, 1.0, "rad/s/sqrt(s)"},
      {"s", Family::kTime, 1.0, "s"},
      {"ms", Family::kTime, 1e-3, "ms"},
      {"us", Family::kTime, 1e-6, "us"},
      {"min", Family::kTime, 60.0, "min"},
      {"h", Family::kTime, 3600.0, "h"},
      {"degc", Family::kTemp, 1.0, "degC"},
      {"pct", Family::kRatio, 1e-2, "%"},
      {"ppm", Family::kRatio, 1e-6, "ppm"},
      {"frac", Family::kRatio, 1.0, "fraction"},
      {"dps_per_g", Family::kRatePerG, kRadPerDeg / kG, "deg/s per g"},
      {"dph_per_g", Family::kRatePerG, kRadPerDeg / 3600.0 / kG, "deg/h per g"},
      {"radps_per_mps2", Family::kRatePerG, 1.0, "rad/s per m/s^2"},
      {"dps_per_degc", Family::kRatePerTemp, kRadPerDeg, "deg/s per degC"},
      {"dph_per_degc", Family::kRatePerTemp, kRadPerDeg / 3600.0, "deg/h per degC"},
      {"radps_per_degc", Family::kRatePerTemp, 1.0, "rad/s per degC"},
      {"pct_per_degc", Family::kRatioPerTemp, 1e-2, "% per degC"},
      {"ppm_per_degc", Family::kRatioPerTemp, 1e-6, "ppm per degC"},
      {"deg", Family::kAngle, kRadPerDeg, "deg"},
      {"rad", Family::kAngle, 1.0, "rad"},
      {"arcmin", Family::kAngle, kRadPerDeg / 60.0, "arcmin"},
      {"arcsec", Family::kAngle, kRadPerDeg / 3600.0, "arcsec"},
      {"mps2", Family::kAccel, 1.0, "m/s^2"},
      {"mg", Family::kAccel, kG * 1e-3, "mg"},
      {"ug", Family::kAccel, kG * 1e-6, "ug"},
      {"mps2_rthz", Family::kAccelDensity, 1.0, "m/s^2/sqrt(Hz)"},
      {"ug_rthz", Family::kAccelDensity, kG * 1e-6, "ug/sqrt(Hz)"},
      {"mg_rthz", Family::kAccelDensity, kG * 1e-3, "mg/sqrt(Hz)"},
      {"lsb_per_dps", Family::kGyroSensitivity, 1.0, "LSB per deg/s"},
      {"lsb_per_g", Family::kAccelSensitivity, 1.0, "LSB per g"},
      {"lsb_per_degc", Family::kTempSensitivity, 1.0, "LSB per degC"},
      {"g", Family::kAccelRange, 1.0, "g"},
      {"hz", Family::kFrequency, 1.0, "Hz"},
      {"khz", Family::kFrequency, 1e3, "kHz"},
  };
  return u;
}

const UnitDef* find_unit(std::string_view suffix) {
  for (const auto& u : units())
    if (u.suffix == suffix) return &u;
  return nullptr;
}

std::string family_units(Family f) {
  std::string s;
  for (const auto& u : units())
    if (u.family == f) s += (s.empty() ? "" : ", ") + std::string(u.suffix) + " (" + std::string(u.label) + ")";
  return s;
}

// ---- field descriptors: one per YAML key, pointing into SensorParams ----

enum class Kind { kBool, kInt, kDouble, kVec3, kMat3, kString, kIntList };

struct Field {
  std::string name;   // base name, e.g. "sigma"
  std::string unit;   // canonical unit suffix ("" for unitless), e.g. "dps"
  Kind kind;
  std::function<void*(SensorParams&)> ref;
  std::string key() const { return unit.empty() ? name : name + "_" + unit; }
};

struct Effect {
  std::string id;
  std::function<bool&(SensorParams&)> enabled;
  std::vector<Field> fields;
};

#define DL_FIELD(eff, fld, nm, un, kd) \
  Field { nm, un, kd, [](SensorParams& p) -> void* { return &p.eff.fld; } }
#define DL_EFFECT(eff, ...)                                                         \
  Effect {                                                                          \
    #eff, [](SensorParams& p) -> bool& { return p.eff.enabled; }, { __VA_ARGS__ } \
  }

const std::vector<Effect>& effects() {
  static const std::vector<Effect> e = {
      DL_EFFECT(constant_bias, DL_FIELD(constant_bias, value_dps, "value", "dps", Kind::kVec3),
                DL_FIELD(constant_bias, sigma_dps, "sigma", "dps", Kind::kVec3)),
      DL_EFFECT(bias_instability, DL_FIELD(bias_instability, sigma_dps, "sigma", "dps", Kind::kVec3),
                DL_FIELD(bias_instability, tau_s, "tau", "s", Kind::kVec3),
                DL_FIELD(bias_instability, stationary_start, "stationary_start", "", Kind::kBool)),
      DL_EFFECT(rate_random_walk, DL_FIELD(rate_random_walk, k_dps_rts, "k", "dps_rts", Kind::kVec3)),
      DL_EFFECT(white_noise,
                DL_FIELD(white_noise, density_dps_rthz, "density", "dps_rthz", Kind::kVec3)),
      DL_EFFECT(scale_factor, DL_FIELD(scale_factor, value_pct, "value", "pct", Kind::kVec3),
                DL_FIELD(scale_factor, sigma_pct, "sigma", "pct", Kind::kVec3)),
      DL_EFFECT(misalignment, DL_FIELD(misalignment, matrix_pct, "matrix", "pct", Kind::kMat3),
                DL_FIELD(misalignment, sigma_pct, "sigma", "pct", Kind::kDouble)),
      DL_EFFECT(g_sensitivity,
                DL_FIELD(g_sensitivity, matrix_dps_per_g, "matrix", "dps_per_g", Kind::kMat3),
                DL_FIELD(g_sensitivity, sigma_dps_per_g, "sigma", "dps_per_g", Kind::kDouble)),
      DL_EFFECT(temperature, DL_FIELD(temperature, ambient_degc, "ambient", "degc", Kind::kDouble),
                DL_FIELD(temperature, warmup_rise_degc, "warmup_rise", "degc", Kind::kDouble),
                DL_FIELD(temperature, warmup_tau_s, "warmup_tau", "s", Kind::kDouble),
                DL_FIELD(temperature, profile_file, "profile_file", "", Kind::kString),
                DL_FIELD(temperature, reference_degc, "reference", "degc", Kind::kDouble),
                DL_FIELD(temperature, bias_tc_dps_per_degc, "bias_tc", "dps_per_degc", Kind::kVec3),
                DL_FIELD(temperature, bias_tc_sigma_dps_per_degc, "bias_tc_sigma", "dps_per_degc",
                         Kind::kVec3),
                DL_FIELD(temperature, scale_tc_pct_per_degc, "scale_tc", "pct_per_degc", Kind::kVec3),
                DL_FIELD(temperature, scale_tc_sigma_pct_per_degc, "scale_tc_sigma", "pct_per_degc",
                         Kind::kVec3),
                DL_FIELD(temperature, output_sensitivity_lsb_per_degc, "output_sensitivity",
                         "lsb_per_degc", Kind::kDouble),
                DL_FIELD(temperature, output_offset_degc, "output_offset", "degc", Kind::kDouble)),
      DL_EFFECT(quantization, DL_FIELD(quantization, sensitivity_lsb_per_dps, "sensitivity",
                                       "lsb_per_dps", Kind::kDouble)),
      DL_EFFECT(saturation,
                DL_FIELD(saturation, full_scale_dps, "full_scale", "dps", Kind::kDouble)),
      DL_EFFECT(adc_missing_codes,
                DL_FIELD(adc_missing_codes, fraction, "fraction", "", Kind::kDouble),
                DL_FIELD(adc_missing_codes, codes, "codes", "", Kind::kIntList)),
      DL_EFFECT(adc_nonlinearity,
                DL_FIELD(adc_nonlinearity, quadratic_pct_fs, "quadratic_pct_fs", "", Kind::kDouble),
                DL_FIELD(adc_nonlinearity, cubic_pct_fs, "cubic_pct_fs", "", Kind::kDouble)),
      DL_EFFECT(lowpass_latency, DL_FIELD(lowpass_latency, dlpf_cfg, "dlpf_cfg", "", Kind::kInt),
                DL_FIELD(lowpass_latency, delay_s, "delay", "s", Kind::kDouble),
                DL_FIELD(lowpass_latency, bandwidth_hz, "bandwidth", "hz", Kind::kDouble)),
      DL_EFFECT(sample_jitter, DL_FIELD(sample_jitter, sigma_s, "sigma", "s", Kind::kDouble)),
      DL_EFFECT(mounting_misalignment,
                DL_FIELD(mounting_misalignment, angles_deg, "angles", "deg", Kind::kVec3),
                DL_FIELD(mounting_misalignment, sigma_deg, "sigma", "deg", Kind::kVec3)),
      DL_EFFECT(accel_bias, DL_FIELD(accel_bias, value_mps2, "value", "mps2", Kind::kVec3),
                DL_FIELD(accel_bias, sigma_mps2, "sigma", "mps2", Kind::kVec3)),
      DL_EFFECT(accel_white_noise, DL_FIELD(accel_white_noise, density_mps2_rthz, "density",
                                            "mps2_rthz", Kind::kVec3)),
      DL_EFFECT(accel_scale_factor,
                DL_FIELD(accel_scale_factor, value_pct, "value", "pct", Kind::kVec3),
                DL_FIELD(accel_scale_factor, sigma_pct, "sigma", "pct", Kind::kVec3)),
      DL_EFFECT(accel_quantization,
                DL_FIELD(accel_quantization, sensitivity_lsb_per_g, "sensitivity", "lsb_per_g",
                         Kind::kDouble),
                DL_FIELD(accel_quantization, full_scale_g, "full_scale", "g", Kind::kDouble)),
      DL_EFFECT(sample_delay, DL_FIELD(sample_delay, delay_s, "delay", "s", Kind::kDouble)),
  };
  return e;
}
#undef DL_FIELD
#undef DL_EFFECT

const Effect& find_effect(std::string_view id) {
  for (const auto& e : effects())
    if (e.id == id) return e;
  std::string valid;
  for (const auto& e : effects()) valid += (valid.empty() ? "" : ", ") + e.id;
  throw std::invalid_argument("unknown sensor effect id '" + std::string(id) +
                              "'; valid ids: " + valid);
}

Family family_of(const std::string& unit) {
  if (unit.empty()) return Family::kNone;
  const UnitDef* u = find_unit(unit);
  return u ? u->family : Family::kNone;
}

// ---- parse helpers ----

std::string where(const std::string& file, const YAML::Node& n) {
  std::string s = file.empty() ? std::string("<yaml>") : file;
  const YAML::Mark m = n.Mark();
  if (!m.is_null()) s += ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1);
  return s;
}

[[noreturn]] void fail(const std::string& file, const YAML::Node& n, const std::string& key,
                       const std::string& msg) {
  throw std::invalid_argument(where(file, n) + ": " + key + ": " + msg);
}

double as_double(const YAML::Node& n, const std::string& file, const std::string& key) {
  if (!n.IsScalar()) fail(file, n, key, "expected a number");
  const std::string s = n.Scalar();
  double v = 0.0;
  const char* b = s.data();
  const char* e = s.data() + s.size();
  if (!s.empty() && *b == '+') ++b;
  auto [ptr, ec] = std::from_chars(b, e, v);
  if (ec != std::errc() || ptr != e) {
    if (s == ".inf" || s == "-.inf" || s == ".nan") fail(file, n, key, "must be finite");
    fail(file, n, key, "expected a number, got '" + s + "'");
  }
  if (!std::isfinite(v)) fail(file, n, key, "must be finite");
  return v;
}

int as_int(const YAML::Node& n, const std::string& file, const std::string& key) {
  const double v = as_double(n, file, key);
  if (v != std::floor(v) || std::abs(v) > 2e9) fail(file, n, key, "expected an integer");
  return static_cast<int>(v);
}

bool as_bool(const YAML::Node& n, const std::string& file, const std::string& key) {
  bool b = false;
  if (!n.IsScalar() || !YAML::convert<bool>::decode(n, b))
    fail(file, n, key, "expected true or false");
  return b;
}

Eigen::Vector3d as_vec3(const YAML::Node& n, const std::string& file, const std::string& key) {
  if (n.IsScalar()) return Eigen::Vector3d::Constant(as_double(n, file, key));
  if (!n.IsSequence() || n.size() != 3)
    fail(file, n, key, "expected a number (all axes) or a list [x, y, z]");
  return {as_double(n[0], file, key), as_double(n[1], file, key), as_double(n[2], file, key)};
}

Eigen::Matrix3d as_mat3(const YAML::Node& n, const std::string& file, const std::string& key) {
  Eigen::Matrix3d m;
  if (n.IsSequence() && n.size() == 3 && n[0].IsSequence()) {
    for (int r = 0; r < 3; ++r) {
      if (!n[r].IsSequence() || n[r].size() != 3)
        fail(file, n[r], key, "expected 3 rows of 3 numbers");
      for (int c = 0; c < 3; ++c) m(r, c) = as_double(n[r][c], file, key);
    }
    return m;
  }
  if (n.IsSequence() && n.size() == 9) {
    for (int i = 0; i < 9; ++i) m(i / 3, i % 3) = as_double(n[i], file, key);
    return m;
  }
  fail(file, n, key, "expected a 3x3 matrix: [[a, b, c], [d, e, f], [g, h, i]] (rows)");
}

// finds the field a key names, with its unit conversion factor; throws on unknown/inconsistent units
std::pair<const Field*, double> resolve_key(const Effect& eff, const std::string& key,
                                            const std::string& file, const YAML::Node& n) {
  const std::string full = "effects." + eff.id + "." + key;
  for (const auto& f : eff.fields)
    if (f.key() == key) return {&f, 1.0};
  // longest field name that prefixes the key with "_<known unit>"
  const Field* best = nullptr;
  const UnitDef* best_unit = nullptr;
  for (const auto& f : eff.fields) {
    if (key.size() <= f.name.size() + 1 || key.compare(0, f.name.size(), f.name) != 0 ||
        key[f.name.size()] != '_')
      continue;
    const UnitDef* u = find_unit(std::string_view(key).substr(f.name.size() + 1));
    if (u && (!best || f.name.size() > best->name.size())) {
      best = &f;
      best_unit = u;
    }
  }
  if (best) {
    const Family want = family_of(best->unit);
    if (want == Family::kNone || best_unit->family != want) {
      fail(file, n, full,
           "inconsistent unit '" + std::string(best_unit->suffix) + "' (" +
               std::string(best_unit->label) + "); " + best->name + " expects " +
               (want == Family::kNone ? std::string("no unit suffix: use '") + best->key() + "'"
                                      : "one of: " + family_units(want) + " (canonical key '" +
                                            best->key() + "')"));
    }
    return {best, best_unit->to_base / find_unit(best->unit)->to_base};
  }
  std::string valid = "enabled";
  for (const auto& f : eff.fields) valid += ", " + f.key();
  fail(file, n, full, "unknown key; valid keys: " + valid);
}

void parse_field(const Field& f, double factor, SensorParams& p, const YAML::Node& n,
                 const std::string& file, const std::string& key) {
  void* ptr = f.ref(p);
  switch (f.kind) {
    case Kind::kBool: *static_cast<bool*>(ptr) = as_bool(n, file, key); break;
    case Kind::kInt: *static_cast<int*>(ptr) = as_int(n, file, key); break;
    case Kind::kDouble: *static_cast<double*>(ptr) = as_double(n, file, key) * factor; break;
    case Kind::kVec3: *static_cast<Eigen::Vector3d*>(ptr) = as_vec3(n, file, key) * factor; break;
    case Kind::kMat3: *static_cast<Eigen::Matrix3d*>(ptr) = as_mat3(n, file, key) * factor; break;
    case Kind::kString:
      if (!n.IsScalar()) fail(file, n, key, "expected a string");
      *static_cast<std::string*>(ptr) = n.Scalar();
      break;
    case Kind::kIntList: {
      if (!n.IsSequence()) fail(file, n, key, "expected a list of integers");
      auto& v = *static_cast<std::vector<int>*>(ptr);
      v.clear();
      for (const auto& x : n) v.push_back(as_int(x, file, key));
      break;
    }
  }
}

// ---- emit helpers: shortest round-trip decimal for every double ----

std::string num(double v) {
  char buf[64];
  auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, v);
  std::string s(buf, ptr);
  // keep it a float in YAML eyes is not needed: our parser reads integers as numbers too
  return s;
}

void emit_field(YAML::Emitter& out, const Field& f, SensorParams& p) {
  void* ptr = f.ref(p);
  out << YAML::Key << f.key() << YAML::Value;
  switch (f.kind) {
    case Kind::kBool: out << *static_cast<bool*>(ptr); break;
    case Kind::kInt: out << *static_cast<int*>(ptr); break;
    case Kind::kDouble: out << num(*static_cast<double*>(ptr)); break;
    case Kind::kVec3: {
      const auto& v = *static_cast<Eigen::Vector3d*>(ptr);
      out << YAML::Flow << YAML::BeginSeq << num(v[0]) << num(v[1]) << num(v[2]) << YAML::EndSeq;
      break;
    }
    case Kind::kMat3: {
      const auto& m = *static_cast<Eigen::Matrix3d*>(ptr);
      out << YAML::Flow << YAML::BeginSeq;
      for (int r = 0; r < 3; ++r)
        out << YAML::Flow << YAML::BeginSeq << num(m(r, 0)) << num(m(r, 1)) << num(m(r, 2))
            << YAML::EndSeq;
      out << YAML::EndSeq;
      break;
    }
    case Kind::kString: out << YAML::DoubleQuoted << *static_cast<std::string*>(ptr); break;
    case Kind::kIntList: {
      out << YAML::Flow << YAML::BeginSeq;
      for (int c : *static_cast<std::vector<int>*>(ptr)) out << c;
      out << YAML::EndSeq;
      break;
    }
  }
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
  if (v < 0.0) bad(what, "must be >= 0 (got " + num(v) + ")");
}
void positive(const std::string& what, double v) {
  finite(what, v);
  if (v <= 0.0) bad(what, "must be > 0 (got " + num(v) + ")");
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
    if (v <= -100.0) bad("scale_factor.value_pct", "must be > -100 % (got " + num(v) + ")");
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
    bad("adc_missing_codes.fraction", "must be <= 0.5 (got " + num(adc_missing_codes.fraction) + ")");
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

SensorParams parse_sensor_params(const YAML::Node& node, const SensorParams& base,
                                 const std::string& file) {
  if (!node.IsDefined() || node.IsNull()) return base;
  if (!node.IsMap())
    fail(file, node, "sensor", "expected a map {preset: mpu6050, effects: {<id>: {...}}}");
  SensorParams p = base;
  std::vector<std::pair<std::string, YAML::Node>> effect_nodes;  // to point validate() errors at a line
  if (const YAML::Node pre = node["preset"]; pre) {
    if (!pre.IsScalar()) fail(file, pre, "preset", "expected a preset name (mpu6050, ideal)");
    try {
      p = sensor_preset(pre.Scalar());
    } catch (const std::invalid_argument& e) {
      fail(file, pre, "preset", e.what());
    }
  }
  for (const auto& kv : node) {
    const std::string k = kv.first.Scalar();
    if (k != "preset" && k != "effects")
      fail(file, kv.first, k, "unknown key in a sensor block; valid keys: preset, effects");
  }
  if (const YAML::Node effs = node["effects"]; effs && !effs.IsNull()) {
    if (!effs.IsMap()) fail(file, effs, "effects", "expected a map of effect id -> parameters");
    for (const auto& kv : effs) {
      const std::string id = kv.first.Scalar();
      const Effect* eff = nullptr;
      try {
        eff = &find_effect(id);
      } catch (const std::invalid_argument& e) {
        fail(file, kv.first, "effects." + id, e.what());
      }
      const YAML::Node body = kv.second;
      effect_nodes.emplace_back(id, kv.first);
      if (body.IsNull()) continue;
      if (body.IsScalar()) {  // shorthand: `white_noise: false`
        eff->enabled(p) = as_bool(body, file, "effects." + id);
        continue;
      }
      if (!body.IsMap()) fail(file, body, "effects." + id, "expected a map {enabled: bool, ...}");
      for (const auto& fkv : body) {
        const std::string key = fkv.first.Scalar();
        const std::string full = "effects." + id + "." + key;
        if (key == "enabled") {
          eff->enabled(p) = as_bool(fkv.second, file, full);
          continue;
        }
        auto [field, factor] = resolve_key(*eff, key, file, fkv.first);
        parse_field(*field, factor, p, fkv.second, file, full);
      }
    }
  }
  // a relative temperature profile is relative to the YAML file's folder
  if (!p.temperature.profile_file.empty() && !file.empty() &&
      p.temperature.profile_file != base.temperature.profile_file) {
    std::filesystem::path prof(p.temperature.profile_file);
    if (prof.is_relative())
      p.temperature.profile_file = (std::filesystem::path(file).parent_path() / prof).string();
  }
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    // messages read "sensor effect <id>.<key>: ..."; point at that effect's block when given
    const std::string msg = e.what();
    YAML::Node at = node;
    for (const auto& [id, n] : effect_nodes)
      if (msg.rfind("sensor effect " + id + ".", 0) == 0 || msg.rfind("sensor effect " + id + ":", 0) == 0)
        at = n;
    throw std::invalid_argument(where(file, at) + ": " + msg);
  }
  return p;
}

void emit_sensor_params(YAML::Emitter& out, const SensorParams& p_in) {
  SensorParams p = p_in;  // the field accessors take a mutable reference; nothing is changed
  out << YAML::BeginMap;
  out << YAML::Key << "preset" << YAML::Value << p.preset;
  out << YAML::Key << "effects" << YAML::Value << YAML::BeginMap;
  for (const auto& e : effects()) {
    out << YAML::Key << e.id << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "enabled" << YAML::Value << e.enabled(p);
    for (const auto& f : e.fields) emit_field(out, f, p);
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  out << YAML::EndMap;
}

}  // namespace driftless::twin
