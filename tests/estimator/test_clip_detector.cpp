// Suspected clipping (estimator/clip_detector.hpp) and its health finding.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "estimator/clip_detector.hpp"
#include "estimator/health.hpp"

namespace driftless::est {
namespace {

constexpr double kPi = 3.14159265358979323846;

// GIVEN a 100 Hz turning rate of amplitude `amp_dps` with white noise of `noise_dps`, read by a gyro
// that clips at +-`fs_dps` and quantises to `lsb_dps` (0: none), on channel `ch`
ClipDetector run(double amp_dps, double noise_dps, double fs_dps, double lsb_dps, int ch, std::uint64_t* clipped) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0.0, noise_dps);
  ClipDetector d;
  *clipped = 0;
  for (int k = 0; k < 60000; ++k) {
    double v = amp_dps * std::sin(2.0 * kPi * 0.05 * k / 100.0) + n(rng);
    if (lsb_dps > 0.0) v = lsb_dps * std::round(v / lsb_dps);
    if (std::fabs(v) >= fs_dps) {
      v = std::copysign(fs_dps, v);
      ++*clipped;
    }
    d.push(ch, v, true);
  }
  return d;
}

TEST(ClipDetector, AGyroDrivenPastItsRangeIsNamedWithItsLevelAndTheClippedSamples) {
  std::uint64_t clipped = 0;
  // WHEN a 600 deg/s swing is read by a +-250 deg/s gyro (MPU6050 LSB 1/131 deg/s, 0.05 deg/s noise)
  const ClipDetector d = run(600.0, 0.05, 250.0, 1.0 / 131.0, 5, &clipped);
  const auto s = d.suspected();
  // THEN channel 5 (gyro2_z) is named at 250 deg/s with every clipped sample (runs of thousands:
  // only each run's first two samples are not counted, here 2 per half-swing)
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].channel, 5);
  EXPECT_DOUBLE_EQ(s[0].level_dps, 250.0);
  EXPECT_GT(clipped, 20000u);
  EXPECT_LE(s[0].samples, clipped);
  EXPECT_GE(s[0].samples + 2 * 6, clipped);
}

TEST(ClipDetector, ARateThatOnlyPassesThroughItsExtremeIsNotClipping) {
  std::uint64_t clipped = 0;
  // GIVEN the same swing inside the range, quantised (its peak holds one LSB value for ~0.1 s
  // without noise, so the noise is what a real gyro adds: 0.05 deg/s = 6.5 LSB)
  const ClipDetector d = run(200.0, 0.05, 250.0, 1.0 / 131.0, 0, &clipped);
  EXPECT_EQ(clipped, 0u);
  // THEN nothing is suspected: the largest value comes once, not in runs of three
  EXPECT_TRUE(d.suspected().empty());
}

TEST(ClipDetector, AQuietStaticLogBelowAnyGyroRangeIsNotClipping) {
  // GIVEN a noise-free simulated log holding one rate: every sample repeats its largest value
  ClipDetector d;
  for (int k = 0; k < 1000; ++k) d.push(2, 15.0, true);
  // THEN it is below kMinLevelDps (no gyro's range is 15 deg/s): not reported
  EXPECT_TRUE(d.suspected().empty());
}

TEST(ClipDetector, AMissingReadingEndsARunAndAHigherValueRestartsTheCount) {
  ClipDetector d;
  // runs of two at 300, split by NaN: never three in a row
  for (int k = 0; k < 20; ++k) {
    d.push(0, 300.0, true);
    d.push(0, 300.0, true);
    d.push(0, std::nan(""), true);
  }
  EXPECT_TRUE(d.suspected().empty());
  // a run of 12 at 300 counts 12; a later single 310 makes 300 not the largest: the count restarts
  for (int k = 0; k < 12; ++k) d.push(0, -300.0, true);
  ASSERT_EQ(d.suspected().size(), 1u);
  EXPECT_EQ(d.suspected()[0].samples, 12u);
  d.push(0, 310.0, true);
  EXPECT_TRUE(d.suspected().empty());
}

TEST(ClipDetector, ClippedSamplesAreSplitIntoAtRestAndWhileAPlatformTurns) {
  ClipDetector d;
  // a run of 10 at the rail during a flip, then one of 6 while the platforms rest: the at-rest
  // samples of a run count from its start once it is kMinRun long
  for (int k = 0; k < 10; ++k) d.push(1, 250.0, false);
  d.push(1, 12.0, true);
  for (int k = 0; k < 6; ++k) d.push(1, -250.0, true);
  ASSERT_EQ(d.suspected().size(), 1u);
  EXPECT_EQ(d.suspected()[0].samples, 16u);
  EXPECT_EQ(d.suspected()[0].samples_at_rest, 6u);
}

TEST(HealthSaturation, AClipInsideTheStandstillsLeadsTheFindingsAndOneDuringFlipsIsANote) {
  // GIVEN a degraded report and three clipped channels over 2000 rows: 5 % of the rows at rest,
  // 0.75 % at rest, and 2 % but only 5 samples at rest (a fast flip)
  HealthReport h;
  h.verdict = HealthVerdict::kDegraded;
  HealthFinding gate;
  gate.cause = HealthCause::kRejections;
  h.findings.push_back(gate);
  add_saturation_findings(h, {{2, 250.0, 100, 100}, {3, 250.0, 30, 15}, {4, 2000.0, 40, 5}}, 2000);
  // THEN the saturation findings come first: failed, degraded, a note; the run fails
  EXPECT_EQ(h.verdict, HealthVerdict::kFailed);
  ASSERT_EQ(h.findings.size(), 4u);
  EXPECT_EQ(h.findings[0].cause, HealthCause::kSaturation);
  EXPECT_EQ(h.findings[0].severity, HealthVerdict::kFailed);
  EXPECT_DOUBLE_EQ(h.findings[0].value, 0.05);
  EXPECT_DOUBLE_EQ(h.findings[0].suggested, 250.0);
  EXPECT_EQ(h.findings[1].severity, HealthVerdict::kDegraded);
  EXPECT_EQ(h.findings[1].components, std::vector<int>{3});
  EXPECT_EQ(h.findings[2].severity, HealthVerdict::kOk);
  EXPECT_EQ(h.findings[3].cause, HealthCause::kRejections);
  // AND a clip only during flips leaves an ok verdict ok
  HealthReport flips;
  add_saturation_findings(flips, {{0, 250.0, 500, 0}}, 2000);
  EXPECT_EQ(flips.verdict, HealthVerdict::kOk);
  ASSERT_EQ(flips.findings.size(), 1u);
  // AND with nothing clipped the report is unchanged
  HealthReport ok;
  add_saturation_findings(ok, {}, 1000);
  EXPECT_EQ(ok.verdict, HealthVerdict::kOk);
  EXPECT_TRUE(ok.findings.empty());
}

TEST(ClipDetector, AnEmptyChannelAndOneStuckAtOneValueAreDeadOthersAreNot) {
  // GIVEN 200 rows: gyro1_y empty throughout, gyro2_z stuck at 0.25 while gyro2_x and gyro2_y move,
  // gyro1_x moving, gyro1_z a constant (its sensor has no other moving axis than gyro1_x)
  ClipDetector d;
  for (int k = 0; k < 200; ++k) {
    const double moving = 0.01 * (k % 7);
    d.push(0, moving, true);
    d.push(1, std::nan(""), true);
    d.push(2, 0.125, true);
    d.push(3, moving, true);
    d.push(4, -moving, true);
    d.push(5, 0.25, true);
  }
  // THEN gyro1_y is empty and gyro2_z stuck at 0.25 ...
  const auto dead = d.dead();
  ASSERT_EQ(dead.size(), 3u);
  EXPECT_EQ(dead[0].channel, 1);
  EXPECT_EQ(dead[0].kind, DeadChannel::Kind::kEmpty);
  EXPECT_EQ(dead[0].rows, 200u);
  // ... and gyro1_z too: one value while gyro1_x moves
  EXPECT_EQ(dead[1].channel, 2);
  EXPECT_EQ(dead[1].kind, DeadChannel::Kind::kStuck);
  EXPECT_EQ(dead[2].channel, 5);
  EXPECT_EQ(dead[2].kind, DeadChannel::Kind::kStuck);
  EXPECT_DOUBLE_EQ(dead[2].value_dps, 0.25);
  // AND a single-sensor view looks at channels 0..2 only
  EXPECT_EQ(d.dead(3).size(), 2u);
}

TEST(ClipDetector, AConstantSensorWithNothingMovingOrAShortLogIsNotDead) {
  // GIVEN a noise-free box that never moves: every channel one value; and a log of 99 rows
  ClipDetector still, shortlog;
  for (int k = 0; k < 1000; ++k) {
    for (int i = 0; i < 6; ++i) still.push(i, 0.1 * i, true);
  }
  for (int k = 0; k < int(ClipDetector::kMinStuckRows) - 1; ++k) {
    shortlog.push(0, 0.01 * k, true);
    shortlog.push(1, 0.5, true);
  }
  // THEN no channel is dead
  EXPECT_TRUE(still.dead().empty());
  EXPECT_TRUE(shortlog.dead(3).empty());
}

TEST(HealthDeadAxis, ADeadAxisLeadsTheFindingsAndFailsTheRun) {
  // GIVEN an ok report with one note and a stuck gyro2_x
  HealthReport h;
  HealthFinding note;
  note.cause = HealthCause::kNoiseOverstated;
  note.severity = HealthVerdict::kOk;
  h.findings.push_back(note);
  add_dead_axis_findings(h, {{DeadChannel::Kind::kStuck, 3, 0.5, 1000}});
  // THEN it fails, the dead axis first with its channel, value and rows
  EXPECT_EQ(h.verdict, HealthVerdict::kFailed);
  ASSERT_EQ(h.findings.size(), 2u);
  EXPECT_EQ(h.findings[0].cause, HealthCause::kDeadAxis);
  EXPECT_EQ(h.findings[0].components, std::vector<int>{3});
  EXPECT_DOUBLE_EQ(h.findings[0].value, 0.5);
  EXPECT_DOUBLE_EQ(h.findings[0].suggested, 1000.0);
  EXPECT_EQ(h.findings[1].cause, HealthCause::kNoiseOverstated);
  // AND with none the report is unchanged
  HealthReport ok;
  add_dead_axis_findings(ok, {});
  EXPECT_EQ(ok.verdict, HealthVerdict::kOk);
}

}  // namespace
}  // namespace driftless::est
