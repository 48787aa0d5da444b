// Whether the filter's correction is locked, with hysteresis (docs/estimator.md section 6, the
// `locked` column): it locks once every sigma of the correction is below the lock level L after an
// update, and stays locked until a gate re-lock widens P above L or a sigma rises above
// kUnlockFactor L.
// Without the band the flag flickered between updates where the steady state sits on L (the
// stop-27 finding F27: sigma 0.049/0.051 alternating with the position cycle), and every dip
// counted as a lost lock. Std only.
#pragma once

namespace driftless::est {

/// The lock is lost only above this multiple of the lock level (or at a gate re-lock).
inline constexpr double kUnlockFactor = 1.5;

/// The lock of one pass, stepped at each update.
class LockState {
 public:
  enum class Change { kNone, kLocked, kLost };
  /// `lock_sigma_dps` (deg/s) <= 0: locked from the first update on, never lost.
  explicit LockState(double lock_sigma_dps) : lock_sigma_dps_(lock_sigma_dps) {}
  /// After an update: `sigma_dps` the largest sigma of the correction, `relocked` whether a gate
  /// re-lock widened P in it. Returns what changed.
  Change on_update(double sigma_dps, bool relocked);
  bool locked() const { return locked_; }
  double lock_sigma_dps() const { return lock_sigma_dps_; }
  /// deg/s, above this a locked filter counts as unlocked (kUnlockFactor times the lock level).
  double unlock_sigma_dps() const { return kUnlockFactor * lock_sigma_dps_; }

 private:
  double lock_sigma_dps_;
  bool locked_ = false;
};

}  // namespace driftless::est
