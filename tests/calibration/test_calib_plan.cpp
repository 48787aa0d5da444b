// Rig plan and calib.yaml: a closed-form rig log cut by its plan fits back to the planted M;
// plans that do not match the log, saturating rate tables and bad files give clear errors.
#include <fstream>
#include <functional>
#include <string>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "tests/calibration/calib_closed_form_rig.hpp"
#include "calibration/calib_file.hpp"
#include "calibration/rig_plan.hpp"
#include "tests/temp_path.hpp"

namespace driftless::calib {
namespace {

std::filesystem::path temp_path(const std::string& name) {
  auto dir = test::temp_path("driftless_test_calib_plan");
  std::filesystem::create_directories(dir);
  return dir / name;
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no exception)";
}

ProcedureParams short_procedure() {
  ProcedureParams p;
  p.segment_s = 20.0;
  return p;
}

struct RigRun {
  RigPlan plan;
  std::vector<Sample> log;
  log::Metadata meta;
  testing::ClosedFormRig rig;
};

RigRun run_rig(std::uint64_t seed = 1, double sigma = 0.05) {
  RigRun r;
  r.plan = standard_plan(short_procedure());
  r.rig.M = testing::planted_matrices();
  r.rig.sigma_dps = sigma;
  r.log = r.rig.run(r.plan, seed, &r.meta);
  return r;
}

TEST(CalibPlan, StandardPlanIsThePapersProcedure) {
  const RigPlan plan = standard_plan({});
  ASSERT_EQ(plan.segments.size(), 6u);
  EXPECT_EQ(plan.segments[0].name, "XY@-90");
  EXPECT_EQ(plan.segments[1].name, "YZ@-90");
  EXPECT_EQ(plan.segments[2].name, "XZ@-90");
  EXPECT_EQ(plan.segments[3].name, "XY@+90");
  EXPECT_EQ(plan.segments[2].axis_box, Eigen::Vector3d::UnitY());
  EXPECT_DOUBLE_EQ(plan.segments[0].t_end_s - plan.segments[0].t_start_s, 60.0);
  EXPECT_DOUBLE_EQ(plan.segments[0].rate_dps, 50.0);
  // the square wave: +rate first, reversing every half period, plateau after the settle time
  const PlanSegment& s = plan.segments[0];
  EXPECT_EQ(s.sign_at(s.t_start_s + 0.5), 1.0);
  EXPECT_EQ(s.sign_at(s.t_start_s + 2.5), -1.0);
  EXPECT_FALSE(s.on_plateau(s.t_start_s + 2.1));
  EXPECT_TRUE(s.on_plateau(s.t_start_s + 2.4));
  EXPECT_EQ(s.sign_at(s.t_end_s), 0.0);
}

TEST(CalibPlan, OrientationMountPutsTheTableAxisUp) {
  for (const char* o : {"XY", "YZ", "XZ"}) {
    const Eigen::Vector3d a = orientation_axis(o);
    EXPECT_LT((orientation_mount(a) * a - Eigen::Vector3d::UnitZ()).norm(), 1e-12) << o;
  }
}

TEST(CalibPlan, PlanFileRoundTrips) {
  RigPlan plan = standard_plan({});
  plan.latitude_deg = 48.5;
  plan.segments[1].first_sign = -1.0;
  const auto path = temp_path("plan.yaml");
  save_rig_plan(path, plan);
  const RigPlan back = load_rig_plan(path);
  ASSERT_EQ(back.segments.size(), plan.segments.size());
  EXPECT_EQ(back.latitude_deg, 48.5);
  for (std::size_t k = 0; k < plan.segments.size(); ++k) {
    EXPECT_EQ(back.segments[k].name, plan.segments[k].name);
    EXPECT_EQ(back.segments[k].axis_box, plan.segments[k].axis_box);
    EXPECT_EQ(back.segments[k].t_start_s, plan.segments[k].t_start_s);
    EXPECT_EQ(back.segments[k].first_sign, plan.segments[k].first_sign);
  }
}

TEST(CalibPlan, RateTableThatSaturatesTheGyroIsRefused) {
  ProcedureParams p;
  p.rate_dps = 300.0;  // MPU6050 FS_SEL=0: +-250 deg/s
  const std::string msg = message_of([&] { standard_plan(p); });
  EXPECT_NE(msg.find("saturates the gyro"), std::string::npos) << msg;
  EXPECT_NE(msg.find("300 deg/s"), std::string::npos) << msg;
  EXPECT_NE(msg.find("+-250 deg/s"), std::string::npos) << msg;
}

TEST(CalibPlan, SaturatedSamplesInTheLogAreRefused) {
  // GIVEN a sensor that clips at 40 deg/s (a smaller range than the plan says) on a 50 deg/s table
  RigRun r = run_rig();
  for (auto& s : r.log) s.gyro1_dps = s.gyro1_dps.cwiseMin(40.0).cwiseMax(-40.0);
  const std::string msg = message_of([&] { extract_segments(r.log, r.meta, r.plan, "rig.csv"); });
  EXPECT_NE(msg.find("saturates the gyro"), std::string::npos) << msg;
  EXPECT_NE(msg.find("gyro 1"), std::string::npos) << msg;
}

TEST(CalibPlan, LogCutByItsPlanFitsThePlantedMatrices) {
  const RigRun r = run_rig(3);
  ExtractReport rep;
  const auto segs = extract_segments(r.log, r.meta, r.plan, "rig.csv", &rep);
  EXPECT_TRUE(rep.earth_rate_removed);
  ASSERT_EQ(segs.size(), 6u);
  for (auto n : rep.samples_used) EXPECT_GT(n, 1500u);  // 20 s minus the settle windows
  const est::CalibFit fit = est::fit_calibration(segs);
  for (int i = 0; i < 2; ++i)
    for (int p = 0; p < 2; ++p) {
      const auto& f = fit.fit[i][p];
      const Eigen::Matrix3d z = (f.M - r.rig.M.M(i, p)).cwiseQuotient(f.M_sigma);
      EXPECT_LT(z.cwiseAbs().maxCoeff(), 5.0) << z;
      // Earth rate removed: the bias is the sensor's own (within 5 sigma)
      for (const auto& b : f.biases)
        EXPECT_LT(((b.bias_dps - r.rig.bias_dps[i]).cwiseQuotient(b.sigma_dps)).cwiseAbs().maxCoeff(), 5.0);
    }
}

TEST(CalibPlan, NoiseFreeQuantizedPlateausAreNotMistakenForClipping) {
  RigRun r;
  r.plan = standard_plan(short_procedure());
  r.rig.M = testing::planted_matrices();
  r.rig.sigma_dps = 0.0;
  r.rig.lsb_dps = 1.0 / 131.0;  // every plateau sample on the same code
  r.log = r.rig.run(r.plan, 1, &r.meta);
  EXPECT_NO_THROW(extract_segments(r.log, r.meta, r.plan, "rig.csv"));
}

TEST(CalibPlan, PlanThatDoesNotMatchTheLogIsRefused) {
  const RigRun r = run_rig(4);
  {  // the log ends before the plan does
    RigPlan plan = r.plan;
    plan.segments.back().t_end_s += 100.0;
    const std::string msg = message_of([&] { extract_segments(r.log, r.meta, plan, "rig.csv"); });
    EXPECT_NE(msg.find("plan does not match the log rig.csv"), std::string::npos) << msg;
    EXPECT_NE(msg.find("lies outside the log"), std::string::npos) << msg;
  }
  {  // the plan says +90 where the log says -90
    RigPlan plan = r.plan;
    plan.segments[0].plat1_deg = 90.0;
    const std::string msg = message_of([&] { extract_segments(r.log, r.meta, plan, "rig.csv"); });
    EXPECT_NE(msg.find("plat1_deg is -90"), std::string::npos) << msg;
  }
  {  // orientations swapped: ref_q shows a turn about x where the plan says z
    RigPlan plan = r.plan;
    plan.segments[0].orientation = "YZ";
    plan.segments[0].axis_box = Eigen::Vector3d::UnitX();
    const std::string msg = message_of([&] { extract_segments(r.log, r.meta, plan, "rig.csv"); });
    EXPECT_NE(msg.find("segment 'XY@-90'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("ref_q"), std::string::npos) << msg;
  }
  {  // the square wave's phase is off by a half period: without ref_q only the gyros tell
    RigRun nq = r;
    for (auto& s : nq.log) s.ref_q_wxyz.setConstant(kNaN);
    nq.plan.segments[2].first_sign = -1.0;
    const std::string msg = message_of([&] { extract_segments(nq.log, nq.meta, nq.plan, "rig.csv"); });
    EXPECT_NE(msg.find("does not follow the planned +-50 deg/s square wave"), std::string::npos) << msg;
    EXPECT_NE(msg.find("segment 'XZ@-90'"), std::string::npos) << msg;
  }
}

TEST(CalibPlan, WrittenInTheFormatOfDocsCalibration) {
  // GIVEN a plan with a named and a custom orientation
  RigPlan plan;
  PlanSegment a;
  a.name = "XY@-90";
  a.t_start_s = 2;
  a.t_end_s = 14;
  PlanSegment b = a;
  b.name = "tilted";
  b.orientation = "custom";
  b.axis_box = Eigen::Vector3d(0.6, 0, 0.8);
  b.plat1_deg = b.plat2_deg = 90;
  b.t_start_s = 20;
  b.t_end_s = 32;
  b.first_sign = -1;
  plan.segments = {a, b};
  plan.latitude_deg = 52;
  // THEN the file is this text, byte for byte (axis_box only with custom; latitude when set)
  EXPECT_EQ(rig_plan_yaml(plan),
            "# rig plan for driftless calibrate --plan (docs/calibration.md)\n"
            "format: driftless-rig-plan 1\n"
            "gyro_full_scale_dps: 250\n"
            "max_rate_fraction: 0.8\n"
            "latitude_deg: 52\n"
            "segments:\n"
            "  - {name: XY@-90, orientation: XY, plat1_deg: -90, plat2_deg: -90, t_start_s: 2, t_end_s: 14, "
            "rate_dps: 50, half_period_s: 2, first_sign: 1, settle_s: 0.3}\n"
            "  - {name: tilted, orientation: custom, axis_box: [0.6, 0, 0.8], plat1_deg: 90, plat2_deg: 90, "
            "t_start_s: 20, t_end_s: 32, rate_dps: 50, half_period_s: 2, first_sign: -1, settle_s: 0.3}\n");
  // AND `defaults:` may stand after the segments; a key in another unit converts
  const RigPlan back = parse_rig_plan(
      "segments:\n  - {name: a, orientation: YZ, plat1_deg: -90, plat2_deg: -90, t_start_ms: 1500, t_end_s: 20}\n"
      "defaults: {rate_dps: 40}\n",
      "d.yaml");
  ASSERT_EQ(back.segments.size(), 1u);
  EXPECT_EQ(back.segments[0].rate_dps, 40.0);
  EXPECT_EQ(back.segments[0].t_start_s, 1.5);
  EXPECT_EQ(back.segments[0].axis_box, Eigen::Vector3d::UnitX());
  // AND a missing required key is named with the segment's line
  const std::string msg = message_of([] {
    parse_rig_plan("segments:\n  - {name: a, orientation: XY, plat1_deg: -90, t_start_s: 0, t_end_s: 60}\n", "m.yaml");
  });
  EXPECT_NE(msg.find("m.yaml:2: segments[0].plat2_deg: missing"), std::string::npos) << msg;
}

TEST(CalibPlan, BadPlanFilesNameFileAndKey) {
  const auto path = temp_path("bad_plan.yaml");
  std::ofstream(path) << "format: driftless-rig-plan 1\nsegments:\n"
                         "  - {name: a, orientation: XW, plat1_deg: -90, plat2_deg: -90, t_start_s: 0, t_end_s: 60}\n";
  std::string msg = message_of([&] { load_rig_plan(path); });
  EXPECT_NE(msg.find("bad_plan.yaml:3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("segments[0].orientation"), std::string::npos) << msg;
  std::ofstream(path) << "segments:\n"
                         "  - {name: a, orientation: XY, plat1_deg: -45, plat2_deg: -90, t_start_s: 0, t_end_s: 60}\n";
  msg = message_of([&] { load_rig_plan(path); });
  EXPECT_NE(msg.find("must be -90 or +90"), std::string::npos) << msg;
  std::ofstream(path) << "segments:\n"
                         "  - {name: a, orientation: XY, plat1_deg: -90, plat2_deg: -90, t_start_s: 0, t_end_s: 60, speed: 3}\n";
  msg = message_of([&] { load_rig_plan(path); });
  EXPECT_NE(msg.find("unknown key"), std::string::npos) << msg;
}

TEST(CalibFile, RoundTripKeepsEveryMatrixBitExact) {
  const RigRun r = run_rig(5);
  ExtractReport rep;
  const auto segs = extract_segments(r.log, r.meta, r.plan, "rig.csv", &rep);
  const est::CalibFit fit = est::fit_calibration(segs);
  RigConditions rig;
  rig.source = "test";
  rig.latitude_deg = rep.latitude_deg;
  rig.earth_rate_removed = rep.earth_rate_removed;
  rig.plan = r.plan;
  rig.samples_used = rep.samples_used;
  const auto path = temp_path("calib.yaml");
  save_calib(path, fit, rig);
  const CalibFile back = load_calib(path);
  EXPECT_EQ(back.method, "least_squares");
  EXPECT_TRUE(back.earth_rate_removed);
  EXPECT_EQ(back.latitude_deg, 52.0);
  for (int i = 0; i < 2; ++i)
    for (int p = 0; p < 2; ++p) {
      EXPECT_EQ(back.M.M(i, p), fit.fit[i][p].M);
      EXPECT_EQ(back.M_sigma[i][p], fit.fit[i][p].M_sigma);
    }
  // the physical errors are written for people to read
  const YAML::Node y = YAML::LoadFile(path.string());
  EXPECT_NEAR(y["sensor1"]["errors"]["travel_error_deg"].as<double>(), 2.0, 0.05);
  EXPECT_NEAR(y["sensor2"]["errors"]["travel_error_deg"].as<double>(), -2.0, 0.05);
}

TEST(CalibFile, BadFilesAreRefusedWithFileAndKey) {
  const auto path = temp_path("bad_calib.yaml");
  std::ofstream(path) << "format: driftless-calib 1\nsensor1:\n  minus90: {M: [[1,0,0],[0,1,0]]}\n";
  std::string msg = message_of([&] { load_calib(path); });
  EXPECT_NE(msg.find("sensor1.minus90.M"), std::string::npos) << msg;
  std::ofstream(path) << "format: something else\n";
  msg = message_of([&] { load_calib(path); });
  EXPECT_NE(msg.find("driftless-calib 1"), std::string::npos) << msg;
  std::ofstream(path) << "format: driftless-calib 1\n"
                         "sensor1: {minus90: {M: [[1,0,0],[0,1,0],[0,0,1]]}, plus90: {M: [[1,0,0],[0,1,0],[0,0,1]]}}\n"
                         "sensor2: {minus90: {M: [[1,0,0],[0,1,0],[0,0,0]]}, plus90: {M: [[1,0,0],[0,1,0],[0,0,1]]}}\n";
  msg = message_of([&] { load_calib(path); });
  EXPECT_NE(msg.find("sensor 2 at -90"), std::string::npos) << msg;
  // every key is one of the table's: a misspelt one is refused, not ignored
  std::ofstream(path) << "format: driftless-calib 1\n"
                         "rig: {source: x, latitude_deg: null, earth_rate_remove: true}\n"
                         "sensor1: {minus90: {M: [[1,0,0],[0,1,0],[0,0,1]]}, plus90: {M: [[1,0,0],[0,1,0],[0,0,1]]}}\n"
                         "sensor2: {minus90: {M: [[1,0,0],[0,1,0],[0,0,1]]}, plus90: {M: [[1,0,0],[0,1,0],[0,0,1]]}}\n";
  msg = message_of([&] { load_calib(path); });
  EXPECT_NE(msg.find("bad_calib.yaml:2: rig.earth_rate_remove: unknown key"), std::string::npos) << msg;
  std::ofstream(path) << "format: driftless-calib 1\n"
                         "sensor1: {minus90: {M: [[1,0,0],[0,1,0],[0,0,1]]}, plus90: {M: [[1,0,0],[0,1,0],[0,0,1]]}}\n";
  msg = message_of([&] { load_calib(path); });
  EXPECT_NE(msg.find("sensor2: missing"), std::string::npos) << msg;
}

}  // namespace
}  // namespace driftless::calib
