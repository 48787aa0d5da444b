// The simulator: steps the MuJoCo box along its motion and flip schedule and produces one
// Sample (file units, true_ columns included) per output period; simulate_to_log() streams a run
// into a driftless log. Truth: MuJoCo's gyro/accelerometer sites plus the Earth rate, added
// analytically (MuJoCo's world is the non-rotating local ENU frame).
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "estimator/log.hpp"
#include "estimator/sample.hpp"
#include "twin/flip_replay.hpp"
#include "twin/flip_schedule.hpp"
#include "twin/motion.hpp"
#include "twin/rest_path.hpp"
#include "twin/scenario.hpp"
#include "twin/sensor/sensor_model.hpp"
#include "twin/truth_delay.hpp"
#include "twin/world.hpp"

namespace driftless::twin {

/// Truth behind one sample, in code units.
struct SampleTruth {
  double t_s = 0;
  Eigen::Vector3d w_sensor_radps[2];   // inertial rate of sensor frame i in its axes (Earth incl.)
  Eigen::Vector3d f_sensor_mps2[2];    // specific force at sensor i in its axes
  Eigen::Vector3d w_body_radps;        // box inertial rate in box axes (Earth incl.)
  double plat_rad[2] = {0, 0};         // joint angles
  double plat_rate_radps[2] = {0, 0};  // joint rates
};

/// Simulator switches (not part of the scenario: they change speed; the differences they make are
/// bounded in tests/twin/test_simulator.cpp and docs/model.md).
struct SimOptions {
  /// The kinematic rest path: while both platforms rest settled on their stops (or, on a static
  /// box, wherever they settled), skip MuJoCo and take the truth from the rigid-body kinematics
  /// of the base motion; MuJoCo steps every flip, its settling, and every base load that could
  /// lift a platform off its stop. false: MuJoCo steps the whole run.
  bool fast_rest = true;
  /// The platforms answer to an outside commander from the start (command_platform(); as after
  /// take_flip_control(), but before the warm-up): the scenario's flip schedule never runs.
  bool external_flips = false;
  /// The rest side each platform starts (and warms up) on, +1 / -1; anything but (+,+) needs
  /// external_flips (the schedule's eq. (5) sequence starts at (+,+)).
  std::array<int, 2> initial_sign = {1, 1};
};

/// A running simulation of one scenario.
class Simulator {
 public:
  explicit Simulator(const Scenario& scenario, SimOptions options = {});
  /// A run along an outside motion (the calibration rig's rate table) instead of the scenario's
  /// `motion:` block; `motion_name` is logged as the log's `motion`.
  Simulator(const Scenario& scenario, std::unique_ptr<Motion> motion, std::string motion_name,
            SimOptions options = {});
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  /// Advances to the next output sample and fills `out`; false once the duration is reached.
  bool next(Sample& out);
  /// Truth of the last sample (rad/s, m/s^2).
  const SampleTruth& truth() const { return truth_; }
  /// Sensor model i (1 or 2): its parameters and this run's drawn instance.
  const SensorModel& sensor(int i) const { return sensors_[i - 1]; }

  const Scenario& scenario() const { return scenario_; }
  const Motion& motion() const { return *motion_; }
  const FlipController& flips() const { return flips_; }
  /// Hands the platform servos to an outside commander (the HIL bridge's motors): the scenario's
  /// flip schedule stops; command_platform() starts the flips. Logged as flip_control: external.
  void take_flip_control();
  /// Drives platform i (1 or 2) toward its rest angle of sign `sign` (+1 / -1), starting at the
  /// next physics step. Throws std::invalid_argument on a bad platform or sign, or without
  /// take_flip_control() first.
  void command_platform(int i, int sign);
  /// The MuJoCo world (physics scope: no carriers; renders pose their own full World). Its data
  /// holds the last stepped state (the kinematic rest path leaves it untouched).
  World& world() { return world_; }
  const World& world() const { return world_; }

  std::uint64_t samples_done() const { return samples_; }
  std::uint64_t total_samples() const { return total_; }
  /// MuJoCo steps taken so far (steps on the kinematic rest path are not counted).
  std::uint64_t physics_steps() const { return mj_steps_; }

  /// Metadata for a log of this run (sample rate, latitude, hinge axes, seed, scenario, carrier).
  log::Metadata metadata() const;
  /// Optional log fields this simulator fills.
  static std::uint32_t fields();

 private:
  enum class Mode { stepped, rest, replay };
  void advance(bool output);
  void step_physics(double t, bool output);
  void rest_output(double t);
  void replay_step(double t, bool output);
  void begin_flip(double t);
  void try_rest(const MotionState& base, const HingeState& hinge, double t);
  void enter_rest(const double angle_rad[2]);
  const MotionState& base_at_output(std::uint64_t sample);
  double output_time_s(std::uint64_t sample) const;  // t of output sample k: its physics step's t
  std::uint64_t first_step_at(double t_s) const;
  void thaw(const double rate_radps[2] = nullptr);
  void capture_truth();
  void rest_truth(const MotionState& base, const double angle_rad[2], const double rate_radps[2],
                  const double accel_radps2[2]);
  void fill_sample(Sample& out);

  Scenario scenario_;
  SimOptions options_;
  World world_;
  std::unique_ptr<Motion> motion_;
  std::string motion_name_;
  FlipController flips_;
  RestGate gate_;
  FlipReplay replays_;
  std::vector<SensorModel> sensors_;  // sensor 1, sensor 2
  Eigen::Vector3d earth_enu_radps_;
  TruthDelay delay_;             // model.time_offset_s
  long steps_per_sample_;
  std::uint64_t total_;
  std::uint64_t samples_ = 0;
  std::uint64_t step_ = 0;       // next physics step index (t = step * dt)
  std::uint64_t mj_steps_ = 0;
  Mode mode_ = Mode::stepped;
  double rest_angle_rad_[2] = {0, 0};    // hinge angles on the rest path and during a replay
  const FlipReplay::Flip* replay_ = nullptr;  // the flip being replayed, and where in it
  std::size_t replay_pos_ = 0;
  SampleTruth truth_;
  SampleTruth static_rest_truth_;        // a static box at rest: the truth is constant
  MotionState base_;             // motion state at the last output sample
  MotionState next_base_;        // look-ahead: motion state at an output sample
  std::uint64_t next_base_sample_ = ~std::uint64_t{0};
};

/// Result of simulate_to_log().
struct SimulateResult {
  std::uint64_t rows = 0;
  bool complete = false;
  std::uint64_t physics_steps = 0;
};

/// Streams a whole run into `log_path` at constant memory. `keep_going(fraction)` is polled
/// about 10 times per simulated second; returning false stops the run and leaves a valid log
/// marked complete: false.
SimulateResult simulate_to_log(const Scenario& scenario, const std::filesystem::path& log_path,
                               const std::function<bool(double)>& keep_going = {},
                               SimOptions options = {});

/// Poses `world` from a logged sample (ref_q, ref_p, platform angles: true_ if present, else the
/// known ones) with the given carrier, for replay and rendering.
void pose_world_from_sample(World& world, const Sample& s, Carrier carrier);

}  // namespace driftless::twin
