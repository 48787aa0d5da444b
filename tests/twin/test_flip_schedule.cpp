// The Fig. 3 flip schedule: order of states, one platform at a time, standstill timing.
#include <vector>

#include <gtest/gtest.h>

#include "estimator/sample.hpp"
#include "twin/flip_schedule.hpp"

namespace driftless::twin {
namespace {

TEST(TrapezoidProfile, RespectsSpeedAndAccelerationLimits) {
  const TrapezoidProfile p(1.0, -1.0, 2.0, 2.0, 4.0);  // 3 rad at 2 rad/s, 4 rad/s^2
  EXPECT_NEAR(p.end_s(), 1.0 + 3.0 / 2.0 + 2.0 / 4.0, 1e-12);
  EXPECT_NEAR(p.angle_rad(0.5), -1.0, 0);
  EXPECT_NEAR(p.angle_rad(10.0), 2.0, 0);
  double prev = p.angle_rad(1.0), prev_v = 0;
  for (double t = 1.001; t < p.end_s(); t += 0.001) {
    const double v = (p.angle_rad(t) - prev) / 0.001;
    EXPECT_LE(v, 2.0 + 1e-9);
    EXPECT_LE(std::abs(v - prev_v) / 0.001, 4.0 + 1e-3);
    prev = p.angle_rad(t);
    prev_v = v;
  }
}

// GIVEN the schedule with instantly settling platforms, WHEN it runs for four flips,
// THEN the states follow (+,+) -> (+,-) -> (-,-) -> (-,+) -> (+,+) and only one platform moves at a time
TEST(FlipController, FollowsFigure3OnePlatformAtATime) {
  FlipScheduleParams p;
  p.standstill_s = 5;
  BoxParams box;
  FlipController fc(p, box);
  std::vector<std::pair<int, int>> states = {{fc.sign(1), fc.sign(2)}};
  std::vector<double> flip_starts;
  bool was_moving = false;
  for (double t = 0; t < 40; t += 0.001) {
    fc.update(t, Eigen::Vector2d::Zero());  // rates 0: settles when the reference arrives
    EXPECT_FALSE(fc.moving(1) && fc.moving(2)) << "both platforms moving at t = " << t;
    if (fc.any_moving() && !was_moving) {
      flip_starts.push_back(t);
      states.emplace_back(fc.sign(1), fc.sign(2));
    }
    was_moving = fc.any_moving();
  }
  const std::vector<std::pair<int, int>> expected = {{1, 1}, {1, -1}, {-1, -1}, {-1, 1}, {1, 1}};
  ASSERT_GE(states.size(), expected.size());
  for (std::size_t k = 0; k < expected.size(); ++k) EXPECT_EQ(states[k], expected[k]) << "state " << k;
  // first flip after one standstill; each next after the move (~1.6 s) plus a standstill
  EXPECT_NEAR(flip_starts[0], 5.0, 0.0015);
  const double move = (180.0 + 2 * box.motor.overtravel_deg) / box.motor.max_speed_dps +
                      box.motor.max_speed_dps / box.motor.max_accel_dps2;
  EXPECT_NEAR(flip_starts[1] - flip_starts[0], move + 5.0, 0.01);
}

TEST(FlipController, SmallerFlipAngleTargetsThatAngleNotTheStop) {
  FlipScheduleParams p;
  p.flip_angle_deg = 45;
  p.standstill_s = 1;
  FlipController fc(p, BoxParams{});
  EXPECT_NEAR(fc.initial_angle_rad(1), 45 * kRadPerDeg, 1e-15);
  for (double t = 0; t < 4; t += 0.001) fc.update(t, Eigen::Vector2d::Zero());
  EXPECT_NEAR(fc.reference_rad(2), -45 * kRadPerDeg, 1e-12);
  EXPECT_NEAR(fc.commanded_rest_rad(2), -45 * kRadPerDeg, 1e-15);
}

TEST(FlipController, DisabledScheduleNeverFlips) {
  FlipScheduleParams p;
  p.enabled = false;
  FlipController fc(p, BoxParams{});
  for (double t = 0; t < 100; t += 0.01) fc.update(t, Eigen::Vector2d::Zero());
  EXPECT_EQ(fc.flips(), 0);
  EXPECT_FALSE(fc.any_moving());
}

TEST(FlipController, StartsOnTheGivenStopsAndRefusesOtherSigns) {
  // GIVEN the calibration rig's start: both platforms on their - stops
  FlipScheduleParams p;
  BoxParams box;
  FlipController fc(p, box, {-1, -1});
  // THEN they start there, the motor presses them onto those stops, the system knows -90
  for (int i = 1; i <= 2; ++i) {
    EXPECT_EQ(fc.initial_angle_rad(i), box.stop_rad(i, -1));
    EXPECT_NEAR(fc.reference_rad(i), -(box.end_stop_deg + box.motor.overtravel_deg) * kRadPerDeg, 1e-15);
    EXPECT_NEAR(fc.commanded_rest_rad(i), -90.0 * kRadPerDeg, 1e-15);
    EXPECT_EQ(fc.sign(i), -1);
  }
  EXPECT_THROW(FlipController(p, box, {0, 1}), std::invalid_argument);
  EXPECT_THROW(FlipController(p, box, {1, 2}), std::invalid_argument);
}

TEST(FlipScheduleParams, RejectsAnglesBeyondTheStop) {
  FlipScheduleParams p;
  p.flip_angle_deg = 95;
  EXPECT_THROW(p.validate(90), std::invalid_argument);
  p.flip_angle_deg = 0;
  EXPECT_THROW(p.validate(90), std::invalid_argument);
}

}  // namespace
}  // namespace driftless::twin
