// Strapdown attitude against closed forms: Earth-rate removal, a constant turn, the error split.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/attitude.hpp"

namespace driftless::est {
namespace {

TEST(AttitudeTest, StaticBoxSeeingOnlyTheEarthRateStaysPut) {
  // GIVEN a box tilted and turned, at rest on the Earth at 52 deg N: ideal gyros read C_bn w_ie
  const Eigen::Quaterniond q0 = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  AttitudeIntegrator att(52.0);
  att.reset(q0, 0.0);
  const Eigen::Vector3d w_body_dps = (q0.conjugate() * att.earth_rate_enu_radps()) * kDegPerRad;
  // WHEN one hour at 100 Hz is integrated
  for (int k = 1; k <= 360000; ++k) att.step(k * 0.01, w_body_dps);
  // THEN the attitude has not moved (the Earth rate was removed)
  EXPECT_LT(attitude_error(att.q_enu_from_body(), q0).angle_deg, 1e-6);
  // and without removal it would have turned by 15.04 deg/h: check the rate magnitude used
  EXPECT_NEAR(att.earth_rate_enu_radps().norm() * kDegPerRad * 3600.0, 15.041, 1e-3);
}

TEST(AttitudeTest, ConstantTurnAboutUpMatchesTheClosedForm) {
  // GIVEN a level box turning at 10 deg/s about Up (plus the Earth rate it also senses)
  AttitudeIntegrator att(0.0);
  att.reset(Eigen::Quaterniond::Identity(), 0.0);
  Eigen::Quaterniond truth = Eigen::Quaterniond::Identity();
  for (int k = 1; k <= 2000; ++k) {
    const double t = k * 0.01;
    truth = Eigen::Quaterniond(Eigen::AngleAxisd(10.0 * t * kRadPerDeg, Eigen::Vector3d::UnitZ()));
    const Eigen::Vector3d w_ib = Eigen::Vector3d(0, 0, 10.0) + (truth.conjugate() * att.earth_rate_enu_radps()) * kDegPerRad;
    att.step(t, w_ib);
  }
  // THEN after 20 s the heading is 200 deg
  const AttitudeError e = attitude_error(att.q_enu_from_body(), truth);
  EXPECT_LT(e.angle_deg, 1e-4);
  EXPECT_NEAR(roll_pitch_yaw_deg(att.q_enu_from_body())[2], -160.0, 1e-4);
}

TEST(AttitudeTest, ErrorSplitsIntoRollPitchHeadingAboutNorthEastUp) {
  const Eigen::Quaterniond ref(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()));
  const Eigen::Quaterniond est = Eigen::Quaterniond(Eigen::AngleAxisd(2.0 * kRadPerDeg, Eigen::Vector3d::UnitZ())) * ref;
  const AttitudeError e = attitude_error(est, ref);
  EXPECT_NEAR(e.heading_deg, 2.0, 1e-9);
  EXPECT_NEAR(e.roll_deg, 0.0, 1e-9);
  EXPECT_NEAR(e.pitch_deg, 0.0, 1e-9);
  EXPECT_NEAR(e.angle_deg, 2.0, 1e-9);
  const Eigen::Quaterniond tilt = Eigen::Quaterniond(Eigen::AngleAxisd(-1.5 * kRadPerDeg, Eigen::Vector3d::UnitY())) * ref;
  EXPECT_NEAR(attitude_error(tilt, ref).roll_deg, -1.5, 1e-9);  // about North
}

TEST(AttitudeTest, DriftIsTheSlopeOfTheErrorIgnoringItsOffset) {
  std::vector<double> t, e;
  for (int k = 0; k <= 100; ++k) {
    t.push_back(100.0 + 36.0 * k);
    e.push_back(7.0 + 0.01 * 36.0 * k);  // offset 7 deg, 0.01 deg/s = 36 deg/h
  }
  EXPECT_NEAR(drift_deg_per_h(t, e), 36.0, 1e-9);
  EXPECT_TRUE(std::isnan(drift_deg_per_h({1.0}, {2.0})));
}

TEST(AttitudeTest, NanRateHoldsTheLastRate) {
  AttitudeIntegrator a(0.0), b(0.0);
  a.reset(Eigen::Quaterniond::Identity(), 0.0);
  b.reset(Eigen::Quaterniond::Identity(), 0.0);
  const Eigen::Vector3d w(1.0, -2.0, 0.5);
  for (int k = 1; k <= 100; ++k) {
    a.step(0.01 * k, w);
    b.step(0.01 * k, (k > 50 && k < 60) ? Eigen::Vector3d::Constant(kNaN) : w);
  }
  EXPECT_LT(attitude_error(a.q_enu_from_body(), b.q_enu_from_body()).angle_deg, 1e-9);
}

}  // namespace
}  // namespace driftless::est
