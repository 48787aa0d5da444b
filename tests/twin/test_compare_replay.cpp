// Log replay: the truth rebuilt from ref_q and platform angles against closed forms, and the
// bad-input rules (no ref_q, other sample rate).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "tests/twin/compare_test_log.hpp"
#include "twin/compare/compare.hpp"
#include "twin/compare/report.hpp"

namespace driftless::twin {
namespace {

SensorParams ideal() { return ideal_sensor(); }

TEST(CompareReplay, BodyRateFromQuaternionsMatchesClosedForm) {
  // GIVEN a pan/tilt log with ideal sensors, WHEN replayed from ref_q and plat angles
  const auto lg = testlog::make_log(ideal(), ideal(), 30.0, 1);
  const Replay r = replay_samples(lg.samples, lg.meta, lg.fields, ReplayOptions{}, "t.csv");
  // THEN the rebuilt sensor truth equals the ideal gyro output at rest (central-difference
  // error O(dt^2 wddot) well below 1e-3 deg/s for this smooth motion)
  double worst = 0.0;
  for (std::size_t k = 5; k + 5 < r.size(); ++k) {
    if (r.flipping[k]) continue;
    for (int s = 0; s < 2; ++s) {
      const Eigen::Vector3d y = s == 0 ? lg.samples[k].gyro1_dps : lg.samples[k].gyro2_dps;
      worst = std::max(worst, (r.w_radps[s][k] * kDegPerRad - y).cwiseAbs().maxCoeff());
    }
  }
  EXPECT_LT(worst, 2e-3);
}

TEST(CompareReplay, StaticLogWithoutRefQIsAcceptedWithAssumption) {
  // GIVEN a static box logged without ref_q
  const auto lg = testlog::make_log(mpu6050_defaults(), mpu6050_defaults(), 40.0, 2, 0.0, 100.0, 52.0,
                                    testlog::Planted{{{0, 0}, {0, 0}}, 0.0, false});
  // WHEN replayed THEN it is accepted and the assumption is stated
  const Replay r = replay_samples(lg.samples, lg.meta, lg.fields, ReplayOptions{}, "static.csv");
  bool said = false;
  for (const auto& n : r.notes) said = said || n.find("assumed static") != std::string::npos;
  EXPECT_TRUE(said);
  EXPECT_NEAR(r.w_body_radps[100].norm(), kEarthRateRadps, 1e-12);
}

TEST(CompareReplay, MovingLogWithoutRefQIsRefused) {
  // GIVEN a moving box logged without ref_q, WHEN replayed, THEN a clear error names ref_q
  const auto lg = testlog::make_log(ideal(), ideal(), 40.0, 3, 30.0, 100.0, 52.0,
                                    testlog::Planted{{{0, 0}, {0, 0}}, 0.0, false});
  try {
    replay_samples(lg.samples, lg.meta, lg.fields, ReplayOptions{}, "moving.csv");
    FAIL() << "a moving log without ref_q was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("ref_qw"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("moving.csv"), std::string::npos) << e.what();
  }
}

TEST(CompareReplay, OtherSampleRateIsRefusedOrResampled) {
  // GIVEN a 200 Hz log and a 100 Hz model
  const auto lg = testlog::make_log(ideal(), ideal(), 20.0, 4, 30.0, 200.0);
  ReplayOptions opt;
  opt.model_sample_rate_hz = 100.0;
  // WHEN replayed without resampling THEN it is refused, naming both rates
  try {
    replay_samples(lg.samples, lg.meta, lg.fields, opt, "fast.csv");
    FAIL() << "rate mismatch accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("--resample"), std::string::npos) << e.what();
  }
  // AND with resampling it runs at the model's rate and says so
  opt.resample = true;
  const Replay r = replay_samples(lg.samples, lg.meta, lg.fields, opt, "fast.csv");
  EXPECT_TRUE(r.resampled);
  EXPECT_NEAR(r.sample_rate_hz, 100.0, 1e-9);
  EXPECT_NEAR(r.t_s[1] - r.t_s[0], 0.01, 1e-12);
}

TEST(CompareReport, JsonIsDeterministicAndHoldsTheContract) {
  SensorParams p = deterministic_part(mpu6050_defaults());
  p.white_noise.enabled = true;
  const auto lg = testlog::make_log(p, p, 40.0, 5);
  const Replay r = replay_samples(lg.samples, lg.meta, lg.fields, ReplayOptions{}, "t.csv");
  CompareModel m = default_compare_model();
  m.sensor = {p, p};
  const auto a = diagnosis_json(compare(r, m, CompareOptions{}));
  const auto b = diagnosis_json(compare(r, m, CompareOptions{}));
  EXPECT_EQ(a, b);
  for (const char* key : {"\"verdict\"", "\"ranking\"", "\"effect\"", "\"sensor\"", "\"axis\"", "\"params\"",
                          "\"explained_fraction\"", "\"evidence\"", "\"residual_rms_dps\"", "\"before\"", "\"after_best\""})
    EXPECT_NE(a.find(key), std::string::npos) << key;
}

}  // namespace
}  // namespace driftless::twin
