// A clipping gyro is said before any effect (diagnose/replay.cpp): on a log from the tests' own
// synthesiser (not the twin), a box spinning past sensor 1's +-250 deg/s range.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "diagnose/replay.hpp"
#include "tests/estimator/synth.hpp"
#include "tests/temp_path.hpp"

namespace driftless::diagnose {
namespace {

Replay replay_spin(double amplitude_dps, const std::string& name) {
  test::SynthParams p;
  p.duration_s = 120.0;
  p.noise_sigma_dps = 0.05;
  p.body_rate_dps = [amplitude_dps](double t) { return Eigen::Vector3d(0.0, 0.0, amplitude_dps * std::sin(0.05 * t)); };
  p.before_quantise = [](Sample& s) { s.gyro1_dps = s.gyro1_dps.cwiseMax(-250.0).cwiseMin(250.0); };
  const auto path = test::temp_path(name);
  test::synth_log(p, path);
  return replay_log(path, ReplayOptions{});
}

TEST(ReplayClipping, AClippedChannelIsTheFirstNoteAndAnUnclippedLogHasNone) {
  // WHEN a 600 deg/s spin is read by a +-250 deg/s sensor 1 THEN the first note names a sensor-1
  // channel at 250 deg/s, inside the standstills
  const Replay clipped = replay_spin(600.0, "driftless_replay_clipped.csv");
  ASSERT_FALSE(clipped.notes.empty());
  EXPECT_EQ(clipped.notes.front().rfind("gyro1_", 0), 0u) << clipped.notes.front();
  EXPECT_NE(clipped.notes.front().find("+-250 deg/s"), std::string::npos) << clipped.notes.front();
  EXPECT_NE(clipped.notes.front().find("not to be trusted"), std::string::npos) << clipped.notes.front();
  // AND a 200 deg/s spin clips only where a flip's hinge rate adds to it: a note that says so,
  // not a warning against the fits (which leave the flips out)
  const Replay inside = replay_spin(200.0, "driftless_replay_inside.csv");
  for (const auto& n : inside.notes) {
    EXPECT_EQ(n.find("not to be trusted"), std::string::npos) << n;
    if (n.find("clips") != std::string::npos) {
      EXPECT_NE(n.find("only while a platform turns"), std::string::npos) << n;
    }
  }
}

}  // namespace
}  // namespace driftless::diagnose
