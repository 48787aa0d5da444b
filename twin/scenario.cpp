#include "twin/scenario.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include <fmt/core.h>

#include "estimator/input_error.hpp"
#include "estimator/sample.hpp"
#include "twin/embedded.hpp"
#include "twin/yaml_doc.hpp"

namespace driftless::twin {
namespace {

using fields::Table;

// ---- the blocks: one table each drives parse, allowed keys and emit (docs/scenario.md) ----

const Table<MotorParams>& motor_table() {
  using M = MotorParams;
  static const Table<M> t = {
      fields::number<M>("max_speed", "dps", &M::max_speed_dps),
      fields::number<M>("max_accel", "dps2", &M::max_accel_dps2),
      fields::number<M>("kp", "nm_per_rad", &M::kp_nm_per_rad),
      fields::number<M>("kv", "nms_per_rad", &M::kv_nms_per_rad),
      fields::number<M>("stall_torque", "nm", &M::stall_torque_nm),
      fields::number<M>("rotor_inertia", "kgm2", &M::rotor_inertia_kgm2),
      fields::number<M>("damping", "nms_per_rad", &M::damping_nms_per_rad),
      fields::number<M>("overtravel", "deg", &M::overtravel_deg),
  };
  return t;
}

const Table<BoxParams>& box_table() {
  using B = BoxParams;
  static const Table<B> t = {
      fields::vector<B>("hinge1_axis", "", &B::hinge1_axis),
      fields::vector<B>("hinge2_axis", "", &B::hinge2_axis),
      fields::number<B>("end_stop", "deg", &B::end_stop_deg),
      fields::vector<B>("stop1_error", "deg", &B::stop1_error_deg),
      fields::vector<B>("stop2_error", "deg", &B::stop2_error_deg),
      fields::number<B>("stop_timeconst", "s", &B::stop_timeconst_s),
      fields::number<B>("stop_dampratio", "", &B::stop_dampratio),
      fields::block<B>("motor", &B::motor, &motor_table),
  };
  return t;
}

// a sensor block belongs to the effect catalogue (twin/sensor/sensor_params.cpp)
fields::Row<ModelConfig> sensor_row(const char* stem, SensorParams ModelConfig::*m) {
  return fields::custom<ModelConfig>(
      stem, "",
      [m](ModelConfig& c, const fields::Node& n, const fields::Reading& r) {
        c.*m = read_sensor_params(n, c.*m, r.ctx);
      },
      [m](const ModelConfig& c) -> std::optional<fields::Node> { return write_sensor_params(c.*m); });
}

const Table<ModelConfig>& model_table() {
  using M = ModelConfig;
  static const Table<M> t = {
      fields::block<M>("box", &M::box, &box_table),
      sensor_row("sensor1", &M::sensor1),
      sensor_row("sensor2", &M::sensor2),
      fields::number<M>("time_offset", "s", &M::time_offset_s),
  };
  return t;
}

const Table<StaticMotionParams>& static_table() {
  using P = StaticMotionParams;
  static const Table<P> t = {
      fields::vector<P>("attitude_ypr", "deg", &P::attitude_ypr_deg),
      fields::vector<P>("position", "m", &P::position_m),
  };
  return t;
}

const Table<PanTiltParams>& pan_tilt_table() {
  using P = PanTiltParams;
  static const Table<P> t = {
      fields::number<P>("max_rate", "dps", &P::max_rate_dps),
      fields::number<P>("min_rate", "dps", &P::min_rate_dps),
      fields::number<P>("accel", "dps2", &P::accel_dps2),
      fields::number<P>("pan_range", "deg", &P::pan_range_deg),
      fields::number<P>("tilt_range", "deg", &P::tilt_range_deg),
      fields::number<P>("dwell_min", "s", &P::dwell_min_s),
      fields::number<P>("dwell_max", "s", &P::dwell_max_s),
      fields::vector<P>("mount_ypr", "deg", &P::mount_ypr_deg),
  };
  return t;
}

const Table<GroundVehicleParams>& vehicle_table() {
  using P = GroundVehicleParams;
  static const Table<P> t = {
      fields::number<P>("max_speed", "mps", &P::max_speed_mps),
      fields::number<P>("max_accel", "mps2", &P::max_accel_mps2),
      fields::number<P>("max_yaw_rate", "dps", &P::max_yaw_rate_dps),
      fields::number<P>("max_lateral_accel", "mps2", &P::max_lateral_accel_mps2),
      fields::number<P>("stop_probability", "", &P::stop_probability),
      fields::number<P>("bumps", "per_km", &P::bumps_per_km),
      fields::number<P>("bump_height", "m", &P::bump_height_m),
      fields::number<P>("wheelbase", "m", &P::wheelbase_m),
      fields::number<P>("vibration", "deg", &P::vibration_deg),
      fields::number<P>("vibration_heave", "m", &P::vibration_heave_m),
      fields::number<P>("idle_vibration", "deg", &P::idle_vibration_deg),
      fields::number<P>("heading", "deg", &P::heading_deg),
  };
  return t;
}

const Table<ShipParams>& ship_table() {
  using P = ShipParams;
  static const Table<P> t = {
      fields::number<P>("speed", "mps", &P::speed_mps),
      fields::number<P>("course", "deg", &P::course_deg),
      fields::number<P>("roll_amplitude", "deg", &P::roll_amplitude_deg),
      fields::number<P>("roll_period", "s", &P::roll_period_s),
      fields::number<P>("pitch_amplitude", "deg", &P::pitch_amplitude_deg),
      fields::number<P>("pitch_period", "s", &P::pitch_period_s),
      fields::number<P>("yaw_amplitude", "deg", &P::yaw_amplitude_deg),
      fields::number<P>("yaw_period", "s", &P::yaw_period_s),
      fields::number<P>("heave_amplitude", "m", &P::heave_amplitude_m),
      fields::number<P>("heave_period", "s", &P::heave_period_s),
  };
  return t;
}

const Table<CsvMotionParams>& csv_table() {
  using P = CsvMotionParams;
  static const Table<P> t = {
      fields::text<P>("file", &P::file),
      fields::number<P>("time_offset", "s", &P::time_offset_s),
  };
  return t;
}

const fields::Names<MotionType>& motion_names() {
  static const fields::Names<MotionType> n = {
      {"static", MotionType::static_box}, {"pan_tilt", MotionType::pan_tilt},
      {"ground_vehicle", MotionType::ground_vehicle}, {"ship", MotionType::ship}, {"csv", MotionType::csv}};
  return n;
}

// the motion block: `type` selects which parameter table the other keys belong to
void read_motion(MotionConfig& m, const fields::Node& n, const fields::Reading& r) {
  if (!n.is_map()) r.fail(n, "expected a mapping with 'type' and that type's parameters");
  if (const fields::Node* t = n.find("type")) {
    m.type = fields::read_choice(*t, fields::Reading{r.ctx.child("type"), 1.0, nullptr}, motion_names());
  }
  switch (m.type) {
    case MotionType::static_box: fields::read_block(static_table(), m.static_box, n, r.ctx, {"type"}); break;
    case MotionType::pan_tilt: fields::read_block(pan_tilt_table(), m.pan_tilt, n, r.ctx, {"type"}); break;
    case MotionType::ground_vehicle: fields::read_block(vehicle_table(), m.ground_vehicle, n, r.ctx, {"type"}); break;
    case MotionType::ship: fields::read_block(ship_table(), m.ship, n, r.ctx, {"type"}); break;
    case MotionType::csv: fields::read_block(csv_table(), m.csv, n, r.ctx, {"type"}); break;
  }
}

fields::Node write_motion(const MotionConfig& m, const std::filesystem::path& base_dir) {
  fields::Node n = fields::Node::map();
  n.add("type", fields::Node::scalar(fields::choice_name(m.type, motion_names())));
  switch (m.type) {
    case MotionType::static_box: fields::write_into(static_table(), m.static_box, n); break;
    case MotionType::pan_tilt: fields::write_into(pan_tilt_table(), m.pan_tilt, n); break;
    case MotionType::ground_vehicle: fields::write_into(vehicle_table(), m.ground_vehicle, n); break;
    case MotionType::ship: fields::write_into(ship_table(), m.ship, n); break;
    case MotionType::csv: {
      // absolute path: the resolved file usually lives elsewhere than the scenario
      CsvMotionParams c = m.csv;
      std::filesystem::path f = c.file;
      if (f.is_relative() && !base_dir.empty()) c.file = (base_dir / f).string();
      fields::write_into(csv_table(), c, n);
      break;
    }
  }
  return n;
}

const Table<FlipScheduleParams>& flip_table() {
  using F = FlipScheduleParams;
  static const Table<F> t = {
      fields::flag<F>("enabled", &F::enabled),
      fields::number<F>("standstill", "s", &F::standstill_s),
      fields::number<F>("flip_angle", "deg", &F::flip_angle_deg),
      fields::number<F>("settle_rate", "dps", &F::settle_rate_dps),
  };
  return t;
}

const Table<Scenario>& scenario_table() {
  using S = Scenario;
  static const Table<S> t = {
      fields::text<S>("name", &S::name),
      fields::text<S>("description", &S::description, false, /*omit_empty=*/true),
      fields::number<S>("duration", "s", &S::duration_s),
      fields::integer<S>("seed", &S::seed, 0, 9007199254740992),  // 2^53: exact in a double
      fields::number<S>("latitude", "deg", &S::latitude_deg),
      fields::number<S>("sample_rate", "hz", &S::sample_rate_hz),
      fields::number<S>("physics_dt", "s", &S::physics_dt_s),
      fields::choice<S>("platform_readback", &S::platform_readback,
                        fields::Names<PlatformReadback>{{"end_stops", PlatformReadback::end_stops},
                                                        {"encoder", PlatformReadback::encoder}}),
      fields::block<S>("model", &S::model, &model_table),
      fields::custom<S>(
          "motion", "", [](S& s, const fields::Node& n, const fields::Reading& r) { read_motion(s.motion, n, r); },
          [](const S& s) -> std::optional<fields::Node> { return write_motion(s.motion, s.base_dir); }),
      fields::block<S>("flip_schedule", &S::flip_schedule, &flip_table),
  };
  return t;
}

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
  const fields::Node root = parse_yaml(text, file);
  Scenario s;
  s.base_dir = base_dir;
  if (!root.is_map()) {
    throw InputError(file, 1, "", "a scenario is a YAML mapping (name, duration_s, model, motion, ...)");
  }
  fields::read_block(scenario_table(), s, root, fields::Context{file, ""});
  with_location(file, 0, "", [&] { s.validate(); });
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
    throw InputError(path_or_builtin, 0, "", "no such scenario file (built-in scenarios: " + names + ")");
  }
  return parse_scenario(read_yaml_text(path), path.string(), std::filesystem::absolute(path).parent_path());
}

Scenario default_scenario() { return load_scenario("default"); }

ModelConfig load_model_config(const std::filesystem::path& path, const ModelConfig& base) {
  const fields::Node root = load_yaml_file(path);
  if (!root.is_map()) throw InputError(path.string(), 1, "", "a model file is a mapping holding 'model:'");
  static const Table<ModelConfig> file_table = {fields::block<ModelConfig>("model", [](auto& m) -> auto& { return m; }, &model_table)};
  ModelConfig m = base;
  fields::read_block(file_table, m, root, fields::Context{path.string(), ""});
  with_location(path.string(), 0, "", [&] { m.validate(); });
  return m;
}

fields::Node scenario_node(const Scenario& s) { return fields::write_block(scenario_table(), s); }

fields::Node model_node(const ModelConfig& m) { return fields::write_block(model_table(), m); }

std::string emit_scenario(const Scenario& s) {
  return "# resolved scenario (driftless simulate): every default explicit; units in the key names\n" +
         to_yaml(scenario_node(s)) + "\n";
}

}  // namespace driftless::twin
