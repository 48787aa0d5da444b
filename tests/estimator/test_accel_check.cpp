// estimator/accel_check: the accel columns' unit at the standstills against gravity in each unit
// of the unit table (stop-27 finding F19), gravity from ref_q in each sensor's axes (F33), the
// witness that ref_q turns (box dwells with gravity from ref_q), and a calibration's uncertain G/E
// elements (F22). Closed forms, seeded.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/Geometry>

#include "estimator/accel_check.hpp"

namespace driftless::est {
namespace {

TEST(AccelCheck, ClassifiesGravityInEachUnitOfTheUnitTable) {
  constexpr double g = kStandardGravityMps2;
  EXPECT_EQ(classify_accel(g, 10).reading, AccelReading::kOk);
  EXPECT_EQ(classify_accel(1.08 * g, 10).reading, AccelReading::kOk);  // a car's 0.08 g, within 10 %
  const AccelSensorReading in_g = classify_accel(1.0, 10);
  EXPECT_EQ(in_g.reading, AccelReading::kOtherUnit);
  EXPECT_EQ(in_g.unit_suffix, "g");
  EXPECT_NEAR(in_g.factor, g, 1e-12);
  const AccelSensorReading in_mg = classify_accel(998.0, 10);
  EXPECT_EQ(in_mg.unit_suffix, "mg");
  EXPECT_NEAR(in_mg.factor, g * 1e-3, 1e-15);
  EXPECT_EQ(classify_accel(1.0e6, 10).unit_suffix, "ug");
  EXPECT_EQ(classify_accel(0.0, 10).reading, AccelReading::kEmpty);
  EXPECT_EQ(classify_accel(0.05, 10).reading, AccelReading::kEmpty);  // below 1 % of g
  EXPECT_EQ(classify_accel(5.0, 10).reading, AccelReading::kOff);     // 0.51 g: no unit
  EXPECT_EQ(classify_accel(g, 0).reading, AccelReading::kNotChecked);
}

TEST(AccelCheck, TheMedianOfTheRestingSamplesWithinItsBin) {
  // |f| uniform on [0.8 g, 1.2 g] while both platforms rest, 5 g while they move (not counted);
  // sensor 2 in g: the median 1 g to the histogram's 0.58 % bins
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.8, 1.2);
  AccelCheck check;
  Sample s;
  for (int k = 0; k < 20000; ++k) {
    const Eigen::Vector3d dir = Eigen::Vector3d(u(rng) - 1.0, u(rng) - 1.0, 1.0).normalized();
    const double scale = u(rng);
    const bool rest = k % 4 != 0;
    s.accel1_mps2 = dir * (rest ? scale * kStandardGravityMps2 : 5.0 * kStandardGravityMps2);
    s.accel2_mps2 = dir * (rest ? scale : 5.0);
    check.push(s, rest);
  }
  const AccelCheckResult r = check.finish();
  EXPECT_EQ(r[0].samples, 15000u);
  EXPECT_NEAR(r[0].median_norm / kStandardGravityMps2, 1.0, 0.006 + 0.01);  // bin + sampling (0.4/sqrt(15000))
  EXPECT_EQ(r[0].reading, AccelReading::kOk);
  EXPECT_EQ(r[1].reading, AccelReading::kOtherUnit);
  EXPECT_EQ(r[1].unit_suffix, "g");
}

TEST(AccelCheck, AllZeroColumnsAreEmpty) {
  AccelCheck check;
  Sample s;
  s.accel1_mps2 = Eigen::Vector3d(0.0, 0.0, kStandardGravityMps2);
  s.accel2_mps2.setZero();
  for (int k = 0; k < 100; ++k) check.push(s, true);
  const AccelCheckResult r = check.finish();
  EXPECT_EQ(r[0].reading, AccelReading::kOk);
  EXPECT_EQ(r[1].reading, AccelReading::kEmpty);
  EXPECT_EQ(r[1].median_norm, 0.0);
}

TEST(AccelCheck, GravityFromRefQIsUpInEachSensorsAxes) {
  // the box rolled 30 deg about x and turned 40 deg about z: gravity's specific force in sensor i's
  // axes is Rot(hinge_i, angle_i)^T C^T (0, 0, g), C = Rz(40) Rx(30)
  EstimatorConfig cfg;
  BoxGeometry box;
  box.sample_rate_hz = 100.0;
  const DriftlessFilter filter(cfg, box);
  const Eigen::Matrix3d C = (Eigen::AngleAxisd(40.0 * kRadPerDeg, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(30.0 * kRadPerDeg, Eigen::Vector3d::UnitX())).toRotationMatrix();
  const Eigen::Quaterniond q(C);
  Sample s;
  s.ref_q_wxyz = Eigen::Vector4d(q.w(), q.x(), q.y(), q.z());
  s.plat1_deg = 90.0;
  s.plat2_deg = -90.0;
  gravity_from_ref_q(filter, s);
  const Eigen::Vector3d up_box = C.transpose() * Eigen::Vector3d(0.0, 0.0, kStandardGravityMps2);
  const Eigen::Matrix3d R1 = Eigen::AngleAxisd(90.0 * kRadPerDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d R2 = Eigen::AngleAxisd(-90.0 * kRadPerDeg, Eigen::Vector3d::UnitX()).toRotationMatrix();
  EXPECT_LT((s.accel1_mps2 - R1.transpose() * up_box).norm(), 1e-12);
  EXPECT_LT((s.accel2_mps2 - R2.transpose() * up_box).norm(), 1e-12);
  // rolled 30 deg: the box's own z reads g cos 30
  EXPECT_NEAR(up_box.z(), kStandardGravityMps2 * std::cos(30.0 * kRadPerDeg), 1e-12);
  // a platform whose angle is unknown (moving) gets none; no ref_q, none at all
  s.plat2_deg = kNaN;
  gravity_from_ref_q(filter, s);
  EXPECT_TRUE(s.accel1_mps2.allFinite());
  EXPECT_FALSE(s.accel2_mps2.allFinite());
  s.ref_q_wxyz.setConstant(kNaN);
  gravity_from_ref_q(filter, s);
  EXPECT_FALSE(s.accel1_mps2.allFinite());
}


TEST(AccelCheck, UncertainCalibrationElementsByTheirSigmaAgainstTheirValue) {
  Calibration cal;
  cal.has_g_sigma = true;
  cal.G_sigma_dps_per_g[0].setConstant(0.001);        // below the floor: known
  cal.G_dps_per_g[1](0, 1) = 0.0;
  cal.G_sigma_dps_per_g[1](0, 1) = 0.0577;            // the prior: not observed
  cal.G_dps_per_g[1](1, 1) = 0.1;
  cal.G_sigma_dps_per_g[1](1, 1) = 0.02;              // 5 sigma from 0: known
  cal.G_dps_per_g[1](2, 1) = 0.03;
  cal.G_sigma_dps_per_g[1](2, 1) = 0.02;              // 1.5 sigma: not small against it
  cal.has_scale_misalign = true;
  cal.E_sigma_frac[0](2, 0) = 0.01;                   // E's prior on a static box
  const std::vector<UncertainElement> el = uncertain_calibration(cal);
  ASSERT_EQ(el.size(), 3u);  // sensor by sensor, G before E, row-major
  EXPECT_EQ(el[0].sensor, 1);
  EXPECT_FALSE(el[0].g);
  EXPECT_EQ(el[0].row, 2);
  EXPECT_EQ(el[0].col, 0);
  EXPECT_EQ(el[1].sensor, 2);
  EXPECT_TRUE(el[1].g);
  EXPECT_EQ(el[1].row, 0);
  EXPECT_EQ(el[1].col, 1);
  EXPECT_DOUBLE_EQ(el[1].sigma, 0.0577);
  EXPECT_EQ(el[2].row, 2);
  EXPECT_DOUBLE_EQ(el[2].value, 0.03);
  HealthReport h;
  add_calib_finding(h, cal);
  ASSERT_EQ(h.findings.size(), 1u);
  EXPECT_EQ(h.findings[0].cause, HealthCause::kCalibUncertain);
  EXPECT_EQ(h.verdict, HealthVerdict::kDegraded);
  EXPECT_EQ(h.findings[0].count, 3u);
  EXPECT_EQ(h.findings[0].components[0], 110 + 3 * 2 + 0);  // sensor 1, E, [z][x]
  EXPECT_EQ(h.findings[0].components[2], 200 + 3 * 2 + 1);  // sensor 2, G, [z][y]
}

}  // namespace
}  // namespace driftless::est
