// Strapdown attitude against closed forms: Earth-rate removal, a constant turn, the error split.
#include <algorithm>
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

TEST(AttitudeTest, AccumulatedErrorKeepsGrowingPastHalfATurn) {
  // GIVEN a static box at the pole (Earth rate along Up, so every rotation here is about Up and
  // the closed form is exact) whose raw gyro reads a 0.5 deg/s bias about box z (= Up): over one
  // hour the estimate turns 1800 deg, folding the error angle five times
  const Eigen::Quaterniond q_ref = Eigen::Quaterniond::Identity();
  AttitudeIntegrator att(90.0);
  att.reset(q_ref, 0.0);
  const Eigen::Vector3d w_earth_dps = att.earth_rate_enu_radps() * kDegPerRad;
  ErrorAccumulator acc;
  acc.add(att.q_enu_from_body(), q_ref);
  std::vector<double> t, wrapped, unwrapped;
  for (int k = 1; k <= 360000; ++k) {
    att.step(k * 0.01, w_earth_dps + Eigen::Vector3d(0, 0, 0.5));
    acc.add(att.q_enu_from_body(), q_ref);
    if (k % 100 == 0) {
      t.push_back(k * 0.01);
      wrapped.push_back(attitude_error(att.q_enu_from_body(), q_ref).angle_deg);
      unwrapped.push_back(acc.angle_deg());
    }
  }
  // THEN the accumulated error is the closed form 0.5 t and its drift 1800 deg/h,
  EXPECT_NEAR(acc.angle_deg(), 1800.0, 1e-6);
  EXPECT_NEAR(drift_deg_per_h(t, unwrapped), 1800.0, 1e-6);
  // while the folded angle never passes 180 deg and its fitted slope says almost nothing
  EXPECT_LE(*std::max_element(wrapped.begin(), wrapped.end()), 180.0 + 1e-9);
  EXPECT_LT(std::fabs(drift_deg_per_h(t, wrapped)), 100.0);
}

TEST(AttitudeTest, AccumulatedErrorEqualsTheErrorAngleWhileSmall) {
  // GIVEN a box turning about a tilted axis with a small rate error about another axis
  AttitudeIntegrator est(30.0), ref(30.0);
  est.reset(Eigen::Quaterniond::Identity(), 0.0);
  ref.reset(Eigen::Quaterniond::Identity(), 0.0);
  ErrorAccumulator acc;
  acc.add(est.q_enu_from_body(), ref.q_enu_from_body());
  for (int k = 1; k <= 6000; ++k) {
    const Eigen::Vector3d w(3.0 * std::sin(0.01 * k), 2.0, -1.0);
    ref.step(k * 0.01, w);
    est.step(k * 0.01, w + Eigen::Vector3d(0.0, 0.0, 0.01));
    acc.add(est.q_enu_from_body(), ref.q_enu_from_body());
  }
  // THEN after 60 s (0.6 deg of error) both measures agree to a fraction of a percent
  const double angle = attitude_error(est.q_enu_from_body(), ref.q_enu_from_body()).angle_deg;
  EXPECT_GT(angle, 0.3);
  EXPECT_NEAR(acc.angle_deg(), angle, 0.01 * angle);
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
