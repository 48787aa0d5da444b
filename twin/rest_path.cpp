#include "twin/rest_path.hpp"

#include <cmath>

namespace driftless::twin {
namespace {

// a static box: the platforms count as settled below these (the leftover motion moves the angle
// by < rate / decay rate ~ 1e-12 rad; far below the 1e-9 rad/s truth tolerance)
constexpr double kSettledRateRadps = 1e-10;
constexpr double kSettledAccelRadps2 = 1e-7;
// a platform moving faster than this relative to the box is in a transient (a flip, a landing,
// a bounce), rad/s; slower, it rides its stop (the vehicle's vibration moves it by <= 2e-4 rad/s)
constexpr double kQuietRateRadps = 1e-3;
// a stop's transient has decayed by e^-25 ~ 1e-11 this many decay times after the platform last
// moved faster than the quiet rate, so what remains is the platform riding on its stop
constexpr double kSettleDecayTimes = 25.0;
// the inertial load may change the stop's contact torque by this fraction of the motor's press
constexpr double kRestLoadFraction = 0.5;
// a base rate change along a hinge that the interval's end-point accelerations leave unexplained
// by more than this is a jolt (a rate step: the vehicle's turn entries), rad/s. Acceleration
// steps leave at most (step x interval / 2) unexplained: <= 0.017 rad/s for the pan/tilt's
// 200 deg/s^2, 0.025 rad/s for the vehicle's 32 Hz vibration; the vehicle's turns jump >= 0.2 rad/s
constexpr double kJoltRadps = 0.05;

// the same motion state, bit for bit
bool same_state(const MotionState& x, const MotionState& y) {
  return x.p_enu_m == y.p_enu_m && x.q_enu_from_body.coeffs() == y.q_enu_from_body.coeffs() &&
         x.v_enu_mps == y.v_enu_mps && x.a_enu_mps2 == y.a_enu_mps2 && x.w_body_radps == y.w_body_radps &&
         x.dw_body_radps2 == y.dw_body_radps2;
}

}  // namespace

double stop_decay_time_s(const BoxParams& box) {
  const double z = box.stop_dampratio;
  const double slow = z <= 1.0 ? 1.0 : 1.0 - std::sqrt(1.0 - 1.0 / (z * z));
  return box.stop_timeconst_s / slow;
}

RestGate::RestGate(const BoxParams& box, bool static_base, double sample_rate_hz)
    : static_base_(static_base),
      dt_out_s_(1.0 / sample_rate_hz),
      settle_s_(kSettleDecayTimes * stop_decay_time_s(box)) {}

void RestGate::observe(double t_s, const HingeState& hinge) {
  for (int i = 0; i < 2; ++i) {
    if (!(std::abs(hinge.rate_radps[i]) < kQuietRateRadps)) loud_s_[i] = t_s;
  }
}

bool RestGate::settled(double t_s, const HingeState& hinge, const double accel_radps2[2]) const {
  for (int i = 0; i < 2; ++i) {
    if (t_s - loud_s_[i] < settle_s_) return false;
    if (static_base_ &&
        !(std::abs(hinge.rate_radps[i]) < kSettledRateRadps && std::abs(accel_radps2[i]) < kSettledAccelRadps2)) {
      return false;
    }
  }
  return true;
}

bool RestGate::holds(const World& world, const FlipController& flips, const MotionState& a,
                     const MotionState& b, const double angle_rad[2]) const {
  if (static_base_) return true;
  if (!flips.on_stops()) return false;  // held by the soft servo alone: its dynamics always matter
  const Eigen::Vector3d jolt_radps =
      (b.w_body_radps - a.w_body_radps) - 0.5 * dt_out_s_ * (a.dw_body_radps2 + b.dw_body_radps2);
  for (int i = 1; i <= 2; ++i) {
    if (std::abs(world.box().hinge_axis(i).dot(jolt_radps)) > kJoltRadps) return false;
  }
  // the loads at `a` were computed as the last interval's end (the same state, bit for bit)
  const bool reuse = end_load_.valid && same_state(a, end_load_.base) &&
                     end_load_.angle_rad[0] == angle_rad[0] && end_load_.angle_rad[1] == angle_rad[1];
  double load_a[2], load_b[2];
  for (int i = 1; i <= 2; ++i) {
    load_a[i - 1] = reuse ? end_load_.torque_nm[i - 1] : world.rest_hinge_torque_nm(i, a, angle_rad[i - 1]);
    load_b[i - 1] = world.rest_hinge_torque_nm(i, b, angle_rad[i - 1]);
  }
  end_load_ = {b, {angle_rad[0], angle_rad[1]}, {load_b[0], load_b[1]}, true};
  for (int i = 1; i <= 2; ++i) {
    const double limit = kRestLoadFraction * std::abs(world.motor_rest_torque_nm(flips.reference_rad(i), angle_rad[i - 1]));
    if (std::abs(load_a[i - 1]) > limit || std::abs(load_b[i - 1]) > limit) return false;
  }
  return true;
}

}  // namespace driftless::twin
