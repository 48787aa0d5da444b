// The closed-form FastBox (twin/fast_box.hpp): GIVEN a scenario with a planted box-level error,
// WHEN it runs, THEN the samples carry exactly that error (the diagnose tests draw their logs
// from it, so what they find must be what was planted).
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "twin/fast_box.hpp"
#include "twin/scenario.hpp"

namespace driftless::twin {
namespace {

Scenario pan_tilt_ideal(double duration_s) {
  Scenario sc;
  sc.duration_s = duration_s;
  sc.seed = 3;
  sc.motion.type = MotionType::pan_tilt;
  sc.model.sensor1 = ideal_sensor();
  sc.model.sensor2 = ideal_sensor();
  return sc;
}

std::vector<Sample> run(const Scenario& sc) {
  FastBox box(sc);
  std::vector<Sample> out;
  Sample s;
  while (box.next(s)) out.push_back(s);
  return out;
}

TEST(FastBox, TimeOffsetDelaysTheSensorsTruthByLinearInterpolation) {
  // GIVEN ideal sensors (output = truth) on a moving box, without and with a 25 ms sampling offset
  Scenario sc = pan_tilt_ideal(20.0);
  const std::vector<Sample> base = run(sc);
  sc.model.time_offset_s = 0.025;  // 2.5 samples at 100 Hz
  const std::vector<Sample> late = run(sc);
  ASSERT_EQ(base.size(), late.size());
  // THEN each output is the truth 2.5 samples earlier (halfway between k-2 and k-3), to rounding
  double worst = 0.0, moved = 0.0;
  for (std::size_t k = 3; k < base.size(); ++k) {
    const Eigen::Vector3d want = 0.5 * (base[k - 2].gyro1_dps + base[k - 3].gyro1_dps);
    worst = std::max(worst, (late[k].gyro1_dps - want).cwiseAbs().maxCoeff());
    moved = std::max(moved, (late[k].gyro1_dps - base[k].gyro1_dps).cwiseAbs().maxCoeff());
    EXPECT_EQ(late[k].t_s, base[k].t_s);  // the log's time stamps do not move
  }
  EXPECT_LT(worst, 1e-12);
  EXPECT_GT(moved, 0.05);  // deg/s: the offset is visible on this motion
}

TEST(FastBox, NegativeTimeOffsetIsRefusedNamingTheKey) {
  Scenario sc = pan_tilt_ideal(1.0);
  sc.model.time_offset_s = -0.01;
  try {
    FastBox box(sc);
    FAIL() << "a negative offset was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("model.time_offset_s"), std::string::npos) << e.what();
  }
}

TEST(FastBox, PlatformsDrivenOntoStopsRestAtTheTrueStopAngles) {
  // GIVEN the flip angle at the end stop (the motor presses the platforms onto their stops) and
  // stop errors [at -stop, at +stop]
  Scenario sc = pan_tilt_ideal(60.0);
  sc.flip_schedule.standstill_s = 5.0;
  sc.model.box.stop1_error_deg = Eigen::Vector2d(-0.3, 0.2);
  sc.model.box.stop2_error_deg = Eigen::Vector2d(0.4, -0.1);
  const std::vector<Sample> log = run(sc);
  // THEN at rest the true angle is the stop's true angle, while the read-back says the nominal one
  int seen[2][2] = {{0, 0}, {0, 0}};
  for (const Sample& s : log) {
    const double read[2] = {s.plat1_deg, s.plat2_deg}, truth[2] = {s.true_plat1_deg, s.true_plat2_deg};
    const Eigen::Vector2d err[2] = {sc.model.box.stop1_error_deg, sc.model.box.stop2_error_deg};
    for (int p = 0; p < 2; ++p) {
      if (!std::isfinite(read[p])) continue;  // moving: unknown to the system
      ASSERT_EQ(std::abs(read[p]), 90.0);
      const int side = read[p] > 0 ? 1 : 0;
      EXPECT_NEAR(truth[p], read[p] + err[p][side], 1e-9) << "t=" << s.t_s << " platform " << p + 1;
      ++seen[p][side];
    }
  }
  for (int p = 0; p < 2; ++p) {
    EXPECT_GT(seen[p][0], 100) << "platform " << p + 1 << " never rested on its - stop";
    EXPECT_GT(seen[p][1], 100) << "platform " << p + 1 << " never rested on its + stop";
  }
}

}  // namespace
}  // namespace driftless::twin
