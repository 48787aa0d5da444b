// The flip schedule of the paper's Fig. 3 and the motor reference that executes it:
// (+,+) -> (+,-) -> (-,-) -> (-,+) -> (+,+) -> ..., one platform moving at a time, each move
// followed by a standstill. The controller commands the piezo servo (twin/world.hpp, motor_i)
// along a speed- and acceleration-limited (trapezoidal) reference.
#pragma once

#include <array>

#include <Eigen/Core>

#include "twin/world.hpp"

namespace driftless::twin {

/// The scenario's `flip_schedule:` block.
struct FlipScheduleParams {
  bool enabled = true;              // false: both platforms stay at (+,+) for the whole run
  double standstill_s = 20.0;       // rest between flips, counted from the moment of settling, s
  double flip_angle_deg = 90.0;     // platform rest angles are +/- this, deg (0 < a <= end stop);
                                    // equal to the end stop: the motor drives onto the stops
  double settle_rate_dps = 0.01;    // a platform counts as settled below this rate, deg/s
  /// Throws std::invalid_argument naming the field; `end_stop_deg` bounds flip_angle_deg.
  void validate(double end_stop_deg) const;
};

/// Trapezoidal motion reference from one angle to another (speed and acceleration limited).
class TrapezoidProfile {
 public:
  TrapezoidProfile() = default;
  /// Starts at t0 (s) from `from_rad` to `to_rad` with limits vmax (rad/s), amax (rad/s^2).
  TrapezoidProfile(double t0_s, double from_rad, double to_rad, double vmax_radps, double amax_radps2);
  double angle_rad(double t_s) const;
  double end_s() const { return t0_ + 2 * t_acc_ + t_cruise_; }
  double target_rad() const { return to_; }

 private:
  double t0_ = 0, from_ = 0, to_ = 0, dir_ = 1, v_ = 0, a_ = 1, t_acc_ = 0, t_cruise_ = 0;
};

/// Runs the schedule: decides when which platform flips, produces the motor references and
/// knows the platform angles as the system does (the commanded rest angle, unknown while moving).
class FlipController {
 public:
  /// `initial_sign`: the rest side each platform starts on (+1 / -1; the schedule's eq. (5)
  /// sequence starts at (+,+), so another start needs take_external_control(): the calibration
  /// rig's first segments rest at (-,-)). Throws std::invalid_argument on a sign other than +-1.
  FlipController(const FlipScheduleParams& p, const BoxParams& box, std::array<int, 2> initial_sign = {1, 1});

  /// Advances to time t (s) given the platforms' current rates (rad/s, index 0 = platform 1).
  /// Call once per physics step with non-decreasing t.
  void update(double t_s, const Eigen::Vector2d& plat_rate_radps);

  /// Servo reference of platform i (1 or 2), rad.
  double reference_rad(int i) const;
  /// Rest angle the system commands for platform i (1 or 2): +/- flip angle, rad.
  double commanded_rest_rad(int i) const { return sign_[i - 1] * flip_rad_; }
  /// True while platform i moves or has not settled after a move.
  bool moving(int i) const { return moving_[i - 1]; }
  bool any_moving() const { return moving_[0] || moving_[1]; }
  /// Signs of the current (or, while moving, the target) rest angles, +1/-1 each.
  int sign(int i) const { return sign_[i - 1]; }
  /// Time the next flip starts, s (infinity when the schedule is disabled).
  double next_flip_s() const { return next_flip_s_; }
  /// Completed flips.
  long flips() const { return flips_; }
  /// True when the platforms rest on their end stops (flip angle = end stop), pressed by the motor.
  bool on_stops() const { return on_stops_; }
  /// Initial platform angle (rad) for platform i: on its initial stop, or at +-flip angle.
  double initial_angle_rad(int i) const;

  /// Hands the flips to an outside commander (the HIL bridge's motor interface): from now on
  /// the schedule no longer starts flips by itself; command() does.
  void take_external_control();
  bool external_control() const { return external_; }
  /// Starts platform i (1 or 2) at t_s toward its rest angle of sign `sign` (+1 or -1) along the
  /// same speed/acceleration-limited profile; a move already heading there is left alone.
  /// A reversal mid-move restarts the profile from the current reference.
  void command(int i, int sign, double t_s);

 private:
  double target_for(int i, int sign) const;
  std::array<int, 2> initial_sign_;

  FlipScheduleParams p_;
  BoxParams box_;
  double flip_rad_;
  bool on_stops_;             // flip angle == end stop: drive onto the stops
  int sign_[2] = {1, 1};
  bool moving_[2] = {false, false};
  TrapezoidProfile profile_[2];
  double ref_[2] = {0, 0};
  double next_flip_s_;
  long flips_ = 0;            // completed flips; the next flip moves platform 2 when even
  bool external_ = false;     // flips come from command(), not from the schedule
};

}  // namespace driftless::twin
