#include "twin/scenario.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include <fmt/core.h>

#include "estimator/sample.hpp"
#include "twin/embedded.hpp"

namespace driftless::twin {
namespace {

// unit suffixes a key may carry, and how a value may spell that unit after the number
const std::map<std::string, std::vector<std::string>>& unit_spellings() {
  static const std::map<std::string, std::vector<std::string>> u = {
      {"deg", {"deg", "°"}}, {"rad", {"rad"}}, {"dps", {"deg/s", "dps"}}, {"radps", {"rad/s"}},
      {"dps2", {"deg/s^2", "deg/s2"}}, {"s", {"s", "sec"}}, {"ms", {"ms"}}, {"min", {"min"}},
      {"h", {"h"}}, {"hz", {"Hz", "hz"}}, {"khz", {"kHz"}}, {"m", {"m"}}, {"mm", {"mm"}},
      {"cm", {"cm"}}, {"km", {"km"}}, {"mps", {"m/s"}}, {"kmh", {"km/h"}},
      {"mps2", {"m/s^2", "m/s2"}}, {"g", {"g"}}, {"dph", {"deg/h"}}, {"nm", {"N m", "Nm"}},
      {"kgm2", {"kg m^2"}}, {"per_km", {"1/km"}}, {"degc", {"degC"}},
  };
  return u;
}

// "standstill_s" -> {"standstill", "s"}; "bumps_per_km" -> {"bumps", "per_km"}
std::pair<std::string, std::string> split_unit(const std::string& key) {
  const auto& units = unit_spellings();
  if (key.size() > 7 && key.compare(key.size() - 7, 7, "_per_km") == 0) {
    return {key.substr(0, key.size() - 7), "per_km"};
  }
  const auto us = key.rfind('_');
  if (us != std::string::npos) {
    const std::string u = key.substr(us + 1);
    if (units.count(u) != 0) return {key.substr(0, us), u};
  }
  return {key, ""};
}

// the scenario parser: remembers the file for messages
class Parser {
 public:
  explicit Parser(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const YAML::Node& at, const std::string& key, const std::string& what) const {
    const auto mark = at.Mark();
    std::string where = file_;
    if (!mark.is_null()) where += ":" + std::to_string(mark.line + 1);
    throw std::runtime_error(where + ": key '" + key + "': " + what);
  }

  // every key of map `node` (at dotted `path`) must be one of `allowed`
  void check_keys(const YAML::Node& node, const std::string& path,
                  const std::vector<std::string>& allowed) const {
    if (!node.IsMap()) fail(node, path, "expected a mapping (key: value lines)");
    for (const auto& kv : node) {
      const std::string key = kv.first.as<std::string>();
      if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
      const std::string full = path.empty() ? key : path + "." + key;
      // the right quantity in the wrong unit is a unit error, not a typo
      const auto [stem, unit] = split_unit(key);
      for (const auto& a : allowed) {
        const auto [astem, aunit] = split_unit(a);
        if (astem == stem && aunit != unit && !aunit.empty()) {
          fail(kv.first, full,
               unit.empty() ? "this value needs its unit in the key: write '" + a + "'"
                            : "inconsistent units: '" + key + "' is in " + unit + " but this field is in " +
                                  unit_spellings().at(aunit).front() + "; write '" + a +
                                  "' with the value converted");
        }
      }
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      fail(kv.first, full, "unknown key (allowed here: " + list + ")");
    }
  }

  // a number; a trailing unit text must match the key's unit
  double number(const YAML::Node& v, const std::string& key) const {
    if (!v.IsScalar()) fail(v, key, "expected a number");
    std::string text = v.Scalar();
    const auto [stem, unit] = split_unit(key.substr(key.rfind('.') + 1));
    std::size_t used = 0;
    double out = 0;
    try {
      out = std::stod(text, &used);
    } catch (const std::exception&) {
      fail(v, key, "expected a number" + unit_hint(unit) + ", got '" + text + "'");
    }
    std::string rest = text.substr(used);
    rest.erase(0, rest.find_first_not_of(' '));
    if (!rest.empty()) {
      bool ok = false;
      if (!unit.empty()) {
        for (const auto& sp : unit_spellings().at(unit)) ok = ok || rest == sp;
      }
      if (!ok) {
        fail(v, key, "inconsistent units: value '" + text + "' carries unit '" + rest + "' but this field is" +
                         (unit.empty() ? " dimensionless" : " in " + unit_spellings().at(unit).front()));
      }
    }
    if (!std::isfinite(out)) fail(v, key, "expected a finite number, got '" + text + "'");
    return out;
  }

  void get(const YAML::Node& map, const std::string& path, const char* key, double& out) const {
    if (auto v = map[key]) out = number(v, dotted(path, key));
  }
  void get(const YAML::Node& map, const std::string& path, const char* key, std::uint64_t& out) const {
    if (auto v = map[key]) {
      const double d = number(v, dotted(path, key));
      if (d < 0 || d != std::floor(d) || d > 9.007199254740992e15) {
        fail(v, dotted(path, key), "expected a non-negative integer");
      }
      out = static_cast<std::uint64_t>(d);
    }
  }
  void get(const YAML::Node& map, const std::string& path, const char* key, bool& out) const {
    if (auto v = map[key]) {
      if (!v.IsScalar() || (v.Scalar() != "true" && v.Scalar() != "false")) {
        fail(v, dotted(path, key), "expected true or false");
      }
      out = v.Scalar() == "true";
    }
  }
  void get(const YAML::Node& map, const std::string& path, const char* key, std::string& out) const {
    if (auto v = map[key]) {
      if (!v.IsScalar()) fail(v, dotted(path, key), "expected a text value");
      out = v.Scalar();
    }
  }
  template <int N>
  void get(const YAML::Node& map, const std::string& path, const char* key,
           Eigen::Matrix<double, N, 1>& out) const {
    if (auto v = map[key]) {
      const std::string k = dotted(path, key);
      if (!v.IsSequence() || v.size() != N) fail(v, k, "expected a list of " + std::to_string(N) + " numbers, e.g. [" +
                                                        std::string(N == 3 ? "0, 0, 1" : "0, 0") + "]");
      for (int i = 0; i < N; ++i) out[i] = number(v[static_cast<std::size_t>(i)], k);
    }
  }

  const std::string& file() const { return file_; }

 private:
  static std::string dotted(const std::string& path, const char* key) {
    return path.empty() ? std::string(key) : path + "." + key;
  }
  static std::string unit_hint(const std::string& unit) {
    return unit.empty() ? "" : " in " + unit_spellings().at(unit).front();
  }
  std::string file_;
};

void parse_motor(const Parser& P, const YAML::Node& n, MotorParams& m) {
  const std::string path = "model.box.motor";
  P.check_keys(n, path, {"max_speed_dps", "max_accel_dps2", "kp_nm_per_rad", "kv_nms_per_rad",
                         "stall_torque_nm", "rotor_inertia_kgm2", "damping_nms_per_rad", "overtravel_deg"});
  P.get(n, path, "max_speed_dps", m.max_speed_dps);
  P.get(n, path, "max_accel_dps2", m.max_accel_dps2);
  P.get(n, path, "kp_nm_per_rad", m.kp_nm_per_rad);
  P.get(n, path, "kv_nms_per_rad", m.kv_nms_per_rad);
  P.get(n, path, "stall_torque_nm", m.stall_torque_nm);
  P.get(n, path, "rotor_inertia_kgm2", m.rotor_inertia_kgm2);
  P.get(n, path, "damping_nms_per_rad", m.damping_nms_per_rad);
  P.get(n, path, "overtravel_deg", m.overtravel_deg);
}

void parse_box(const Parser& P, const YAML::Node& n, BoxParams& b) {
  const std::string path = "model.box";
  P.check_keys(n, path, {"hinge1_axis", "hinge2_axis", "end_stop_deg", "stop1_error_deg", "stop2_error_deg",
                         "stop_timeconst_s", "stop_dampratio", "motor"});
  P.get(n, path, "hinge1_axis", b.hinge1_axis);
  P.get(n, path, "hinge2_axis", b.hinge2_axis);
  P.get(n, path, "end_stop_deg", b.end_stop_deg);
  P.get(n, path, "stop1_error_deg", b.stop1_error_deg);
  P.get(n, path, "stop2_error_deg", b.stop2_error_deg);
  P.get(n, path, "stop_timeconst_s", b.stop_timeconst_s);
  P.get(n, path, "stop_dampratio", b.stop_dampratio);
  if (auto m = n["motor"]) parse_motor(P, m, b.motor);
}

void parse_model(const Parser& P, const YAML::Node& n, ModelConfig& m) {
  P.check_keys(n, "model", {"box", "sensor1", "sensor2", "time_offset_s"});
  if (auto b = n["box"]) parse_box(P, b, m.box);
  P.get(n, "model", "time_offset_s", m.time_offset_s);
  // the sensor blocks belong to the effect catalogue (docs/effects.md); it names file and line
  if (auto v = n["sensor1"]) m.sensor1 = parse_sensor_params(v, m.sensor1, P.file());
  if (auto v = n["sensor2"]) m.sensor2 = parse_sensor_params(v, m.sensor2, P.file());
}

void parse_motion(const Parser& P, const YAML::Node& n, MotionConfig& m) {
  const std::string path = "motion";
  if (!n.IsMap()) P.fail(n, path, "expected a mapping with 'type' and that type's parameters");
  if (auto t = n["type"]) {
    const std::string type = t.IsScalar() ? t.Scalar() : "";
    if (type == "static") m.type = MotionType::static_box;
    else if (type == "pan_tilt") m.type = MotionType::pan_tilt;
    else if (type == "ground_vehicle") m.type = MotionType::ground_vehicle;
    else if (type == "ship") m.type = MotionType::ship;
    else if (type == "csv") m.type = MotionType::csv;
    else P.fail(t, "motion.type", "unknown motion type '" + type + "' (static, pan_tilt, ground_vehicle, ship, csv)");
  }
  switch (m.type) {
    case MotionType::static_box: {
      auto& p = m.static_box;
      P.check_keys(n, path, {"type", "attitude_ypr_deg", "position_m"});
      P.get(n, path, "attitude_ypr_deg", p.attitude_ypr_deg);
      P.get(n, path, "position_m", p.position_m);
      break;
    }
    case MotionType::pan_tilt: {
      auto& p = m.pan_tilt;
      P.check_keys(n, path, {"type", "max_rate_dps", "min_rate_dps", "accel_dps2", "pan_range_deg", "tilt_range_deg",
                             "dwell_min_s", "dwell_max_s", "mount_ypr_deg"});
      P.get(n, path, "max_rate_dps", p.max_rate_dps);
      P.get(n, path, "min_rate_dps", p.min_rate_dps);
      P.get(n, path, "accel_dps2", p.accel_dps2);
      P.get(n, path, "pan_range_deg", p.pan_range_deg);
      P.get(n, path, "tilt_range_deg", p.tilt_range_deg);
      P.get(n, path, "dwell_min_s", p.dwell_min_s);
      P.get(n, path, "dwell_max_s", p.dwell_max_s);
      P.get(n, path, "mount_ypr_deg", p.mount_ypr_deg);
      break;
    }
    case MotionType::ground_vehicle: {
      auto& p = m.ground_vehicle;
      P.check_keys(n, path, {"type", "max_speed_mps", "max_accel_mps2", "max_yaw_rate_dps", "max_lateral_accel_mps2",
                             "stop_probability", "bumps_per_km", "bump_height_m", "wheelbase_m", "vibration_deg",
                             "vibration_heave_m", "idle_vibration_deg", "heading_deg"});
      P.get(n, path, "max_speed_mps", p.max_speed_mps);
      P.get(n, path, "max_accel_mps2", p.max_accel_mps2);
      P.get(n, path, "max_yaw_rate_dps", p.max_yaw_rate_dps);
      P.get(n, path, "max_lateral_accel_mps2", p.max_lateral_accel_mps2);
      P.get(n, path, "stop_probability", p.stop_probability);
      P.get(n, path, "bumps_per_km", p.bumps_per_km);
      P.get(n, path, "bump_height_m", p.bump_height_m);
      P.get(n, path, "wheelbase_m", p.wheelbase_m);
      P.get(n, path, "vibration_deg", p.vibration_deg);
      P.get(n, path, "vibration_heave_m", p.vibration_heave_m);
      P.get(n, path, "idle_vibration_deg", p.idle_vibration_deg);
      P.get(n, path, "heading_deg", p.heading_deg);
      break;
    }
    case MotionType::ship: {
      auto& p = m.ship;
      P.check_keys(n, path, {"type", "speed_mps", "course_deg", "roll_amplitude_deg", "roll_period_s",
                             "pitch_amplitude_deg", "pitch_period_s", "yaw_amplitude_deg", "yaw_period_s",
                             "heave_amplitude_m", "heave_period_s"});
      P.get(n, path, "speed_mps", p.speed_mps);
      P.get(n, path, "course_deg", p.course_deg);
      P.get(n, path, "roll_amplitude_deg", p.roll_amplitude_deg);
      P.get(n, path, "roll_period_s", p.roll_period_s);
      P.get(n, path, "pitch_amplitude_deg", p.pitch_amplitude_deg);
      P.get(n, path, "pitch_period_s", p.pitch_period_s);
      P.get(n, path, "yaw_amplitude_deg", p.yaw_amplitude_deg);
      P.get(n, path, "yaw_period_s", p.yaw_period_s);
      P.get(n, path, "heave_amplitude_m", p.heave_amplitude_m);
      P.get(n, path, "heave_period_s", p.heave_period_s);
      break;
    }
    case MotionType::csv: {
      auto& p = m.csv;
      P.check_keys(n, path, {"type", "file", "time_offset_s"});
      P.get(n, path, "file", p.file);
      P.get(n, path, "time_offset_s", p.time_offset_s);
      break;
    }
  }
}

void parse_flips(const Parser& P, const YAML::Node& n, FlipScheduleParams& f) {
  const std::string path = "flip_schedule";
  P.check_keys(n, path, {"enabled", "standstill_s", "flip_angle_deg", "settle_rate_dps"});
  P.get(n, path, "enabled", f.enabled);
  P.get(n, path, "standstill_s", f.standstill_s);
  P.get(n, path, "flip_angle_deg", f.flip_angle_deg);
  P.get(n, path, "settle_rate_dps", f.settle_rate_dps);
}

YAML::Node load_yaml(const std::string& text, const std::string& file) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(file + ":" + std::to_string(e.mark.line + 1) + ": broken YAML: " + e.msg);
  }
}

// ---- emitting: numbers in their shortest exact form, vectors as flow lists

std::string fmt_num(double v) { return fmt::format("{}", v); }

template <typename Vec>
void emit_vec(YAML::Emitter& out, const char* key, const Vec& v) {
  out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (Eigen::Index i = 0; i < v.size(); ++i) out << fmt_num(v[i]);
  out << YAML::EndSeq;
}
void emit_num(YAML::Emitter& out, const char* key, double v) { out << YAML::Key << key << YAML::Value << fmt_num(v); }

}  // namespace

const char* readback_name(PlatformReadback r) {
  return r == PlatformReadback::encoder ? "encoder" : "end_stops";
}

void ModelConfig::validate() const {
  box.validate();
  if (!(std::abs(time_offset_s) <= 1.0)) {
    throw std::invalid_argument(fmt::format("model.time_offset_s must be within [-1, 1] s, got {}", time_offset_s));
  }
  for (const auto* sp : {&sensor1, &sensor2}) {
    try {
      sp->validate();
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string(sp == &sensor1 ? "model.sensor1: " : "model.sensor2: ") + e.what());
    }
  }
}

void Scenario::validate() const {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument(what);
  };
  // beyond 1e7 s (116 days) a double time stamp resolves less than 2e-6 of a 1 ms physics step,
  // and the log would hold 1e9 rows (~370 GB) at 100 Hz
  require(duration_s > 0 && duration_s <= 1e7,
          fmt::format("duration_s = {} s must be in (0, 1e7] s (1e7 s = 116 days: at 100 Hz the log would "
                      "already hold 1e9 rows, ~370 GB); run longer studies as several runs with their own seeds",
                      duration_s));
  require(latitude_deg >= -90 && latitude_deg <= 90, "latitude_deg must be in [-90, 90] deg");
  require(sample_rate_hz > 0 && sample_rate_hz <= 1000, "sample_rate_hz must be in (0, 1000] Hz");
  require(physics_dt_s > 0 && physics_dt_s <= 0.005, "physics_dt_s must be in (0, 0.005] s");
  const double ratio = 1.0 / (sample_rate_hz * physics_dt_s);
  require(std::abs(ratio - std::round(ratio)) < 1e-6 && std::round(ratio) >= 1,
          fmt::format("sample_rate_hz = {} Hz and physics_dt_s = {} s: the sample period must be a whole "
                      "number of physics steps",
                      sample_rate_hz, physics_dt_s));
  model.validate();
  motion.validate();
  flip_schedule.validate(model.box.end_stop_deg);
}

long Scenario::steps_per_sample() const {
  return std::lround(1.0 / (sample_rate_hz * physics_dt_s));
}

std::uint64_t Scenario::total_samples() const {
  return static_cast<std::uint64_t>(std::ceil(duration_s * sample_rate_hz - 1e-9));
}

Scenario parse_scenario(const std::string& text, const std::string& file, const std::filesystem::path& base_dir) {
  const Parser P(file);
  const YAML::Node root = load_yaml(text, file);
  Scenario s;
  s.base_dir = base_dir;
  if (!root.IsMap()) {
    throw std::runtime_error(file + ":1: a scenario is a YAML mapping (name, duration_s, model, motion, ...)");
  }
  P.check_keys(root, "", {"name", "description", "duration_s", "seed", "latitude_deg", "sample_rate_hz",
                          "physics_dt_s", "platform_readback", "model", "motion", "flip_schedule"});
  P.get(root, "", "name", s.name);
  P.get(root, "", "description", s.description);
  P.get(root, "", "duration_s", s.duration_s);
  P.get(root, "", "seed", s.seed);
  P.get(root, "", "latitude_deg", s.latitude_deg);
  P.get(root, "", "sample_rate_hz", s.sample_rate_hz);
  P.get(root, "", "physics_dt_s", s.physics_dt_s);
  if (auto r = root["platform_readback"]) {
    const std::string v = r.IsScalar() ? r.Scalar() : "";
    if (v == "end_stops") s.platform_readback = PlatformReadback::end_stops;
    else if (v == "encoder") s.platform_readback = PlatformReadback::encoder;
    else P.fail(r, "platform_readback", "expected end_stops or encoder, got '" + v + "'");
  }
  if (auto m = root["model"]) parse_model(P, m, s.model);
  if (auto m = root["motion"]) parse_motion(P, m, s.motion);
  if (auto f = root["flip_schedule"]) parse_flips(P, f, s.flip_schedule);
  try {
    s.validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(file + ": " + e.what());
  }
  return s;
}

std::vector<std::string> builtin_scenarios() {
  std::vector<std::string> names;
  for (const auto& s : embedded::scenarios()) names.emplace_back(s.name);
  return names;
}

Scenario load_scenario(const std::string& path_or_builtin) {
  const std::filesystem::path path(path_or_builtin);
  if (!std::filesystem::exists(path)) {
    for (const auto& s : embedded::scenarios()) {
      if (s.name == path_or_builtin) return parse_scenario(std::string(s.text), "builtin:" + std::string(s.name));
    }
    std::string names;
    for (const auto& n : builtin_scenarios()) names += (names.empty() ? "" : ", ") + n;
    throw std::runtime_error(path_or_builtin + ": no such scenario file (built-in scenarios: " + names + ")");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot read scenario file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_scenario(ss.str(), path.string(), std::filesystem::absolute(path).parent_path());
}

Scenario default_scenario() { return load_scenario("default"); }

ModelConfig load_model_config(const std::filesystem::path& path, const ModelConfig& base) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot read model file");
  std::stringstream ss;
  ss << in.rdbuf();
  const Parser P(path.string());
  const YAML::Node root = load_yaml(ss.str(), path.string());
  if (!root.IsMap()) throw std::runtime_error(path.string() + ":1: a model file is a mapping holding 'model:'");
  P.check_keys(root, "", {"model"});
  ModelConfig m = base;
  if (auto n = root["model"]) parse_model(P, n, m);
  try {
    m.validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(path.string() + ": " + e.what());
  }
  return m;
}

std::string emit_scenario(const Scenario& s) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << s.name;
  if (!s.description.empty()) out << YAML::Key << "description" << YAML::Value << s.description;
  emit_num(out, "duration_s", s.duration_s);
  out << YAML::Key << "seed" << YAML::Value << s.seed;
  emit_num(out, "latitude_deg", s.latitude_deg);
  emit_num(out, "sample_rate_hz", s.sample_rate_hz);
  emit_num(out, "physics_dt_s", s.physics_dt_s);
  out << YAML::Key << "platform_readback" << YAML::Value << readback_name(s.platform_readback);

  out << YAML::Key << "model" << YAML::Value << YAML::BeginMap;
  const BoxParams& b = s.model.box;
  out << YAML::Key << "box" << YAML::Value << YAML::BeginMap;
  emit_vec(out, "hinge1_axis", b.hinge1_axis);
  emit_vec(out, "hinge2_axis", b.hinge2_axis);
  emit_num(out, "end_stop_deg", b.end_stop_deg);
  emit_vec(out, "stop1_error_deg", b.stop1_error_deg);
  emit_vec(out, "stop2_error_deg", b.stop2_error_deg);
  emit_num(out, "stop_timeconst_s", b.stop_timeconst_s);
  emit_num(out, "stop_dampratio", b.stop_dampratio);
  out << YAML::Key << "motor" << YAML::Value << YAML::BeginMap;
  emit_num(out, "max_speed_dps", b.motor.max_speed_dps);
  emit_num(out, "max_accel_dps2", b.motor.max_accel_dps2);
  emit_num(out, "kp_nm_per_rad", b.motor.kp_nm_per_rad);
  emit_num(out, "kv_nms_per_rad", b.motor.kv_nms_per_rad);
  emit_num(out, "stall_torque_nm", b.motor.stall_torque_nm);
  emit_num(out, "rotor_inertia_kgm2", b.motor.rotor_inertia_kgm2);
  emit_num(out, "damping_nms_per_rad", b.motor.damping_nms_per_rad);
  emit_num(out, "overtravel_deg", b.motor.overtravel_deg);
  out << YAML::EndMap << YAML::EndMap;
  out << YAML::Key << "sensor1" << YAML::Value;
  emit_sensor_params(out, s.model.sensor1);
  out << YAML::Key << "sensor2" << YAML::Value;
  emit_sensor_params(out, s.model.sensor2);
  emit_num(out, "time_offset_s", s.model.time_offset_s);
  out << YAML::EndMap;

  out << YAML::Key << "motion" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "type" << YAML::Value << motion_type_name(s.motion.type);
  switch (s.motion.type) {
    case MotionType::static_box:
      emit_vec(out, "attitude_ypr_deg", s.motion.static_box.attitude_ypr_deg);
      emit_vec(out, "position_m", s.motion.static_box.position_m);
      break;
    case MotionType::pan_tilt: {
      const auto& p = s.motion.pan_tilt;
      emit_num(out, "max_rate_dps", p.max_rate_dps);
      emit_num(out, "min_rate_dps", p.min_rate_dps);
      emit_num(out, "accel_dps2", p.accel_dps2);
      emit_num(out, "pan_range_deg", p.pan_range_deg);
      emit_num(out, "tilt_range_deg", p.tilt_range_deg);
      emit_num(out, "dwell_min_s", p.dwell_min_s);
      emit_num(out, "dwell_max_s", p.dwell_max_s);
      emit_vec(out, "mount_ypr_deg", p.mount_ypr_deg);
      break;
    }
    case MotionType::ground_vehicle: {
      const auto& p = s.motion.ground_vehicle;
      emit_num(out, "max_speed_mps", p.max_speed_mps);
      emit_num(out, "max_accel_mps2", p.max_accel_mps2);
      emit_num(out, "max_yaw_rate_dps", p.max_yaw_rate_dps);
      emit_num(out, "max_lateral_accel_mps2", p.max_lateral_accel_mps2);
      emit_num(out, "stop_probability", p.stop_probability);
      emit_num(out, "bumps_per_km", p.bumps_per_km);
      emit_num(out, "bump_height_m", p.bump_height_m);
      emit_num(out, "wheelbase_m", p.wheelbase_m);
      emit_num(out, "vibration_deg", p.vibration_deg);
      emit_num(out, "vibration_heave_m", p.vibration_heave_m);
      emit_num(out, "idle_vibration_deg", p.idle_vibration_deg);
      emit_num(out, "heading_deg", p.heading_deg);
      break;
    }
    case MotionType::ship: {
      const auto& p = s.motion.ship;
      emit_num(out, "speed_mps", p.speed_mps);
      emit_num(out, "course_deg", p.course_deg);
      emit_num(out, "roll_amplitude_deg", p.roll_amplitude_deg);
      emit_num(out, "roll_period_s", p.roll_period_s);
      emit_num(out, "pitch_amplitude_deg", p.pitch_amplitude_deg);
      emit_num(out, "pitch_period_s", p.pitch_period_s);
      emit_num(out, "yaw_amplitude_deg", p.yaw_amplitude_deg);
      emit_num(out, "yaw_period_s", p.yaw_period_s);
      emit_num(out, "heave_amplitude_m", p.heave_amplitude_m);
      emit_num(out, "heave_period_s", p.heave_period_s);
      break;
    }
    case MotionType::csv: {
      // absolute path: the resolved file usually lives elsewhere than the scenario
      std::filesystem::path f = s.motion.csv.file;
      if (f.is_relative() && !s.base_dir.empty()) f = s.base_dir / f;
      out << YAML::Key << "file" << YAML::Value << f.string();
      emit_num(out, "time_offset_s", s.motion.csv.time_offset_s);
      break;
    }
  }
  out << YAML::EndMap;

  out << YAML::Key << "flip_schedule" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "enabled" << YAML::Value << (s.flip_schedule.enabled ? "true" : "false");
  emit_num(out, "standstill_s", s.flip_schedule.standstill_s);
  emit_num(out, "flip_angle_deg", s.flip_schedule.flip_angle_deg);
  emit_num(out, "settle_rate_dps", s.flip_schedule.settle_rate_dps);
  out << YAML::EndMap;
  out << YAML::EndMap;
  return std::string("# resolved scenario (driftless simulate): every default explicit; units in the key names\n") +
         out.c_str() + "\n";
}

}  // namespace driftless::twin
