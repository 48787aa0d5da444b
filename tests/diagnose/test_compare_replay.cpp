// Log replay: the truth rebuilt from ref_q and platform angles against closed forms, and the
// bad-input rules (no ref_q, other sample rate).
#include <gtest/gtest.h>

#include "tests/diagnose/diagnosis_checks.hpp"

#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "tests/diagnose/compare_test_log.hpp"
#include "diagnose/compare.hpp"
#include "diagnose/report.hpp"
#include "tests/temp_path.hpp"

namespace driftless::diagnose {

using namespace driftless::twin;  // the sensor model, scenario and simulator
namespace {

SensorParams ideal() { return ideal_sensor(); }

TEST(CompareReplay, BodyRateFromQuaternionsMatchesClosedForm) {
  // GIVEN a pan/tilt log with ideal sensors, WHEN replayed from ref_q and plat angles (away from
  // the flips and the kinks of the trapezoidal rate profiles, which the replay marks rough)
  const auto lg = testlog::make_log(ideal(), ideal(), 30.0, 1);
  const Replay r = replay_samples(lg.samples, lg.meta, lg.fields, ReplayOptions{}, "t.csv");
  // THEN the rebuilt sensor truth equals the ideal gyro output at rest (central-difference
  // error O(dt^2 wddot) well below 1e-3 deg/s for this smooth motion)
  double worst = 0.0;
  for (std::size_t k = 5; k + 5 < r.size(); ++k) {
    if (r.flipping[k] || r.rough[k]) continue;  // flips and the pan/tilt's rate kinks
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
  // (sensor 1's rate in double: the box rate is kept as float for the report)
  EXPECT_NEAR(r.w_radps[0][100].norm(), kEarthRateRadps, 1e-12);
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

TEST(CompareReplay, OtherSampleRateRunsNativelyOrIsResampled) {
  // GIVEN a 200 Hz log
  const auto lg = testlog::make_log(ideal(), ideal(), 20.0, 4, 30.0, 200.0);
  // WHEN replayed with no model rate THEN it runs at its own rate (one policy for every model)
  const Replay native = replay_samples(lg.samples, lg.meta, lg.fields, ReplayOptions{}, "fast.csv");
  EXPECT_FALSE(native.resampled);
  EXPECT_NEAR(native.sample_rate_hz, 200.0, 1e-9);
  // AND asked to resample to 100 Hz it does and says so
  ReplayOptions opt;
  opt.resample_hz = 100.0;
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
  for (const char* key : {"\"verdict\"", "\"selected\"", "\"noise_model\"", "\"not_supported\"", "\"effect\"",
                          "\"family\"", "\"sensor\"", "\"axis\"", "\"params\"", "\"explained_fraction\"", "\"evidence\"",
                          "\"evidence_threshold\"", "\"residual_rms_dps\"", "\"before\"", "\"after_selected\""})
    EXPECT_NE(a.find(key), std::string::npos) << key;
  // AND every family is one of the machine-readable ids docs/compare.md lists
  const std::regex family_re("\"family\": \"([^\"]*)\"");
  int families = 0;
  for (auto it = std::sregex_iterator(a.begin(), a.end(), family_re); it != std::sregex_iterator(); ++it, ++families) {
    const std::string id = (*it)[1];
    EXPECT_TRUE(id == "physical" || id == "box" || id == "signal_chain" || id == "adc" || id == "noise_model") << id;
  }
  EXPECT_GT(families, 5);
}

TEST(CompareReplay, RateKinksAreMarkedRoughAndLinearRateIsExact) {
  // GIVEN a static log with one rate kink: from t = 5 s the box turns about z with a constant
  // acceleration of 200 deg/s^2 (a trapezoid profile's corner)
  const auto lg = testlog::make_log(ideal(), ideal(), 10.0, 6, 0.0);
  std::vector<Sample> s = lg.samples;
  for (auto& x : s) {
    const double u = std::max(0.0, x.t_s - 5.0);
    const double yaw = 0.5 * 200.0 * u * u * kRadPerDeg;
    x.set_q_enu_from_body(Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())));
  }
  // WHEN replayed
  const Replay r = replay_samples(s, lg.meta, lg.fields, ReplayOptions{}, "kink.csv");
  // THEN the samples at the kink are rough (left out), the others are not
  EXPECT_TRUE(r.rough[500]);
  EXPECT_FALSE(r.rough[400]);
  EXPECT_FALSE(r.rough[600]);
  // AND away from it the body rate equals the closed form (exact for a linear rate)
  // (sensor 1, whose hinge is the box's z axis: its z rate is the box's, in double)
  const Eigen::Vector3d earth = r.w_radps[0][300];
  for (std::size_t k : {520u, 700u, 950u}) {
    const double want = 200.0 * (r.t_s[k] - 5.0) * kRadPerDeg;
    EXPECT_NEAR((r.w_radps[0][k] - earth)[2], want, 1e-6) << k;
    EXPECT_NEAR((r.w_body_radps[k].cast<double>() - earth)[2], want, 2e-5) << k;  // the float copy
  }
}

TEST(CompareReport, EmbeddedPlotsAreNonEmpty) {
  // GIVEN a comparison with a missing effect
  SensorParams p = deterministic_part(mpu6050_defaults());
  p.white_noise.enabled = true;
  SensorParams q = p;
  q.scale_factor.value_pct = Eigen::Vector3d(3.0, 0.0, 0.0);
  const auto lg = testlog::make_log(q, p, 60.0, 7);
  const Replay r = replay_samples(lg.samples, lg.meta, lg.fields, ReplayOptions{}, "t.csv");
  CompareModel m = default_compare_model();
  m.sensor = {p, p};
  const auto dir = test::temp_path("driftless_report_plots_test");
  std::filesystem::remove_all(dir);
  // WHEN the report is written
  write_report(compare(r, m, CompareOptions{}), dir);
  std::ifstream f(dir / "report.html");
  std::stringstream ss;
  ss << f.rdbuf();
  const std::string html = ss.str();
  // THEN it embeds all four plots, each a PNG of real size, and gnuplot drew data in each
  int images = 0;
  for (std::size_t at = html.find("data:image/png;base64,"); at != std::string::npos;
       at = html.find("data:image/png;base64,", at + 1)) {
    const std::size_t start = at + 22, end = html.find('\'', start);
    ASSERT_NE(end, std::string::npos);
    EXPECT_EQ(html.substr(start, 8), "iVBORw0K");  // base64 of the PNG signature
    EXPECT_GT(end - start, 8000u) << "image " << images << " is tiny";
    ++images;
  }
  EXPECT_EQ(images, 4) << "plots missing (is gnuplot on PATH?)";
  for (const char* stem : {"residual", "windows", "adev", "regimes"}) {
    std::ifstream lf(dir / "plots" / (std::string(stem) + ".log"));
    std::stringstream ls;
    ls << lf.rdbuf();
    EXPECT_EQ(ls.str().find("no valid points"), std::string::npos) << stem << ": " << ls.str();
    EXPECT_GT(std::filesystem::file_size(dir / "plots" / (std::string(stem) + ".dat")), 100u) << stem;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace driftless::diagnose
