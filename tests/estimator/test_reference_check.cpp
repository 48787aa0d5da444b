// GIVEN a box turning by a closed-form attitude (C_enu_from_body = Rz(psi) Rx(phi), its exact
// body rate written here, apart from twin/) WHEN ref_q is written in the log's convention, its
// conjugate, scalar last, another body's, or the gyros read 2x THEN the reference check names the
// convention the data fit, with misfits against their closed forms (docs/estimator.md 4.1).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "estimator/geometry.hpp"
#include "estimator/reference_check.hpp"

namespace driftless::est {
namespace {

constexpr double kDt = 0.01;  // s, 100 Hz

struct Motion {
  double yaw_amp_deg = 60.0, yaw_w = 0.3;    // psi = A sin(w t)
  double roll_amp_deg = 0.0, roll_w = 0.7;   // phi = B sin(w t)
};

Eigen::Quaterniond q_enu_from_body(const Motion& m, double t) {
  const double psi = m.yaw_amp_deg * kRadPerDeg * std::sin(m.yaw_w * t);
  const double phi = m.roll_amp_deg * kRadPerDeg * std::sin(m.roll_w * t);
  return Eigen::Quaterniond(Eigen::AngleAxisd(psi, Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(phi, Eigen::Vector3d::UnitX()));
}

// w_nb = Rx(phi)^T (0, 0, psidot) + (phidot, 0, 0), deg/s
Eigen::Vector3d body_rate_dps(const Motion& m, double t) {
  const double psidot = m.yaw_amp_deg * m.yaw_w * std::cos(m.yaw_w * t);
  const double phidot = m.roll_amp_deg * m.roll_w * std::cos(m.roll_w * t);
  const double phi = m.roll_amp_deg * kRadPerDeg * std::sin(m.roll_w * t);
  const Eigen::Matrix3d rx = Eigen::AngleAxisd(phi, Eigen::Vector3d::UnitX()).toRotationMatrix();
  return rx.transpose() * Eigen::Vector3d(0.0, 0.0, psidot) + Eigen::Vector3d(phidot, 0.0, 0.0);
}

using Columns = std::function<Eigen::Vector4d(const Eigen::Quaterniond&)>;

ReferenceFit run(const Motion& m, const Columns& columns, double gyro_gain = 1.0, double sigma_dps = 0.01,
                 double duration_s = 120.0) {
  ReferenceCheck check;
  Sample s;
  for (int k = 0; k * kDt <= duration_s; ++k) {
    s.t_s = k * kDt;
    s.ref_q_wxyz = columns(q_enu_from_body(m, s.t_s));
    check.push(s, gyro_gain * body_rate_dps(m, s.t_s), sigma_dps);
  }
  return check.finish();
}

Eigen::Vector4d as_written(const Eigen::Quaterniond& q) { return {q.w(), q.x(), q.y(), q.z()}; }
Eigen::Vector4d conjugated(const Eigen::Quaterniond& q) { return {q.w(), -q.x(), -q.y(), -q.z()}; }
Eigen::Vector4d scalar_last(const Eigen::Quaterniond& q) { return {q.x(), q.y(), q.z(), q.w()}; }

TEST(ReferenceCheck, TheLogsConventionFits) {
  Motion m;
  m.roll_amp_deg = 20.0;
  const ReferenceFit f = run(m, as_written);
  EXPECT_EQ(f.verdict, RefFitVerdict::kFits);
  EXPECT_GT(f.windows, 50u);
  // the trapezoid over 10 ms steps of a <= 18 deg/s, 0.3 rad/s sine: error ~ (w dt)^2 / 12 of the turn
  EXPECT_LT(f.misfit[0], 1e-6);
}

TEST(ReferenceCheck, AConjugatedReferenceOnALevelYawingBoxTurnsTheOtherWay) {
  // level box, yaw only: the conjugate's body-axis turn is exactly -theta, misfit |2 theta|^2/|theta|^2 = 4
  const ReferenceFit f = run(Motion{}, conjugated);
  EXPECT_EQ(f.verdict, RefFitVerdict::kOtherConvention);
  EXPECT_EQ(f.best, RefConvention::kBodyFromEnuWxyz);
  EXPECT_NEAR(f.misfit[0], 4.0, 1e-3);
  EXPECT_LT(f.misfit[static_cast<std::size_t>(RefConvention::kBodyFromEnuWxyz)], 1e-6);
  // the example window: the gyros and ref_q turn by opposite angles about up (z)
  // ... up to the trapezoid's error, (w dt)^2 / 12 = 7.5e-7 of the ~18 deg turn: 1.35e-5 deg
  EXPECT_NEAR(f.example_gyro_deg.z(), -f.example_ref_deg.z(), 3e-5);
  EXPECT_GT(std::fabs(f.example_gyro_deg.z()), 10.0);
}

TEST(ReferenceCheck, ScalarLastColumnsAreNamed) {
  Motion m;
  m.roll_amp_deg = 20.0;
  const ReferenceFit f = run(m, scalar_last);
  EXPECT_EQ(f.verdict, RefFitVerdict::kOtherConvention);
  EXPECT_EQ(f.best, RefConvention::kEnuFromBodyXyzw);
  EXPECT_GT(f.misfit[0], 0.5);
  const ReferenceFit g = run(m, [](const Eigen::Quaterniond& q) { return scalar_last(q.conjugate()); });
  EXPECT_EQ(g.best, RefConvention::kBodyFromEnuXyzw);
  EXPECT_EQ(g.verdict, RefFitVerdict::kOtherConvention);
}

TEST(ReferenceCheck, GyrosReadingTwiceTheTurnFitNoConvention) {
  // gyro turn 2 theta against theta: sum |2t - t|^2 / sum |2t|^2 = 1/4, for a level yawing box
  const ReferenceFit f = run(Motion{}, as_written, 2.0);
  EXPECT_EQ(f.verdict, RefFitVerdict::kNoFit);
  EXPECT_NEAR(f.misfit[0], 0.25, 1e-3);
}

TEST(ReferenceCheck, AnotherBodysAttitudeFitsNoConvention) {
  // a reference IMU mounted turned 90 deg about x: its yaw turn shows about -y of the box
  const Eigen::Quaterniond mount(Eigen::AngleAxisd(0.5 * kPi, Eigen::Vector3d::UnitX()));
  const ReferenceFit f = run(Motion{}, [&](const Eigen::Quaterniond& q) { return as_written(q * mount); });
  EXPECT_EQ(f.verdict, RefFitVerdict::kNoFit);
  EXPECT_GT(f.misfit[static_cast<std::size_t>(f.best)], 0.1);
}

TEST(ReferenceCheck, NothingIsJudgedWithoutTurnsAboveTheBiasSigma) {
  // a still box: no turning window
  Motion still;
  still.yaw_amp_deg = 0.0;
  EXPECT_EQ(run(still, conjugated).verdict, RefFitVerdict::kNotChecked);
  EXPECT_EQ(run(still, conjugated).windows, 0u);
  // before lock (sigma 20 deg/s): a 1 s window must turn > 100 deg; the 18 deg/s yaw never does
  EXPECT_EQ(run(Motion{}, conjugated, 1.0, 20.0).windows, 0u);
}

TEST(ReferenceCheck, AGapRestartsTheWindow) {
  // ref_q missing every other second: no window spans a gap, the check still fits
  ReferenceCheck check;
  Sample s;
  const Motion m;
  for (int k = 0; k * kDt <= 60.0; ++k) {
    s.t_s = k * kDt;
    const bool gap = (k / 150) % 2 == 1;
    s.ref_q_wxyz = gap ? Eigen::Vector4d::Constant(kNaN) : as_written(q_enu_from_body(m, s.t_s));
    check.push(s, body_rate_dps(m, s.t_s), 0.01);
  }
  const ReferenceFit f = check.finish();
  EXPECT_EQ(f.verdict, RefFitVerdict::kFits);
  EXPECT_LT(f.misfit[0], 1e-6);
  EXPECT_LE(f.windows, 20u);  // 1.5 s of each 3 s: one window each
}

}  // namespace
}  // namespace driftless::est
