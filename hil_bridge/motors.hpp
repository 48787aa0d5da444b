// Platform motors and their end-stop switches, and the flip schedule that drives them.
// Back ends: EmulatedMotors (kinematic, for the emulators), SerialMotors (serial/serial_motors.hpp:
// the microcontroller drives the real motors), and the twin's MuJoCo actuators (twin/).
#pragma once

#include <array>
#include <string>

#include "hil_bridge/clock.hpp"
#include "hil_bridge/source.hpp"

namespace driftless::hil {

/// Which end-stop switch of a platform is closed.
enum class EndStop { kNone, kMinus, kPlus };  // kNone: moving or between the stops

/// Platform angle the system knows from its switches: +-stop_deg at a stop, NaN while moving.
double known_angle_deg(EndStop s, double stop_deg = 90.0);

/// The two platform motors.
class Motors {
 public:
  virtual ~Motors() = default;
  virtual std::string name() const = 0;
  /// Starts platform `platform` (1 or 2) toward its end stop of sign `sign` (-1 or +1).
  virtual Status command(int platform, int sign) = 0;
  /// The switches as last known.
  virtual EndStop end_stop(int platform) const = 0;
};

/// Kinematic motors for the emulators: constant speed between the stops, switches closed within
/// `switch_window_deg` of +-stop_deg. Time comes from `clock`.
class EmulatedMotors final : public Motors {
 public:
  struct Params {
    double speed_dps = 90.0;          // platform speed while moving, deg/s
    double stop_deg = 90.0;           // end-stop angle, deg
    double switch_window_deg = 0.5;   // a switch closes this close to its stop, deg
    std::array<double, 2> start_deg{90.0, 90.0};
    void validate() const;
  };
  EmulatedMotors(const Clock& clock, Params p);
  std::string name() const override { return "emulated"; }
  Status command(int platform, int sign) override;
  EndStop end_stop(int platform) const override;
  /// True angle, deg, and rate, deg/s, of a platform at time t_s (for the sensor generator).
  double angle_deg(int platform, double t_s) const;
  double rate_dps(int platform, double t_s) const;

 private:
  struct Move {
    double from_deg, to_deg, t0_s;
  };
  const Clock& clock_;
  Params p_;
  std::array<Move, 2> moves_;
};

/// Cycles the platforms through eq. (5)'s positions (geo::kFlipCycle: (+,+) -> (+,-) -> (-,-) ->
/// (-,+) -> (+,+)...): one platform moves at a time and every position is held for standstill_s
/// (the paper's k = 4n..4n+3), in the same order as the twin's servos and the filter's paper mode.
class FlipSchedule {
 public:
  struct Params {
    double standstill_s = 10.0;  // hold at each position after both stops are reached, s
    double move_timeout_s = 10.0;  // a move that has not reached its stop by then is a fault, s
    void validate() const;
  };
  explicit FlipSchedule(Params p);
  /// Advances the schedule at time t_s; returns false (and fills `fault`) when a move timed out.
  bool update(double t_s, Motors& motors, std::string* fault = nullptr);
  /// Index of the current position in the 4-cycle.
  int phase() const { return phase_; }

 private:
  Params p_;
  int phase_ = 0;
  bool moving_ = false;
  double since_s_ = kNaN;  // arrival time at the current position (or start of the move)
};

}  // namespace driftless::hil
