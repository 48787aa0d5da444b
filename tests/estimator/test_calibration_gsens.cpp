// g-sensitivity from the rig's per-segment biases (est::fit_g_sensitivity) and its use in the
// filter (Calibration::G_dps_per_g): closed forms, exact to rounding.
#include <gtest/gtest.h>

#include "estimator/calibration.hpp"
#include "estimator/filter.hpp"
#include "estimator/geometry.hpp"
#include "estimator/log.hpp"

namespace driftless::est {
namespace {

// six rig segments (XY, YZ, XZ at -90 and +90) whose biases follow b0 + G f + k (T - T_mean)
struct Rig {
  std::vector<CalibSegment> segs;
  CalibFit fit;
};

Rig make_rig(const Eigen::Matrix3d G[2], const Eigen::Vector3d b0[2], const Eigen::Vector3d k[2],
             bool with_temp = true) {
  Rig r;
  const Eigen::Vector3d up_box[3] = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY()};
  const char* names[3] = {"XY", "YZ", "XZ"};
  const Eigen::Vector3d hinge[2] = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()};
  int n = 0;
  for (int p = 0; p < 2; ++p) {
    for (int o = 0; o < 3; ++o, ++n) {
      CalibSegment s;
      s.name = std::string(names[o]) + (p == 0 ? "@-90" : "@+90");
      s.pos = {p, p};
      const double temp = 25.0 + 0.1 * n;  // warming up through the rig
      for (int i = 0; i < 2; ++i) {
        // gravity (specific force up, 1 g) in sensor axes: R_box_from_sensor^T up
        const Eigen::Vector3d f = geo::rot_about_axis_deg(hinge[i], position_deg(p)).transpose() * up_box[o];
        s.f_mean_g[static_cast<std::size_t>(i)] = f;
        s.temp_mean_c[static_cast<std::size_t>(i)] = with_temp ? temp : kNaN;
        SegmentBias b;
        b.segment = s.name;
        b.bias_dps = b0[i] + G[i] * f + k[i] * (temp - 25.25);
        r.fit.fit[static_cast<std::size_t>(i)][static_cast<std::size_t>(p)].biases.push_back(b);
      }
      r.segs.push_back(s);
    }
  }
  return r;
}

TEST(GSensitivityFit, RecoversGAndTheWarmUpDriftExactly) {
  // GIVEN biases made of an offset, a g-sensitivity and a temperature drift, without noise
  Eigen::Matrix3d G[2];
  G[0] << 0.06, -0.04, 0.05, 0.03, 0.07, -0.05, -0.04, 0.05, 0.06;
  G[1] << -0.02, 0.08, 0.01, 0.05, -0.03, 0.02, 0.07, 0.01, -0.06;
  const Eigen::Vector3d b0[2] = {Eigen::Vector3d(1.5, -0.8, 0.3), Eigen::Vector3d(-2.1, 0.4, 1.1)};
  const Eigen::Vector3d k[2] = {Eigen::Vector3d(0.08, -0.05, 0.02), Eigen::Vector3d(-0.03, 0.06, 0.01)};
  const Rig r = make_rig(G, b0, k);
  // WHEN fitted
  const GSensitivityFit g = fit_g_sensitivity(r.segs, r.fit);
  // THEN G, b0 and the temperature coefficient come back to rounding
  ASSERT_TRUE(g.valid) << g.reason;
  EXPECT_TRUE(g.temperature_term);
  EXPECT_EQ(g.segments, 6u);
  for (int i = 0; i < 2; ++i) {
    const auto iu = static_cast<std::size_t>(i);
    EXPECT_LT((g.G_dps_per_g[iu] - G[i]).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((g.b0_dps[iu] - b0[i]).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((g.bias_tc_dps_per_degc[iu] - k[i]).cwiseAbs().maxCoeff(), 1e-10);
    EXPECT_LT(g.residual_rms_dps[iu].maxCoeff(), 1e-12);
  }
}

TEST(GSensitivityFit, SaysWhyItCannotFit) {
  Eigen::Matrix3d G[2] = {Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  const Eigen::Vector3d z[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  // no accelerometer columns
  Rig r = make_rig(G, z, z);
  for (auto& s : r.segs) s.f_mean_g = {Eigen::Vector3d::Constant(kNaN), Eigen::Vector3d::Constant(kNaN)};
  GSensitivityFit g = fit_g_sensitivity(r.segs, r.fit);
  EXPECT_FALSE(g.valid);
  EXPECT_NE(g.reason.find("accelerometer"), std::string::npos) << g.reason;
  // one orientation only: gravity along one sensor axis in every segment
  r = make_rig(G, z, z);
  for (auto& s : r.segs) s.f_mean_g = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitZ()};
  g = fit_g_sensitivity(r.segs, r.fit);
  EXPECT_FALSE(g.valid);
  EXPECT_NE(g.reason.find("span"), std::string::npos) << g.reason;
  // without temperatures the fit runs without the drift term
  r = make_rig(G, z, z, /*with_temp=*/false);
  g = fit_g_sensitivity(r.segs, r.fit);
  EXPECT_TRUE(g.valid) << g.reason;
  EXPECT_FALSE(g.temperature_term);
}

TEST(GSensitivityFit, FilterSubtractsGTimesTheSpecificForce) {
  // GIVEN a filter with G for sensor 1 and a sample at rest with gravity along sensor 1's z
  log::Metadata meta;
  meta.set("sample_rate_hz", "100");
  meta.set("hinge1_axis", "0 0 1");
  meta.set("hinge2_axis", "1 0 0");
  EstimatorConfig plain, with_g;
  with_g.calibration.G_dps_per_g[0] << 0, 0, 0.1, 0, 0, 0, 0, 0, 0.05;  // x and z respond to f_z
  DriftlessFilter a(plain, box_geometry_from_metadata(meta)), b(with_g, box_geometry_from_metadata(meta));
  Sample s;
  s.t_s = 0.0;
  s.gyro1_dps = Eigen::Vector3d(0.1, 0.0, 0.05);  // exactly G f: the g-sensitivity and nothing else
  s.gyro2_dps = Eigen::Vector3d::Zero();
  s.plat1_deg = s.plat2_deg = 90.0;
  s.accel1_mps2 = Eigen::Vector3d(0, 0, kStandardGravityMps2);
  s.accel2_mps2 = Eigen::Vector3d(0, kStandardGravityMps2, 0);
  a.push(s);
  b.push(s);
  // THEN the corrected output is the raw one minus G f / g: zero here
  EXPECT_NEAR((a.output().y1c_dps - s.gyro1_dps).norm(), 0.0, 1e-12);
  EXPECT_LT(b.output().y1c_dps.norm(), 1e-12);
  // AND a sample without accelerometer data passes unchanged
  Sample n = s;
  n.t_s = 0.01;
  n.accel1_mps2 = Eigen::Vector3d::Constant(kNaN);
  b.push(n);
  EXPECT_NEAR((b.output().y1c_dps - n.gyro1_dps).norm(), 0.0, 1e-12);
}

}  // namespace
}  // namespace driftless::est
