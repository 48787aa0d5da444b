// The kinematic rest path's two decisions (docs/model.md, "How the simulator saves time"): when a
// platform has settled after a disturbance, and whether the base's loads over the next output
// interval keep both platforms rigidly on their stops. While they do, the simulator skips MuJoCo
// and takes the truth from the rigid-body kinematics of the base motion (World::site_motion).
#pragma once

#include "twin/flip_schedule.hpp"
#include "twin/motion.hpp"
#include "twin/world.hpp"

namespace driftless::twin {

/// Slowest decay time of MuJoCo's soft end stop (solref time constant and damping ratio), s: the
/// envelope decays at 1/timeconst when underdamped; an overdamped stop's slow root is slower.
double stop_decay_time_s(const BoxParams& box);

class RestGate {
 public:
  /// `static_base`: the box never moves; `sample_rate_hz`: the output interval the look-ahead spans.
  RestGate(const BoxParams& box, bool static_base, double sample_rate_hz);

  /// Platform i (1 or 2) was disturbed at t_s (a base jolt, the base starting to move at t = 0).
  void disturbed(int i, double t_s) { loud_s_[i - 1] = t_s; }
  /// Watches the hinge state of every MuJoCo step at t_s: a platform moving faster than 1e-3 rad/s
  /// relative to the box (a flip, a landing, a bounce) is disturbed.
  void observe(double t_s, const HingeState& hinge);

  /// Both platforms have settled at t_s: each has moved slower than 1e-3 rad/s for 25 stop decay
  /// times (any transient is down by e^-25 since), and on a static box they are below 1e-10 rad/s
  /// and 1e-7 rad/s^2 (`accel_radps2` from MuJoCo).
  bool settled(double t_s, const HingeState& hinge, const double accel_radps2[2]) const;

  /// The rigid rest holds from output sample `a` to the next, `b`, with the platforms at
  /// `angle_rad`: at both ends each platform's inertial load stays within half the motor's press
  /// (it neither lifts off nor sinks into the compliant stop by more than half its static
  /// penetration), and no jolt (a base rate step inside the interval) kicks it. Always true on a
  /// static box; never on a moving one when the servos hold the platforms off their stops.
  bool holds(const World& world, const FlipController& flips, const MotionState& a, const MotionState& b,
             const double angle_rad[2]) const;

  bool static_base() const { return static_base_; }
  double settle_time_s() const { return settle_s_; }

 private:
  bool static_base_;
  double dt_out_s_;
  double settle_s_;
  double loud_s_[2] = {-kNoTime, -kNoTime};  // last time platform i moved or was disturbed, s
  static constexpr double kNoTime = 1e300;
  // the platforms' loads at the last interval's end `b`, N m: the next interval starts there
  struct EndLoad {
    MotionState base;
    double angle_rad[2] = {0, 0};
    double torque_nm[2] = {0, 0};
    bool valid = false;
  };
  mutable EndLoad end_load_;
};

}  // namespace driftless::twin
