// The lock with hysteresis (lock_state.hpp).
#include "estimator/lock_state.hpp"

namespace driftless::est {

LockState::Change LockState::on_update(double sigma_dps, bool relocked) {
  if (lock_sigma_dps_ <= 0.0) {
    const bool was = locked_;
    locked_ = true;
    return was ? Change::kNone : Change::kLocked;
  }
  if (locked_) {
    // lost at a gate re-lock that widened P above the level, or at a sigma above the band (a NaN
    // too: no number is no lock); a sigma that only crosses the level stays locked
    if ((relocked && !(sigma_dps < lock_sigma_dps_)) || !(sigma_dps <= unlock_sigma_dps())) {
      locked_ = false;
      return Change::kLost;
    }
    return Change::kNone;
  }
  if (sigma_dps < lock_sigma_dps_) {
    locked_ = true;
    return Change::kLocked;
  }
  return Change::kNone;
}

}  // namespace driftless::est
