#include "hil_bridge/motors.hpp"

#include "estimator/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace driftless::hil {

double known_angle_deg(EndStop s, double stop_deg) {
  switch (s) {
    case EndStop::kPlus: return stop_deg;
    case EndStop::kMinus: return -stop_deg;
    case EndStop::kNone: return kNaN;
  }
  return kNaN;
}

void EmulatedMotors::Params::validate() const {
  if (!(speed_dps > 0.0)) throw std::invalid_argument("motors: speed_dps must be > 0 deg/s");
  if (!(stop_deg > 0.0 && stop_deg <= 180.0)) {
    throw std::invalid_argument("motors: stop_deg must be in (0, 180] deg");
  }
  if (!(switch_window_deg > 0.0)) throw std::invalid_argument("motors: switch_window_deg must be > 0 deg");
}

EmulatedMotors::EmulatedMotors(const Clock& clock, Params p) : clock_(clock), p_(p) {
  p_.validate();
  const double t = clock_.now_s();
  for (int i = 0; i < 2; ++i) moves_[static_cast<std::size_t>(i)] = {p_.start_deg[static_cast<std::size_t>(i)], p_.start_deg[static_cast<std::size_t>(i)], t};
}

Status EmulatedMotors::command(int platform, int sign) {
  if (platform < 1 || platform > 2 || (sign != -1 && sign != 1)) {
    return Status::BadConfig("motors: platform must be 1 or 2 and sign -1 or +1");
  }
  const double t = clock_.now_s();
  auto& m = moves_[static_cast<std::size_t>(platform - 1)];
  m = Move{angle_deg(platform, t), sign * p_.stop_deg, t};
  return Status::Ok();
}

double EmulatedMotors::angle_deg(int platform, double t_s) const {
  const auto& m = moves_[static_cast<std::size_t>(platform - 1)];
  const double travel = std::abs(m.to_deg - m.from_deg);
  const double done = std::clamp(p_.speed_dps * (t_s - m.t0_s), 0.0, travel);
  return m.from_deg + std::copysign(done, m.to_deg - m.from_deg);
}

double EmulatedMotors::rate_dps(int platform, double t_s) const {
  const auto& m = moves_[static_cast<std::size_t>(platform - 1)];
  const double travel = std::abs(m.to_deg - m.from_deg);
  const double dt = t_s - m.t0_s;
  if (dt < 0.0 || p_.speed_dps * dt >= travel) return 0.0;
  return std::copysign(p_.speed_dps, m.to_deg - m.from_deg);
}

EndStop EmulatedMotors::end_stop(int platform) const {
  const double a = angle_deg(platform, clock_.now_s());
  if (std::abs(a - p_.stop_deg) <= p_.switch_window_deg) return EndStop::kPlus;
  if (std::abs(a + p_.stop_deg) <= p_.switch_window_deg) return EndStop::kMinus;
  return EndStop::kNone;
}

void FlipSchedule::Params::validate() const {
  if (!(standstill_s > 0.0)) throw std::invalid_argument("flip schedule: standstill_s must be > 0 s");
  if (!(move_timeout_s > 0.0)) throw std::invalid_argument("flip schedule: move_timeout_s must be > 0 s");
}

FlipSchedule::FlipSchedule(Params p) : p_(p) { p_.validate(); }

namespace {
EndStop stop_of(int sign) { return sign > 0 ? EndStop::kPlus : EndStop::kMinus; }
}  // namespace

bool FlipSchedule::update(double t_s, Motors& motors, std::string* fault) {
  // the stop signs of the current position of eq. (5)'s cycle
  const geo::FlipSigns cur = geo::flip_cycle_at(phase_);
  const int want[2] = {cur.plat1, cur.plat2};
  const bool arrived =
      motors.end_stop(1) == stop_of(want[0]) && motors.end_stop(2) == stop_of(want[1]);
  if (std::isnan(since_s_)) {
    // first call: go to phase 0 if not there yet
    since_s_ = t_s;
    moving_ = !arrived;
    if (moving_) {
      motors.command(1, want[0]);
      motors.command(2, want[1]);
    }
    return true;
  }
  if (moving_) {
    if (arrived) {
      moving_ = false;
      since_s_ = t_s;
    } else if (t_s - since_s_ > p_.move_timeout_s) {
      if (fault) {
        *fault = "platform move to phase " + std::to_string(phase_) + " did not reach its end stop within " +
                 std::to_string(p_.move_timeout_s) + " s";
      }
      since_s_ = t_s;  // report once per time-out, keep waiting
      return false;
    }
    return true;
  }
  if (t_s - since_s_ >= p_.standstill_s) {
    const int next = (phase_ + 1) % 4;
    const int mover = geo::flip_cycle_mover(phase_);  // one platform moves per step
    const geo::FlipSigns to = geo::flip_cycle_at(next);
    motors.command(mover, mover == 1 ? to.plat1 : to.plat2);
    phase_ = next;
    moving_ = true;
    since_s_ = t_s;
  }
  return true;
}

}  // namespace driftless::hil
