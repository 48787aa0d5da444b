// Closed-form checks of the shared geometry (estimator/geometry.hpp): eq. (1)'s hinge rotation,
// the quaternion log/exp maps, the Earth rate and the eq. (5) flip cycle.
#include "estimator/geometry.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace driftless::geo {
namespace {

TEST(Geometry, QuarterTurnAboutZMapsXToY) {
  const Eigen::Matrix3d R = rot_about_axis_deg(Eigen::Vector3d(0, 0, 2.0), 90.0);  // axis normalised
  EXPECT_TRUE((R * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-15));
  EXPECT_NEAR(R.determinant(), 1.0, 1e-15);
  // the paper's R_i(+90) R_i(-90)^T is a half turn about the hinge
  const Eigen::Vector3d a = Eigen::Vector3d(1, 2, 3).normalized();
  const Eigen::Matrix3d H = rot_about_axis_deg(a, 90.0) * rot_about_axis_deg(a, -90.0).transpose();
  EXPECT_TRUE(H.isApprox(2.0 * a * a.transpose() - Eigen::Matrix3d::Identity(), 1e-14));
  EXPECT_TRUE(rot_about_axis_deg(Eigen::Vector3d::Zero(), 30.0).isIdentity(0.0));
  EXPECT_TRUE(rot_about_axis_rad(a, 0.3).isApprox(rot_about_axis_deg(a, 0.3 * kDegPerRad), 1e-15));
}

TEST(Geometry, LogMapInvertsExpMapAndTakesTheShortWay) {
  for (double angle : {1e-14, 1e-8, 0.3, 2.0, 3.1}) {
    const Eigen::Vector3d phi = angle * Eigen::Vector3d(0.6, -0.8, 0.0);
    const Eigen::Vector3d back = rotvec_rad(quat_from_rotvec(phi));
    EXPECT_LE((back - phi).norm(), 1e-15 * std::max(1.0, angle)) << angle;
  }
  // q and -q are the same rotation: the log map answers the shorter way round
  Eigen::Quaterniond q = quat_from_rotvec(Eigen::Vector3d(0, 0, 0.5));
  q.coeffs() = -q.coeffs();
  EXPECT_NEAR(rotvec_rad(q).z(), 0.5, 1e-15);
  // a rotation past pi reads as the shorter one the other way
  EXPECT_NEAR(rotvec_rad(quat_from_rotvec(Eigen::Vector3d(0, 0, 4.0))).z(), 4.0 - 2 * kPi, 1e-14);
  // the matrix form agrees with the quaternion form
  const Eigen::Vector3d phi(0.1, 0.2, -0.3);
  EXPECT_LE((rotvec_rad(quat_from_rotvec(phi).toRotationMatrix()) - phi).norm(), 1e-15);
  EXPECT_TRUE(rotvec_rad(Eigen::Quaterniond::Identity()).isZero(0.0));
}

// the small-angle series of both maps against the closed forms they stand in for (Eigen's
// angle-axis quaternion, 2 atan2(s, w) / s), on both sides of each series' bound and at it: equal to
// rounding (a few ulp; the series' omitted terms are below 1e-22)
TEST(Geometry, TheSmallAngleSeriesEqualTheClosedFormsToRounding) {
  const Eigen::Vector3d axis = Eigen::Vector3d(0.36, -0.48, 0.8);  // unit
  for (double angle : {1e-150, 1e-12, 1e-6, 1e-3, 1.9e-3, 2.0e-3, 0.01, 0.0624, 0.0625, 0.0626, 0.2}) {
    const Eigen::Vector3d phi = angle * axis;
    const Eigen::Quaterniond exact(Eigen::AngleAxisd(angle, axis));
    const Eigen::Quaterniond q = quat_from_rotvec(phi);
    EXPECT_LE((q.coeffs() - exact.coeffs()).cwiseAbs().maxCoeff(), 4e-16) << angle;
    EXPECT_LE((q.vec() - exact.vec()).norm(), 4e-16 * exact.vec().norm()) << angle;
    const double s = exact.vec().norm();
    const Eigen::Vector3d log_exact = exact.vec() * (2.0 * std::atan2(s, exact.w()) / s);
    EXPECT_LE((rotvec_rad(exact) - log_exact).norm(), 4e-16 * angle) << angle;
  }
  EXPECT_TRUE(quat_from_rotvec(Eigen::Vector3d::Constant(std::nan(""))).coeffs().isApprox(
      Eigen::Quaterniond::Identity().coeffs()));
}

TEST(Geometry, EarthRateHasWgs84MagnitudeAndItsLatitudeDerivative) {
  // 15.041 deg/h at any latitude; vertical component Omega sin(phi)
  EXPECT_NEAR(earth_rate_enu_radps(52.0).norm() * kDegPerRad * 3600.0, 15.0411, 1e-4);
  EXPECT_NEAR(earth_rate_enu_radps(52.0).z(), kEarthRateRadps * std::sin(52.0 * kRadPerDeg), 1e-20);
  EXPECT_EQ(earth_rate_enu_radps(0.0).z(), 0.0);
  EXPECT_NEAR(earth_rate_enu_radps(90.0).y(), 0.0, 1e-20);
  // central difference against the analytic derivative
  const double h_deg = 1e-4;
  const Eigen::Vector3d fd = (earth_rate_enu_radps(30.0 + h_deg) - earth_rate_enu_radps(30.0 - h_deg)) /
                             (2.0 * h_deg * kRadPerDeg);
  EXPECT_LE((fd - earth_rate_enu_dlat_radps_per_rad(30.0)).norm(), 1e-14);
}

TEST(Geometry, FlipCycleIsEq5OrderAndMovesOnePlatformPerStep) {
  // eq. (5): (+,+) -> (+,-) -> (-,-) -> (-,+): platform 2, 1, 2, 1 move
  const int movers[4] = {2, 1, 2, 1};
  for (int k = 0; k < 4; ++k) {
    const FlipSigns a = flip_cycle_at(k), b = flip_cycle_at(k + 1);
    EXPECT_EQ((a.plat1 != b.plat1) + (a.plat2 != b.plat2), 1) << k;
    EXPECT_EQ(flip_cycle_mover(k), movers[k]) << k;
    EXPECT_EQ(flip_cycle_index(90.0 * a.plat1, 90.0 * a.plat2), k);
  }
  EXPECT_EQ(flip_cycle_at(-1).plat1, -1);  // k = -1 is position 3, (-,+)
  EXPECT_EQ(flip_cycle_at(-1).plat2, +1);
  EXPECT_EQ(flip_cycle_at(5).plat2, -1);   // k = 5 is position 1, (+,-)
}

}  // namespace
}  // namespace driftless::geo
