// The lock's hysteresis (estimator/lock_state.hpp, docs/estimator.md section 6.5): a sigma that
// crosses the lock level back and forth (the steady state of F27 sitting on it) keeps the lock; a
// gate re-lock that widens P above the level, or a sigma above 1.5x the level, loses it.
#include <cmath>

#include <gtest/gtest.h>

#include "estimator/lock_state.hpp"

namespace driftless::est {
namespace {

TEST(LockStateTest, ASigmaAlternatingAcrossTheLevelLocksOnce) {
  // GIVEN a lock level of 0.05 deg/s and F27's steady state, 0.049/0.051 from update to update
  LockState lock(0.05);
  int changes = 0;
  for (int k = 0; k < 40; ++k) {
    const double sigma = k < 10 ? 0.2 / (k + 1) : (k % 2 ? 0.051 : 0.049);
    // WHEN each update reports it
    if (lock.on_update(sigma, false) != LockState::Change::kNone) ++changes;
  }
  // THEN the lock came once and stayed
  EXPECT_EQ(changes, 1);
  EXPECT_TRUE(lock.locked());
  EXPECT_DOUBLE_EQ(lock.unlock_sigma_dps(), kUnlockFactor * 0.05);
}

TEST(LockStateTest, OnlyARealLossUnlocks) {
  LockState lock(0.05);
  ASSERT_EQ(lock.on_update(0.04, false), LockState::Change::kLocked);
  // a sigma inside the band, and a re-lock whose widened sigma stayed below the level: kept
  EXPECT_EQ(lock.on_update(0.074, false), LockState::Change::kNone);
  EXPECT_EQ(lock.on_update(0.045, true), LockState::Change::kNone);
  // a re-lock that widened P above the level: lost, and back at the next update below it
  EXPECT_EQ(lock.on_update(0.06, true), LockState::Change::kLost);
  EXPECT_EQ(lock.on_update(0.06, false), LockState::Change::kNone);
  EXPECT_EQ(lock.on_update(0.049, false), LockState::Change::kLocked);
  // a sigma above 1.5x the level without a re-lock (a temperature jump, a wide prior): lost
  EXPECT_EQ(lock.on_update(0.0751, false), LockState::Change::kLost);
  EXPECT_FALSE(lock.locked());
  // no number is no lock
  ASSERT_EQ(lock.on_update(0.01, false), LockState::Change::kLocked);
  EXPECT_EQ(lock.on_update(std::nan(""), false), LockState::Change::kLost);
}

TEST(LockStateTest, ALevelOfZeroLocksAtTheFirstUpdateForGood) {
  LockState lock(0.0);
  EXPECT_FALSE(lock.locked());
  EXPECT_EQ(lock.on_update(5.0, false), LockState::Change::kLocked);
  EXPECT_EQ(lock.on_update(50.0, true), LockState::Change::kNone);
  EXPECT_TRUE(lock.locked());
}

}  // namespace
}  // namespace driftless::est
