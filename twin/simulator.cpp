#include "twin/simulator.hpp"

#include "estimator/geometry.hpp"
#include "estimator/random.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <fmt/core.h>

namespace driftless::twin {
namespace {

// the static fast path engages once the platforms are this still (the state is then constant
// to far below the 1e-9 rad/s truth tolerance)
constexpr double kFreezeRateRadps = 1e-11;
constexpr double kFreezeAccelRadps2 = 1e-8;
// platforms settle on their stops for this long before t = 0, s
constexpr double kWarmupS = 1.0;

std::string vec_text(const Eigen::Vector3d& v) { return fmt::format("{} {} {}", v.x(), v.y(), v.z()); }

}  // namespace

Simulator::Simulator(const Scenario& scenario, SimOptions options)
    : scenario_((scenario.validate(), scenario)),
      options_(options),
      world_(scenario.model.box, scenario.physics_dt_s),
      motion_(make_motion(scenario.motion, scenario.duration_s, scenario.seed, scenario.base_dir)),
      flips_(scenario.flip_schedule, scenario.model.box),
      earth_enu_radps_(geo::earth_rate_enu_radps(scenario.latitude_deg)),
      steps_per_sample_(scenario.steps_per_sample()),
      total_(scenario.total_samples()) {
  if (scenario.model.time_offset_s < 0) {
    throw std::invalid_argument(fmt::format(
        "model.time_offset_s = {} s: simulate models sensors sampling before the log's time stamp "
        "(offset >= 0) only; compare and diagnose honour negative offsets",
        scenario.model.time_offset_s));
  }
  // each sensor draws its run-to-run values and noise from its own stream of the seed
  sensors_.emplace_back(scenario.model.sensor1, scenario.sample_rate_hz, rnd::stream_seed(scenario.seed, rnd::Stream::kSensor1));
  sensors_.emplace_back(scenario.model.sensor2, scenario.sample_rate_hz, rnd::stream_seed(scenario.seed, rnd::Stream::kSensor2));
  // initial state: box at its t = 0 pose, both platforms at rest on their + positions
  const MotionState m0 = motion_->at(0.0);
  world_.set_base(m0.p_enu_m, m0.q_enu_from_body, m0.v_enu_mps, m0.w_body_radps);
  for (int i = 1; i <= 2; ++i) {
    world_.set_platform(i, flips_.initial_angle_rad(i), 0.0);
    world_.set_motor_reference(i, flips_.reference_rad(i));
  }
  world_.pose_carrier(motion_->carrier(), m0.p_enu_m, m0.q_enu_from_body);
  // settle the platforms on their stops before t = 0 (the box held still at its t = 0 pose), so
  // the run starts at rest rather than with the stops' initial transient
  mjModel* m = world_.model();
  mjData* d = world_.data();
  const long warmup_steps = std::lround(kWarmupS / scenario.physics_dt_s);
  for (long n = 0; n < warmup_steps; ++n) {
    world_.set_base(m0.p_enu_m, m0.q_enu_from_body, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
    mj_step1(m, d);
    world_.drive_base(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
    mj_step2(m, d);
  }
  d->time = 0.0;
  world_.set_base(m0.p_enu_m, m0.q_enu_from_body, m0.v_enu_mps, m0.w_body_radps);
  mj_forward(m, d);
}

Simulator::~Simulator() = default;

std::uint32_t Simulator::fields() {
  return kFieldAccel | kFieldTemp | kFieldRefQ | kFieldRefP | kFieldTrueBias | kFieldTrueRate | kFieldTruePlat;
}

log::Metadata Simulator::metadata() const {
  log::Metadata m;
  m.set("sample_rate_hz", fmt::format("{}", scenario_.sample_rate_hz));
  m.set("latitude_deg", fmt::format("{}", scenario_.latitude_deg));
  m.set("hinge1_axis", vec_text(scenario_.model.box.hinge_axis(1)));
  m.set("hinge2_axis", vec_text(scenario_.model.box.hinge_axis(2)));
  m.set("source", "twin");
  m.set("scenario", scenario_.name);
  m.set("seed", std::to_string(scenario_.seed));
  m.set("duration_s", fmt::format("{}", scenario_.duration_s));
  m.set("motion", motion_type_name(scenario_.motion.type));
  m.set("carrier", carrier_name(motion_->carrier()));
  m.set("platform_readback", readback_name(scenario_.platform_readback));
  m.set("flip_angle_deg", fmt::format("{}", scenario_.flip_schedule.flip_angle_deg));
  m.set("standstill_s", fmt::format("{}", scenario_.flip_schedule.standstill_s));
  if (flips_.external_control()) m.set("flip_control", "external");
  m.set("end_stop_deg", fmt::format("{}", scenario_.model.box.end_stop_deg));
  m.set("sensor1_preset", scenario_.model.sensor1.preset);
  m.set("sensor2_preset", scenario_.model.sensor2.preset);
  return m;
}

void Simulator::take_flip_control() { flips_.take_external_control(); }

void Simulator::command_platform(int i, int sign) {
  if (i != 1 && i != 2) throw std::invalid_argument("command_platform: platform must be 1 or 2, got " + std::to_string(i));
  if (sign != 1 && sign != -1) throw std::invalid_argument("command_platform: sign must be +1 or -1, got " + std::to_string(sign));
  if (!flips_.external_control()) {
    throw std::invalid_argument("command_platform: the scenario's flip schedule drives the servos (call take_flip_control() first)");
  }
  // the move starts at the next physics step; a frozen (static fast path) state thaws there
  flips_.command(i, sign, static_cast<double>(step_) * scenario_.physics_dt_s);
}

// one physics step at t = step_ * dt: drive the base, command the motors, step MuJoCo;
// with `output`, the truth at t is captured between the two halves of the step
void Simulator::physics_step(bool output) {
  const mjModel* m = world_.model();
  mjData* d = world_.data();
  const double t = static_cast<double>(step_) * scenario_.physics_dt_s;
  const Eigen::Vector2d rates(world_.platform_rate_radps(1), world_.platform_rate_radps(2));
  flips_.update(t, rates);

  if (frozen_) {
    if (!flips_.any_moving()) {
      if (output) {
        truth_ = frozen_truth_;
        truth_.t_s = t;
        base_ = motion_->at(t);
      }
      ++step_;
      return;
    }
    frozen_ = false;  // a flip starts: back to full physics
  }

  const MotionState ms = motion_->at(t);
  world_.set_base(ms.p_enu_m, ms.q_enu_from_body, ms.v_enu_mps, ms.w_body_radps);
  for (int i = 1; i <= 2; ++i) world_.set_motor_reference(i, flips_.reference_rad(i));
  d->time = t;
  mj_step1(m, d);  // kinematics, velocities, gyro sensors at t
  world_.drive_base(ms.a_enu_mps2, ms.dw_body_radps2);
  if (output) {
    base_ = ms;
    truth_.t_s = t;
    for (int i = 0; i < 2; ++i) {
      truth_.plat_rad[i] = world_.platform_angle_rad(i + 1);
      truth_.plat_rate_radps[i] = world_.platform_rate_radps(i + 1);
    }
  }
  mj_step2(m, d);  // actuation, constraints (end stops), accelerometers at t; integrate to t + dt
  ++mj_steps_;
  if (output) capture_truth();

  // static fast path: a static box with settled platforms stays exactly as it is
  if (options_.fast_standstill && motion_->is_static() && !flips_.any_moving()) {
    bool still = true;
    for (int i = 1; i <= 2; ++i) {
      still = still && std::abs(world_.platform_rate_radps(i)) < kFreezeRateRadps &&
              std::abs(world_.platform_accel_radps2(i)) < kFreezeAccelRadps2;
    }
    if (still) {
      if (!output) capture_truth();  // truth of this (constant) state
      frozen_truth_ = truth_;
      frozen_ = true;
    }
  }
  ++step_;
}

// truth from MuJoCo's sensors (valid after mj_step2 for the time of that step) + Earth rate
void Simulator::capture_truth() {
  for (int i = 0; i < 2; ++i) {
    const Eigen::Matrix3d R = world_.R_enu_from_sensor(i + 1);
    truth_.w_sensor_radps[i] = world_.mj_gyro(i + 1) + R.transpose() * earth_enu_radps_;
    truth_.f_sensor_mps2[i] = world_.mj_accel(i + 1);
  }
  const mjData* d = world_.data();
  const int box = world_.box_body();
  const mjtNum* xq = d->xquat + 4 * box;
  const Eigen::Quaterniond q_box(xq[0], xq[1], xq[2], xq[3]);
  const mjtNum* cv = d->cvel + 6 * box;  // com-based velocity: [angular (world axes); linear]
  const Eigen::Vector3d w_world(cv[0], cv[1], cv[2]);
  truth_.w_body_radps = q_box.conjugate() * (w_world + earth_enu_radps_);
}

void Simulator::fill_sample(Sample& out) {
  out = Sample{};
  out.t_s = truth_.t_s;
  // the sensor-effect catalogue turns the truth into readings (docs/effects.md)
  // model.time_offset_s: the sensors sampled the truth of `offset` earlier (linear
  // interpolation between the output samples kept in a short history)
  const double shift = scenario_.model.time_offset_s * scenario_.sample_rate_hz;
  Eigen::Vector3d w_in[2] = {truth_.w_sensor_radps[0], truth_.w_sensor_radps[1]};
  Eigen::Vector3d f_in[2] = {truth_.f_sensor_mps2[0], truth_.f_sensor_mps2[1]};
  if (shift > 0) {
    history_.push_back(truth_);
    const auto keep = static_cast<std::size_t>(std::ceil(shift)) + 2;
    while (history_.size() > keep) history_.pop_front();
    const auto whole = static_cast<std::size_t>(std::floor(shift));
    const double u = shift - static_cast<double>(whole);
    const std::size_t last = history_.size() - 1;
    const SampleTruth& a = history_[last >= whole ? last - whole : 0];
    const SampleTruth& b = history_[last >= whole + 1 ? last - whole - 1 : 0];
    for (int i = 0; i < 2; ++i) {
      w_in[i] = (1.0 - u) * a.w_sensor_radps[i] + u * b.w_sensor_radps[i];
      f_in[i] = (1.0 - u) * a.f_sensor_mps2[i] + u * b.f_sensor_mps2[i];
    }
  }
  SensorReading r[2];
  for (int i = 0; i < 2; ++i) {
    SensorTruth st;
    st.t_s = truth_.t_s;
    st.w_radps = w_in[i];
    st.f_mps2 = f_in[i];
    r[i] = sensors_[static_cast<std::size_t>(i)].step(st);
  }
  out.gyro1_dps = r[0].gyro_radps * kDegPerRad;
  out.gyro2_dps = r[1].gyro_radps * kDegPerRad;
  out.accel1_mps2 = r[0].accel_mps2;
  out.accel2_mps2 = r[1].accel_mps2;
  out.temp1_c = r[0].temp_c;
  out.temp2_c = r[1].temp_c;
  out.true_bias1_dps = r[0].bias_radps * kDegPerRad;
  out.true_bias2_dps = r[1].bias_radps * kDegPerRad;
  out.true_rate_body_dps = truth_.w_body_radps * kDegPerRad;
  out.true_plat1_deg = truth_.plat_rad[0] * kDegPerRad;
  out.true_plat2_deg = truth_.plat_rad[1] * kDegPerRad;
  double known[2];
  for (int i = 0; i < 2; ++i) {
    if (scenario_.platform_readback == PlatformReadback::encoder) {
      known[i] = truth_.plat_rad[i] * kDegPerRad;
    } else {
      known[i] = flips_.moving(i + 1) ? kNaN : flips_.commanded_rest_rad(i + 1) * kDegPerRad;
    }
  }
  out.plat1_deg = known[0];
  out.plat2_deg = known[1];
  out.set_q_enu_from_body(base_.q_enu_from_body);
  out.ref_p_enu_m = base_.p_enu_m;
}

bool Simulator::next(Sample& out) {
  if (samples_ >= total_) return false;
  const std::uint64_t out_step = samples_ * static_cast<std::uint64_t>(steps_per_sample_);
  while (step_ < out_step) physics_step(false);
  physics_step(true);
  fill_sample(out);
  ++samples_;
  return true;
}

SimulateResult simulate_to_log(const Scenario& scenario, const std::filesystem::path& log_path,
                               const std::function<bool(double)>& keep_going, SimOptions options) {
  Simulator sim(scenario, options);
  log::LogWriter writer(log_path, sim.metadata(), Simulator::fields());
  SimulateResult r;
  Sample s;
  const std::uint64_t poll = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(scenario.sample_rate_hz / 10));
  bool stopped = false;
  while (sim.next(s)) {
    writer.write(s);
    if (keep_going && sim.samples_done() % poll == 0 &&
        !keep_going(static_cast<double>(sim.samples_done()) / static_cast<double>(sim.total_samples()))) {
      stopped = true;
      break;
    }
  }
  r.rows = writer.rows_written();
  r.physics_steps = sim.physics_steps();
  r.complete = !stopped;
  writer.finish(r.complete, stopped ? "stopped by the user before the end of the run" : "");
  return r;
}

void pose_world_from_sample(World& world, const Sample& s, Carrier carrier) {
  const Eigen::Quaterniond q = s.ref_q_wxyz.allFinite() ? s.q_enu_from_body().normalized()
                                                       : Eigen::Quaterniond::Identity();
  const Eigen::Vector3d p = s.ref_p_enu_m.allFinite() ? s.ref_p_enu_m : Eigen::Vector3d(0, 0, 0.772);
  auto angle = [](double truth_deg, double known_deg) {
    if (std::isfinite(truth_deg)) return truth_deg * kRadPerDeg;
    if (std::isfinite(known_deg)) return known_deg * kRadPerDeg;
    return 0.0;
  };
  world.pose(p, q, angle(s.true_plat1_deg, s.plat1_deg), angle(s.true_plat2_deg, s.plat2_deg), carrier);
}

}  // namespace driftless::twin
