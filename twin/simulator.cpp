#include "twin/simulator.hpp"

#include "estimator/background_writer.hpp"
#include "estimator/geometry.hpp"
#include "estimator/random.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "estimator/log_metadata.hpp"

namespace driftless::twin {
namespace {

// platforms settle on their stops for this long before t = 0, s
constexpr double kWarmupS = 1.0;

std::unique_ptr<Motion> required(std::unique_ptr<Motion> motion) {
  if (!motion) throw std::invalid_argument("simulator: no motion given");
  return motion;
}

}  // namespace

Simulator::Simulator(const Scenario& scenario, SimOptions options)
    : Simulator(scenario, make_motion((scenario.validate(), scenario.motion), scenario.duration_s, scenario.seed, scenario.base_dir),
                motion_type_name(scenario.motion.type), options) {}

Simulator::Simulator(const Scenario& scenario, std::unique_ptr<Motion> motion, std::string motion_name,
                     SimOptions options)
    : scenario_((scenario.validate(), scenario)),
      options_(options),
      world_(scenario.model.box, scenario.physics_dt_s, ModelScope::physics),
      motion_(required(std::move(motion))),
      motion_name_(std::move(motion_name)),
      flips_(scenario.flip_schedule, scenario.model.box, options.initial_sign),
      gate_(scenario.model.box, motion_->is_static(), scenario.sample_rate_hz),
      earth_enu_radps_(geo::earth_rate_enu_radps(scenario.latitude_deg)),
      delay_(scenario.model.time_offset_s, scenario.sample_rate_hz),
      steps_per_sample_(scenario.steps_per_sample()),
      total_(scenario.total_samples()) {
  if (options.initial_sign != std::array<int, 2>{1, 1} && !options.external_flips) {
    throw std::invalid_argument("simulator: platforms starting anywhere but (+,+) need external flip control "
                                "(the flip schedule's eq. (5) sequence starts at (+,+))");
  }
  if (options.external_flips) flips_.take_external_control();
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
  // settle the platforms on their stops before t = 0 (the box held still at its t = 0 pose), so
  // the run starts at rest rather than with the stops' initial transient
  MotionState held = m0;
  held.v_enu_mps = held.a_enu_mps2 = held.w_body_radps = held.dw_body_radps2 = Eigen::Vector3d::Zero();
  const Eigen::Vector2d ref0(flips_.reference_rad(1), flips_.reference_rad(2));
  const long warmup_steps = std::lround(kWarmupS / scenario.physics_dt_s);
  for (long n = 0; n < warmup_steps; ++n) {
    const double t = static_cast<double>(n - warmup_steps) * scenario.physics_dt_s;
    gate_.observe(t, world_.step_driven(t, held, ref0, false));
  }
  world_.data()->time = 0.0;
  world_.set_base(m0.p_enu_m, m0.q_enu_from_body, m0.v_enu_mps, m0.w_body_radps);
  mj_forward(world_.model(), world_.data());
  // the base starts moving at t = 0 (a jolt from the held warm-up pose): MuJoCo steps its transient
  if (!motion_->is_static()) {
    for (int i = 1; i <= 2; ++i) gate_.disturbed(i, 0.0);
  }
}

Simulator::~Simulator() = default;

std::uint32_t Simulator::fields() {
  return kFieldAccel | kFieldTemp | kFieldRefQ | kFieldRefP | kFieldTrueBias | kFieldTrueRate | kFieldTruePlat;
}

log::Metadata Simulator::metadata() const {
  log::LogInfo info;
  info.sample_rate_hz = scenario_.sample_rate_hz;
  info.latitude_deg = scenario_.latitude_deg;
  info.hinge1_axis = scenario_.model.box.hinge_axis(1);
  info.hinge2_axis = scenario_.model.box.hinge_axis(2);
  info.source = "twin";
  info.scenario = scenario_.name;
  info.seed = scenario_.seed;
  info.duration_s = scenario_.duration_s;
  info.motion = motion_name_;
  info.carrier = carrier_name(motion_->carrier());
  info.platform_readback = readback_name(scenario_.platform_readback);
  info.flip_angle_deg = scenario_.flip_schedule.flip_angle_deg;
  info.standstill_s = scenario_.flip_schedule.standstill_s;
  if (flips_.external_control()) info.flip_control = "external";
  info.end_stop_deg = scenario_.model.box.end_stop_deg;
  info.sensor1_preset = scenario_.model.sensor1.preset;
  info.sensor2_preset = scenario_.model.sensor2.preset;
  log::Metadata m;
  log::write_log_info(m, info);
  return m;
}

void Simulator::take_flip_control() { flips_.take_external_control(); }

void Simulator::command_platform(int i, int sign) {
  if (i != 1 && i != 2) throw std::invalid_argument("command_platform: platform must be 1 or 2, got " + std::to_string(i));
  if (sign != 1 && sign != -1) throw std::invalid_argument("command_platform: sign must be +1 or -1, got " + std::to_string(sign));
  if (!flips_.external_control()) {
    throw std::invalid_argument("command_platform: the scenario's flip schedule drives the servos (call take_flip_control() first)");
  }
  // the move starts at the next physics step; the rest path hands over to MuJoCo there
  flips_.command(i, sign, static_cast<double>(step_) * scenario_.physics_dt_s);
}

double Simulator::output_time_s(std::uint64_t sample) const {
  return static_cast<double>(sample * static_cast<std::uint64_t>(steps_per_sample_)) * scenario_.physics_dt_s;
}

// the first physics step whose time t = step * dt is >= t_s (the schedule's own test), at or
// after the current step
std::uint64_t Simulator::first_step_at(double t_s) const {
  const double dt = scenario_.physics_dt_s;
  if (!(t_s < static_cast<double>(total_ * static_cast<std::uint64_t>(steps_per_sample_)) * dt)) return ~std::uint64_t{0};
  auto n = static_cast<std::uint64_t>(std::max(0.0, std::ceil(t_s / dt)));
  while (n > 0 && static_cast<double>(n - 1) * dt >= t_s) --n;
  while (static_cast<double>(n) * dt < t_s) ++n;
  return std::max(n, step_);
}

// one physics step at t = step_ * dt: the flip schedule, then MuJoCo, the rest path or a replay
void Simulator::advance(bool output) {
  const double t = static_cast<double>(step_) * scenario_.physics_dt_s;
  Eigen::Vector2d rates = Eigen::Vector2d::Zero();
  if (mode_ == Mode::stepped) rates = {world_.platform_rate_radps(1), world_.platform_rate_radps(2)};
  if (mode_ == Mode::replay) rates[replay_->platform - 1] = replay_->steps[replay_pos_].rate_radps;
  flips_.update(t, rates);
  if (mode_ == Mode::rest && flips_.any_moving()) begin_flip(t);
  if (mode_ == Mode::replay && (flips_.moving(3 - replay_->platform) || flips_.sign(replay_->platform) != replay_->sign)) {
    // a command the recording never saw: MuJoCo takes over from the replayed state
    const FlipReplay::Step& s = replay_->steps[replay_pos_];
    rest_angle_rad_[replay_->platform - 1] = s.angle_rad;
    double rate[2] = {0, 0};
    rate[replay_->platform - 1] = s.rate_radps;
    thaw(rate);
  }
  switch (mode_) {
    case Mode::rest: if (output) rest_output(t); break;
    case Mode::replay: replay_step(t, output); break;
    case Mode::stepped: step_physics(t, output); break;
  }
  ++step_;
}

// a flip starts from the rest path: replay it when a static box saw this flip before, else let
// MuJoCo step it (and record it, on a static box)
void Simulator::begin_flip(double) {
  const int moving = flips_.moving(1) && flips_.moving(2) ? 0 : (flips_.moving(1) ? 1 : 2);
  if (!gate_.static_base() || moving == 0) {
    thaw();
    return;
  }
  const int sign = flips_.sign(moving);
  replay_ = replays_.find(moving, sign, rest_angle_rad_[moving - 1]);
  if (replay_ != nullptr) {
    mode_ = Mode::replay;
    replay_pos_ = 0;
    return;
  }
  thaw();
  replays_.start_recording(moving, sign, rest_angle_rad_[moving - 1]);
}

void Simulator::step_physics(double t, bool output) {
  const MotionState ms = motion_->at(t);
  const HingeState h = world_.step_driven(t, ms, Eigen::Vector2d(flips_.reference_rad(1), flips_.reference_rad(2)), output);
  ++mj_steps_;
  gate_.observe(t, h);
  if (const int i = replays_.recording_platform()) {
    if (flips_.moving(3 - i) || flips_.sign(i) != replays_.recording_sign()) {
      replays_.stop_recording(false);  // the other platform moves too, or a reversal: not one flip
    } else {
      replays_.record({h.angle_rad[i - 1], h.rate_radps[i - 1], world_.platform_accel_radps2(i)});
    }
  }
  if (!output) return;
  base_ = ms;
  truth_.t_s = t;
  for (int i = 0; i < 2; ++i) {
    truth_.plat_rad[i] = h.angle_rad[i];
    truth_.plat_rate_radps[i] = h.rate_radps[i];
  }
  capture_truth();
  if (options_.fast_rest) try_rest(ms, h, t);
}

// after a stepped output sample: rest from here on if the platforms settled and the coming
// interval's loads keep them on their stops
void Simulator::try_rest(const MotionState& base, const HingeState& hinge, double t) {
  const double accel[2] = {world_.platform_accel_radps2(1), world_.platform_accel_radps2(2)};
  if (flips_.any_moving() || !gate_.settled(t, hinge, accel)) return;
  if (!gate_.holds(world_, flips_, base, base_at_output(samples_ + 1), hinge.angle_rad)) return;
  replays_.stop_recording(true);
  enter_rest(hinge.angle_rad);
}

void Simulator::enter_rest(const double angle_rad[2]) {
  for (int i = 0; i < 2; ++i) rest_angle_rad_[i] = angle_rad[i];
  mode_ = Mode::rest;
  if (gate_.static_base()) {
    const double zero[2] = {0, 0};
    rest_truth(base_, rest_angle_rad_, zero, zero);
    static_rest_truth_ = truth_;
  }
}

const MotionState& Simulator::base_at_output(std::uint64_t sample) {
  if (next_base_sample_ != sample) {
    next_base_ = motion_->at(output_time_s(sample));
    next_base_sample_ = sample;
  }
  return next_base_;
}

// an output sample on the rest path: the base from the motion, the platforms rigid on their stops
void Simulator::rest_output(double t) {
  if (gate_.static_base()) {
    truth_ = static_rest_truth_;
    truth_.t_s = t;
    return;
  }
  base_ = base_at_output(samples_);
  const double zero[2] = {0, 0};
  rest_truth(base_, rest_angle_rad_, zero, zero);
  truth_.t_s = t;
  // the next interval: stay on the rest path, or step MuJoCo through it from the rigid state
  if (!gate_.holds(world_, flips_, base_, base_at_output(samples_ + 1), rest_angle_rad_)) {
    thaw();
    for (int i = 1; i <= 2; ++i) gate_.disturbed(i, output_time_s(samples_ + 1));
  }
}

// one step of a replayed flip; where the recording came to rest, so does the replay
void Simulator::replay_step(double t, bool output) {
  const int k = replay_->platform - 1;
  const FlipReplay::Step& s = replay_->steps[replay_pos_];
  double angle[2] = {rest_angle_rad_[0], rest_angle_rad_[1]}, rate[2] = {0, 0}, accel[2] = {0, 0};
  angle[k] = s.angle_rad;
  rate[k] = s.rate_radps;
  accel[k] = s.accel_radps2;
  if (output) {
    rest_truth(base_, angle, rate, accel);
    truth_.t_s = t;
  }
  if (++replay_pos_ < replay_->steps.size()) return;
  rest_angle_rad_[k] = s.angle_rad;
  if (flips_.any_moving()) {
    thaw(rate);  // the schedule's settle test has not passed here: MuJoCo continues
  } else {
    enter_rest(rest_angle_rad_);
  }
}

// leaves the rest path or a replay: MuJoCo continues from the platforms at their rest angles
// (and the given rates, rad/s; at rest by default)
void Simulator::thaw(const double rate_radps[2]) {
  for (int i = 1; i <= 2; ++i) world_.set_platform(i, rest_angle_rad_[i - 1], rate_radps ? rate_radps[i - 1] : 0.0);
  mode_ = Mode::stepped;
  replay_ = nullptr;
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

// truth off MuJoCo: the rigid-body kinematics of each sensor site on the base, the hinges at the
// given angles (rad), rates (rad/s) and accelerations (rad/s^2)
void Simulator::rest_truth(const MotionState& base, const double angle_rad[2], const double rate_radps[2],
                           const double accel_radps2[2]) {
  const Eigen::Vector3d earth_body = base.q_enu_from_body.normalized().conjugate() * earth_enu_radps_;
  for (int i = 0; i < 2; ++i) {
    const SiteMotion sm = world_.site_motion(i + 1, base, angle_rad[i], rate_radps[i], accel_radps2[i]);
    truth_.w_sensor_radps[i] = sm.w_radps + sm.R_body_from_sensor.transpose() * earth_body;
    truth_.f_sensor_mps2[i] = sm.f_mps2;
    truth_.plat_rad[i] = angle_rad[i];
    truth_.plat_rate_radps[i] = rate_radps[i];
  }
  truth_.w_body_radps = base.w_body_radps + earth_body;
}

void Simulator::fill_sample(Sample& out) {
  out = Sample{};
  out.t_s = truth_.t_s;
  // the sensor-effect catalogue turns the truth into readings (docs/effects.md)
  // model.time_offset_s: the sensors sampled the truth of `offset` earlier
  Eigen::Vector3d w_in[2] = {truth_.w_sensor_radps[0], truth_.w_sensor_radps[1]};
  Eigen::Vector3d f_in[2] = {truth_.f_sensor_mps2[0], truth_.f_sensor_mps2[1]};
  delay_.apply(w_in, f_in);
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
  while (step_ < out_step) {
    // on the rest path nothing happens until the schedule starts the next flip
    if (mode_ == Mode::rest) step_ = std::min(out_step, first_step_at(flips_.next_flip_s()));
    if (step_ < out_step) advance(false);
  }
  advance(true);
  fill_sample(out);
  ++samples_;
  return true;
}

SimulateResult simulate_to_log(const Scenario& scenario, const std::filesystem::path& log_path,
                               const std::function<bool(double)>& keep_going, SimOptions options) {
  Simulator sim(scenario, options);
  log::LogWriter writer(log_path, sim.metadata(), Simulator::fields());
  const std::uint64_t poll = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(scenario.sample_rate_hz / 10));
  constexpr std::size_t kBlock = 1024;
  bool stopped = false;
  {
    // the log is formatted and written on a second thread while the simulation runs (same bytes as
    // written inline; two blocks in memory at most)
    io::BackgroundWriter<Sample> background(
        [&writer](const std::vector<Sample>& block) {
          for (const Sample& b : block) writer.write(b);
        },
        kBlock);
    Sample s;
    while (sim.next(s)) {
      background.push(s);
      if (keep_going && sim.samples_done() % poll == 0 &&
          !keep_going(static_cast<double>(sim.samples_done()) / static_cast<double>(sim.total_samples()))) {
        stopped = true;
        break;
      }
    }
    background.finish();
  }
  SimulateResult r;
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
