#include "twin/flip_schedule.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "estimator/geometry.hpp"
#include "estimator/sample.hpp"

namespace driftless::twin {

void FlipScheduleParams::validate(double end_stop_deg) const {
  if (!(standstill_s > 0 && std::isfinite(standstill_s))) {
    throw std::invalid_argument("flip_schedule.standstill_s must be > 0 s");
  }
  if (!(flip_angle_deg > 0 && flip_angle_deg <= end_stop_deg)) {
    throw std::invalid_argument("flip_schedule.flip_angle_deg must be in (0, end_stop_deg = " +
                                std::to_string(end_stop_deg) + "] deg");
  }
  if (!(settle_rate_dps > 0)) throw std::invalid_argument("flip_schedule.settle_rate_dps must be > 0 deg/s");
}

TrapezoidProfile::TrapezoidProfile(double t0, double from, double to, double vmax, double amax)
    : t0_(t0), from_(from), to_(to), dir_(to >= from ? 1.0 : -1.0), a_(amax) {
  const double d = std::abs(to - from);
  v_ = std::min(vmax, std::sqrt(d * amax));
  t_acc_ = v_ > 0 ? v_ / amax : 0.0;
  t_cruise_ = v_ > 0 ? (d - v_ * v_ / amax) / v_ : 0.0;
}

double TrapezoidProfile::angle_rad(double t) const {
  const double tau = t - t0_;
  if (tau <= 0) return from_;
  if (tau >= 2 * t_acc_ + t_cruise_) return to_;
  const double d_acc = 0.5 * a_ * t_acc_ * t_acc_;
  double s;
  if (tau <= t_acc_) {
    s = 0.5 * a_ * tau * tau;
  } else if (tau <= t_acc_ + t_cruise_) {
    s = d_acc + v_ * (tau - t_acc_);
  } else {
    const double u = tau - t_acc_ - t_cruise_;
    s = d_acc + v_ * t_cruise_ + v_ * u - 0.5 * a_ * u * u;
  }
  return from_ + dir_ * s;
}

FlipController::FlipController(const FlipScheduleParams& p, const BoxParams& box, std::array<int, 2> initial_sign)
    : initial_sign_(initial_sign), p_(p), box_(box), flip_rad_(p.flip_angle_deg * kRadPerDeg),
      on_stops_(std::abs(p.flip_angle_deg - box.end_stop_deg) < 1e-9),
      next_flip_s_(p.enabled ? p.standstill_s : std::numeric_limits<double>::infinity()) {
  p_.validate(box.end_stop_deg);
  for (int i = 1; i <= 2; ++i) {
    const int sign = initial_sign_[i - 1];
    if (sign != 1 && sign != -1) {
      throw std::invalid_argument("flip controller: platform " + std::to_string(i) + " must start at sign +1 or -1, got " +
                                  std::to_string(sign));
    }
    sign_[i - 1] = sign;
    ref_[i - 1] = target_for(i, sign);
    profile_[i - 1] = TrapezoidProfile(0, ref_[i - 1], ref_[i - 1], 1, 1);
  }
}

double FlipController::target_for(int, int sign) const {
  // on stops: the reference runs past the stop by the overtravel, so the motor presses on it
  if (on_stops_) return sign * (box_.end_stop_deg + box_.motor.overtravel_deg) * kRadPerDeg;
  return sign * flip_rad_;
}

double FlipController::initial_angle_rad(int i) const {
  const int sign = initial_sign_[i - 1];
  return on_stops_ ? box_.stop_rad(i, sign) : sign * flip_rad_;
}

double FlipController::reference_rad(int i) const { return ref_[i - 1]; }

void FlipController::update(double t, const Eigen::Vector2d& rate) {
  const double vmax = box_.motor.max_speed_dps * kRadPerDeg;
  const double amax = box_.motor.max_accel_dps2 * kRadPerDeg;
  const double settle = p_.settle_rate_dps * kRadPerDeg;
  for (int k = 0; k < 2; ++k) {
    ref_[k] = profile_[k].angle_rad(t);
    // settled: the reference arrived and the platform has come to rest
    if (moving_[k] && t >= profile_[k].end_s() && std::abs(rate[k]) < settle) {
      moving_[k] = false;
      ++flips_;
      next_flip_s_ = external_ ? std::numeric_limits<double>::infinity() : t + p_.standstill_s;
    }
  }
  if (!external_ && !any_moving() && t >= next_flip_s_) {
    // Fig. 3 / eq. (5): the platform that moves from the current position of the flip cycle
    // (platform 2 after (+,+) and (-,-), platform 1 after (+,-) and (-,+))
    const int k = geo::flip_cycle_mover(geo::flip_cycle_index(sign_[0], sign_[1])) - 1;
    sign_[k] = -sign_[k];
    profile_[k] = TrapezoidProfile(t, ref_[k], target_for(k + 1, sign_[k]), vmax, amax);
    moving_[k] = true;
    next_flip_s_ = std::numeric_limits<double>::infinity();
  }
}

void FlipController::take_external_control() {
  external_ = true;
  next_flip_s_ = std::numeric_limits<double>::infinity();
}

void FlipController::command(int i, int sign, double t) {
  const int k = i - 1;
  if (sign_[k] == sign) return;  // at that stop already, or on its way there
  sign_[k] = sign;
  profile_[k] = TrapezoidProfile(t, ref_[k], target_for(i, sign), box_.motor.max_speed_dps * kRadPerDeg,
                                 box_.motor.max_accel_dps2 * kRadPerDeg);
  moving_[k] = true;
}

}  // namespace driftless::twin
