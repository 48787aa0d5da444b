// The simulator: steps the MuJoCo box along its motion and flip schedule and produces one
// Sample (file units, true_ columns included) per output period; simulate_to_log() streams a run
// into a driftless log. Truth: MuJoCo's gyro/accelerometer sites plus the Earth rate, added
// analytically (MuJoCo's world is the non-rotating local ENU frame).
#pragma once

#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "estimator/log.hpp"
#include "estimator/sample.hpp"
#include "twin/flip_schedule.hpp"
#include "twin/motion.hpp"
#include "twin/scenario.hpp"
#include "twin/sensor/sensor_model.hpp"
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

/// Simulator switches (not part of the scenario: they change speed, never results beyond 1e-9).
struct SimOptions {
  /// Skip MuJoCo steps while the box is static and both platforms have settled (state constant,
  /// truth analytic); physics runs through every flip and whenever the base moves.
  bool fast_standstill = true;
};

/// A running simulation of one scenario.
class Simulator {
 public:
  explicit Simulator(const Scenario& scenario, SimOptions options = {});
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
  /// The MuJoCo world (model and data at the last sample's physics state) for rendering.
  World& world() { return world_; }
  const World& world() const { return world_; }

  std::uint64_t samples_done() const { return samples_; }
  std::uint64_t total_samples() const { return total_; }
  /// MuJoCo steps taken so far (physics steps skipped on the static fast path are not counted).
  std::uint64_t physics_steps() const { return mj_steps_; }

  /// Metadata for a log of this run (sample rate, latitude, hinge axes, seed, scenario, carrier).
  log::Metadata metadata() const;
  /// Optional log fields this simulator fills.
  static std::uint32_t fields();

 private:
  void physics_step(bool output);
  void capture_truth();
  void fill_sample(Sample& out);

  Scenario scenario_;
  SimOptions options_;
  World world_;
  std::unique_ptr<Motion> motion_;
  FlipController flips_;
  std::vector<SensorModel> sensors_;  // sensor 1, sensor 2
  Eigen::Vector3d earth_enu_radps_;
  long steps_per_sample_;
  std::uint64_t total_;
  std::uint64_t samples_ = 0;
  std::uint64_t step_ = 0;       // next physics step index (t = step * dt)
  std::uint64_t mj_steps_ = 0;
  bool frozen_ = false;          // static fast path active
  SampleTruth truth_;
  SampleTruth frozen_truth_;
  MotionState base_;             // motion state at the last output sample
  std::deque<SampleTruth> history_;  // recent output truths (model.time_offset_s > 0)
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
