// One IMU against motion capture (issue 16): single-sensor logs ('sensors: 1') with ref_q from
// the independent generator (tests/diagnose/independent_log.py --single), diagnosed with the
// embedded default model as `driftless diagnose` does (docs/compare.md "Single-sensor logs").
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>
#include <stdexcept>

#include "diagnose/report.hpp"
#include "tests/diagnose/independent_logs.hpp"

namespace driftless::diagnose {
namespace {

// every selected effect other than `e` belongs to the signal chain
bool others_signal_chain(const CompareResult& r, Effect e) {
  for (const auto& c : r.selected)
    if (c.effect != e && c.family() != Family::kSignalChain) return false;
  return true;
}

// no selected or noise-model parameter names sensor 2
bool nothing_on_sensor_2(const CompareResult& r) {
  for (const auto* list : {&r.selected, &r.noise_model})
    for (const auto& c : *list)
      for (const auto& p : c.params)
        if (p.ref.sensor == 1) return false;
  return true;
}

indep::Source single_source(int seed, double duration_s) {
  indep::Source src;
  src.seed = seed;
  src.duration_s = duration_s;
  src.single = true;
  return src;
}

TEST(SingleImu, PlantedScaleIsFoundAndApplyCloses) {
  // GIVEN one IMU on a pan/tilt body, no DLPF (the model has DLPF_CFG 3), 1.5x the MPU6050's
  // noise, its y axis reading 2 % high, and the body's attitude from motion capture
  indep::Source src = single_source(5, 90.0);
  src.noise_scale = 1.5;
  src.plants = {"scale:1:y:2"};
  const auto log = indep::generate(src, "single_scale");
  // WHEN it is diagnosed with the embedded model
  const CompareResult r = indep::diagnose_log(log);
  // THEN the scale error is selected within 20 %, besides at most the signal chain, on sensor 1
  ASSERT_EQ(r.verdict, Verdict::kMissingEffect) << r.statement;
  EXPECT_EQ(r.sensors, 1);
  const Candidate* scale = indep::selected(r, Effect::kScaleFactor);
  ASSERT_NE(scale, nullptr) << r.statement;
  const FittedParam* fp = find_param(*scale, "s1.y.value_pct");
  ASSERT_NE(fp, nullptr) << r.statement;
  EXPECT_NEAR(fp->new_value(), 2.0, 0.4) << r.statement;
  EXPECT_TRUE(others_signal_chain(r, Effect::kScaleFactor)) << r.statement;
  EXPECT_TRUE(nothing_on_sensor_2(r)) << r.statement;
  // AND sensor 2's channels are absent from the summaries (null in diagnosis.json)
  EXPECT_TRUE(std::isnan(r.channels[3].rms_dps));
  EXPECT_TRUE(std::isfinite(r.channels[0].rms_dps));
  // AND after --apply the log is consistent with the written model
  const CompareResult again = indep::apply_and_compare(log, r, "single_scale");
  EXPECT_EQ(again.verdict, Verdict::kConsistent) << again.statement;
  std::filesystem::remove(log);
}

TEST(SingleImu, GSensitivityWithTheAccelerometerIsFound) {
  // GIVEN one IMU with its accelerometer, its x axis sensing 0.1 deg/s per g along x, a 200 Hz
  // sweep of the body (pitch +-25 deg: the specific force along x swings by +-0.4 g; only that
  // swing counts, a constant part is the turn-on bias)
  indep::Source src = single_source(8, 90.0);
  src.rate_hz = 200.0;
  src.motion = "sweep";
  src.accel = true;
  src.plants = {"gsens:1:x:x:0.1"};
  const auto log = indep::generate(src, "single_gsens");
  // WHEN diagnosed
  const CompareResult r = indep::diagnose_log(log);
  std::filesystem::remove(log);
  // THEN the g-sensitivity term is found within 20 %, from the log's accel columns
  const Candidate* g = indep::selected(r, Effect::kGSensitivity);
  ASSERT_NE(g, nullptr) << r.statement;
  const FittedParam* fp = find_param(*g, "s1.matrix_dps_per_g[x][x]");
  ASSERT_NE(fp, nullptr) << r.statement;
  EXPECT_NEAR(fp->new_value(), 0.1, 0.02) << r.statement;
  EXPECT_TRUE(others_signal_chain(r, Effect::kGSensitivity)) << r.statement;
}

TEST(SingleImu, CleanLogIsConsistentOrOnlyItsSignalChain) {
  // GIVEN a clean single-IMU log with another DLPF (cfg 1) on a wobbling body at 100 Hz
  indep::Source src = single_source(12, 90.0);
  src.motion = "wobble";
  src.dlpf = "cfg:1";
  const auto log = indep::generate(src, "single_clean");
  // WHEN diagnosed
  const CompareResult r = indep::diagnose_log(log);
  std::filesystem::remove(log);
  // THEN nothing physical is reported, and nothing on the absent sensor
  EXPECT_TRUE(r.verdict == Verdict::kConsistent || others_signal_chain(r, Effect::kCount)) << r.statement;
  EXPECT_NE(r.verdict, Verdict::kUnexplained) << r.statement;
  EXPECT_TRUE(nothing_on_sensor_2(r)) << r.statement;
  // AND report.html has no row for the absent sensor's channels (no 'nan' cells)
  const auto dir = std::filesystem::temp_directory_path() / "driftless-single-clean-report";
  write_report(r, dir);
  std::ifstream in(dir / "report.html");
  const std::string html((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(html.find("gyro1_x"), std::string::npos);
  EXPECT_EQ(html.find("gyro2_"), std::string::npos);
  EXPECT_EQ(html.find(">nan<"), std::string::npos);
  std::filesystem::remove_all(dir);
  // AND the candidates a single IMU cannot show are not tested: end stops and flips need
  // platforms; sensor 1's sample delay is the box time offset (one of them is tested)
  for (const auto& c : r.not_supported) {
    const bool platform_only = c.effect == Effect::kEndStopError || c.effect == Effect::kFlipTransient;
    if (platform_only || c.effect == Effect::kSampleDelay) {
      EXPECT_FALSE(c.testable) << effect_info(c.effect).id;
    }
  }
}

TEST(SingleImu, WithoutRefQItIsRefusedNamingTheFile) {
  // GIVEN a single-sensor log without ref_q (a static recording)
  const auto path = test::temp_path("driftless_single_noref.csv");
  {
    std::ofstream f(path);
    f << "# format: driftless-log 1\n# complete: true\n# sensors: 1\n# sample_rate_hz: 100\n"
         "t,gyro1_x,gyro1_y,gyro1_z\n";
    for (int k = 0; k < 500; ++k) f << k * 0.01 << ",0.01,-0.02,0.003\n";
  }
  // WHEN it is replayed for a comparison THEN the error names the file and what is missing
  try {
    (void)replay_log(path, ReplayOptions{});
    ADD_FAILURE() << "a single-sensor log without ref_q was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("ref_q"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace driftless::diagnose
