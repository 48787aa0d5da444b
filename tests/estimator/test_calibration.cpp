// Calibration fit (paper section 4) against a closed-form rig: y = M^-1 (w_table + w_earth) + b + n,
// with planted scale, misalignment, cross-coupling and end-stop errors.
#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "estimator/calibration.hpp"
#include "estimator/geometry.hpp"
#include "estimator/sample.hpp"

namespace driftless::est {
namespace {

constexpr double kLatitudeDeg = 52.0;
constexpr double kMpu6050SigmaDps = 0.05;  // 0.005 deg/s/rtHz at 100 Hz (paper section 4)

// the planted errors of one box
struct Truth {
  Eigen::Vector3d hinge[2] = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()};
  Eigen::Matrix3d C[2];            // sensor calibration: y = C w_sensor
  double stop_error_deg[2][2];     // [sensor][pos]: actual angle = nominal + error
  Eigen::Vector3d bias_dps[2];
  Eigen::Matrix3d M_inv(int i, int p) const {
    const Eigen::Matrix3d T = geo::rot_about_axis_deg(hinge[i], position_deg(p) + stop_error_deg[i][p]);
    return C[i] * T.transpose();
  }
  CalibMatrices matrices() const {
    CalibMatrices m;
    for (int i = 0; i < 2; ++i)
      for (int p = 0; p < 2; ++p) m.M(i, p) = M_inv(i, p).inverse();
    return m;
  }
};

// 2 % scale, 1 deg axis misalignment, 0.5 % cross-coupling, 2 deg end-stop error (issue #4)
Truth planted_truth() {
  Truth t;
  for (int i = 0; i < 2; ++i) {
    const double sgn = i == 0 ? 1.0 : -1.0;
    const Eigen::Vector3d scale(0.02 * sgn, -0.02, 0.02);
    Eigen::Matrix3d K = Eigen::Matrix3d::Zero();  // cross-coupling
    K << 0, 0.005, -0.005, 0.005 * sgn, 0, 0.005, -0.005, 0.005, 0;
    const Eigen::Matrix3d mount =
        geo::rot_about_axis_deg(Eigen::Vector3d(1.0, 1.0 * sgn, 0.5).normalized(), 1.0);  // 1 deg misalignment
    t.C[i] = (Eigen::Matrix3d::Identity() + scale.asDiagonal().toDenseMatrix()) *
             (Eigen::Matrix3d::Identity() + K) * mount.transpose();
    t.stop_error_deg[i][kPosMinus90] = 0.0;
    t.stop_error_deg[i][kPosPlus90] = 2.0 * sgn;  // the +90 stop is 2 deg off
  }
  t.bias_dps[0] = Eigen::Vector3d(1.5, -0.8, 0.3);
  t.bias_dps[1] = Eigen::Vector3d(-2.1, 0.4, 1.1);
  return t;
}

// the orientation's mounting: the table (pan) axis is ENU up; the box axis `axis` points up
Eigen::Quaterniond mount_for_axis(int axis) {
  if (axis == 2) return Eigen::Quaterniond::Identity();                    // XY level
  if (axis == 0) return Eigen::Quaterniond(Eigen::AngleAxisd(-kPi / 2, Eigen::Vector3d::UnitY()));  // YZ
  return Eigen::Quaterniond(Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitX()));                  // XZ
}

// the rig: for each end stop and orientation, 60 s of +-50 deg/s square wave (2 s half period)
std::vector<CalibSegment> simulate_rig(const Truth& truth, double sigma_dps, std::uint64_t seed,
                                       std::vector<int> axes = {2, 0, 1}) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma_dps);
  const Eigen::Vector3d w_earth_enu_dps =
      kEarthRateRadps * kDegPerRad *
      Eigen::Vector3d(0.0, std::cos(kLatitudeDeg * kRadPerDeg), std::sin(kLatitudeDeg * kRadPerDeg));
  const char* kOrient[3] = {"YZ", "XZ", "XY"};
  std::vector<CalibSegment> out;
  double t = 0.0;
  for (int p : {kPosMinus90, kPosPlus90}) {
    for (int axis : axes) {
      CalibSegment s;
      s.orientation = kOrient[axis];
      s.name = s.orientation + "@" + position_name(p);
      s.pos = {p, p};
      s.axis_box = Eigen::Vector3d::Unit(axis);
      s.rate_dps = 50.0;
      double pan_deg = -50.0;
      const double dt = 0.01;
      for (int k = 0; k < 6000; ++k, t += dt) {
        CalibSample x;
        x.t_s = t;
        x.sign = (k / 200) % 2 == 0 ? 1.0 : -1.0;
        const Eigen::Quaterniond q_enu_from_body =
            Eigen::AngleAxisd(pan_deg * kRadPerDeg, Eigen::Vector3d::UnitZ()) * mount_for_axis(axis);
        x.earth_rate_box_dps = q_enu_from_body.conjugate() * w_earth_enu_dps;
        const Eigen::Vector3d w_box = x.sign * s.rate_dps * s.axis_box + x.earth_rate_box_dps;
        for (int i = 0; i < 2; ++i) {
          x.gyro_dps[i] = truth.M_inv(i, p) * w_box + truth.bias_dps[i];
          for (int j = 0; j < 3; ++j) x.gyro_dps[i][j] += noise(rng);
        }
        s.samples.push_back(x);
        pan_deg += x.sign * s.rate_dps * dt;
      }
      out.push_back(std::move(s));
    }
  }
  return out;
}

CalibFit fit(const std::vector<CalibSegment>& segs, CalibMethod m) {
  CalibFitOptions o;
  o.method = m;
  return fit_calibration(segs, o);
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no exception)";
}

TEST(Calibration, RoundTripOfTheSensorEquationIsExactWithoutNoise) {
  // GIVEN a planted box; WHEN M^-1 turns a rate into an output and M turns it back
  const CalibMatrices m = planted_truth().matrices();
  const Eigen::Vector3d b(0.7, -1.2, 3.3);
  for (int i = 0; i < 2; ++i)
    for (int p = 0; p < 2; ++p)
      for (const Eigen::Vector3d& w : {Eigen::Vector3d(50, -3, 7), Eigen::Vector3d(-0.004, 0.01, 250)}) {
        const Eigen::Vector3d y = sensor_output_dps(m.M(i, p), w, b);
        // THEN the input rate comes back to 1e-9
        EXPECT_LT((box_rate_dps(m.M(i, p), y, b) - w).norm(), 1e-9);
      }
}

TEST(Calibration, NominalMatricesAreTheHingeRotations) {
  const CalibMatrices m = CalibMatrices::nominal(Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX());
  // platform 1 at +90 about z: sensor x lies along box y
  EXPECT_LT((m.M(0, kPosPlus90) * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 1e-12);
  EXPECT_LT((m.M(1, kPosMinus90) * Eigen::Vector3d::UnitY() + Eigen::Vector3d::UnitZ()).norm(), 1e-12);
  EXPECT_NO_THROW(m.validate());
  const CalibErrors e = describe_errors(m, 0, Eigen::Vector3d::UnitZ());
  EXPECT_LT(e.scale_error.norm(), 1e-12);
  EXPECT_LT(std::abs(e.travel_error_deg), 1e-9);
}

TEST(Calibration, BothMethodsRecoverMExactlyWithoutNoise) {
  const Truth truth = planted_truth();
  const auto segs = simulate_rig(truth, 0.0, 1);
  const CalibMatrices m = truth.matrices();
  const CalibFit ls = fit(segs, CalibMethod::kLeastSquares);
  const CalibFit tt = fit(segs, CalibMethod::kTopToTop);
  for (int i = 0; i < 2; ++i)
    for (int p = 0; p < 2; ++p) {
      EXPECT_LT((ls.fit[i][p].M - m.M(i, p)).cwiseAbs().maxCoeff(), 1e-9);
      EXPECT_LT(ls.fit[i][p].residual_rms_dps.maxCoeff(), 1e-9);
      // the least-squares bias is the sensor's own bias: the Earth rate was removed
      for (const auto& b : ls.fit[i][p].biases) EXPECT_LT((b.bias_dps - truth.bias_dps[i]).norm(), 1e-9);
      // top-to-top: the Earth rate's change over a half period leaks only slightly into M
      EXPECT_LT((tt.fit[i][p].M - m.M(i, p)).cwiseAbs().maxCoeff(), 1e-5);
    }
}

TEST(Calibration, TopToTopBiasCarriesTheEarthRateLeastSquaresDoesNot) {
  const Truth truth = planted_truth();
  const auto segs = simulate_rig(truth, 0.0, 1);
  const CalibFit tt = fit(segs, CalibMethod::kTopToTop);
  // the XY segment at -90: box z is up, so the mean Earth rate in box axes is about (.., .., Omega sin(lat))
  const auto& b = tt.fit[0][kPosMinus90].biases[0];
  ASSERT_EQ(b.segment, "XY@-90");
  Eigen::Vector3d w_mean = Eigen::Vector3d::Zero();
  for (const auto& x : segs[0].samples) w_mean += x.earth_rate_box_dps;
  w_mean /= static_cast<double>(segs[0].samples.size());
  const Eigen::Vector3d expected = truth.M_inv(0, kPosMinus90) * w_mean + truth.bias_dps[0];
  EXPECT_LT((b.bias_dps - expected).norm(), 2e-5);
  EXPECT_GT((b.bias_dps - truth.bias_dps[0]).norm(), 2e-3);  // 15 deg/h is not nothing
}

TEST(Calibration, RecoversPlantedErrorsAtMpu6050Noise) {
  // GIVEN 2 % scale, 1 deg misalignment, 0.5 % cross-coupling and a 2 deg end-stop error
  const Truth truth = planted_truth();
  const auto segs = simulate_rig(truth, kMpu6050SigmaDps, 7);
  const CalibMatrices m_true = truth.matrices();
  for (CalibMethod method : {CalibMethod::kLeastSquares, CalibMethod::kTopToTop}) {
    SCOPED_TRACE(method_name(method));
    const CalibFit f = fit(segs, method);
    const CalibMatrices m_fit = f.matrices();
    for (int i = 0; i < 2; ++i) {
      const Eigen::Vector3d hinge = truth.hinge[i];
      const CalibErrors want = describe_errors(m_true, i, hinge);
      const CalibErrors got = describe_errors(m_fit, i, hinge);
      // the planted values are what describe_errors reads off the true M
      EXPECT_NEAR(want.scale_error.cwiseAbs().minCoeff(), 0.02, 0.001);
      EXPECT_NEAR(std::abs(want.travel_error_deg), 2.0, 1e-9);
      // scale within 10 % of 2 %
      EXPECT_LT((got.scale_error - want.scale_error).cwiseAbs().maxCoeff(), 0.1 * 0.02);
      // cross-coupling (non-orthogonality, 0.5 % ~ 0.29 deg per pair): within 10 %
      EXPECT_LT((got.nonorthogonality_deg - want.nonorthogonality_deg).cwiseAbs().maxCoeff(),
                0.1 * 0.005 * kDegPerRad);
      // angles within 0.05 deg: axis misalignment, tilt, end-stop travel
      for (int p = 0; p < 2; ++p) {
        EXPECT_LT((got.axis_error_deg[p] - want.axis_error_deg[p]).cwiseAbs().maxCoeff(), 0.05);
        EXPECT_LT((got.tilt_box_deg[p] - want.tilt_box_deg[p]).cwiseAbs().maxCoeff(), 0.05);
      }
      EXPECT_NEAR(got.travel_error_deg, want.travel_error_deg, 0.05);
      EXPECT_LT(got.travel_offaxis_deg, 0.05);
      for (int p = 0; p < 2; ++p) {
        const SensorPositionFit& sp = f.fit[i][p];
        // every coefficient within 5 sigma of the truth, residuals at the noise level
        const Eigen::Matrix3d z = (sp.M - m_true.M(i, p)).cwiseQuotient(sp.M_sigma);
        EXPECT_LT(z.cwiseAbs().maxCoeff(), 5.0) << z;
        EXPECT_NEAR(sp.residual_rms_dps.maxCoeff(), kMpu6050SigmaDps, 0.005);
        EXPECT_GT(sp.M_sigma.minCoeff(), 0.0);
      }
    }
  }
}

TEST(Calibration, ReportedSigmaMatchesMonteCarloSpread) {
  // the normalised errors (fit - truth) / sigma of all 36 coefficients over 20 seeded runs
  // have unit variance: chi-square with 720 dof, 99.9 % bounds about [602, 845]
  const Truth truth = planted_truth();
  const CalibMatrices m_true = truth.matrices();
  for (CalibMethod method : {CalibMethod::kLeastSquares, CalibMethod::kTopToTop}) {
    SCOPED_TRACE(method_name(method));
    double chi2 = 0.0;
    int dof = 0;
    for (std::uint64_t seed = 100; seed < 120; ++seed) {
      const CalibFit f = fit(simulate_rig(truth, kMpu6050SigmaDps, seed), method);
      for (int i = 0; i < 2; ++i)
        for (int p = 0; p < 2; ++p) {
          chi2 += (f.fit[i][p].M - m_true.M(i, p)).cwiseQuotient(f.fit[i][p].M_sigma).squaredNorm();
          dof += 9;
        }
    }
    EXPECT_EQ(dof, 720);
    RecordProperty("chi2_" + method_name(method), std::to_string(chi2));
    EXPECT_GT(chi2, 602.0);
    EXPECT_LT(chi2, 845.0);
  }
}

TEST(Calibration, MissingOrientationNamesTheUnobservableCoefficients) {
  // GIVEN no XZ orientation: nothing turns the box about y
  const auto segs = simulate_rig(planted_truth(), kMpu6050SigmaDps, 3, {2, 0});
  const std::string msg = message_of([&] { fit(segs, CalibMethod::kLeastSquares); });
  EXPECT_NE(msg.find("sensor 1 at -90"), std::string::npos) << msg;
  EXPECT_NE(msg.find("M^-1[x,y]"), std::string::npos) << msg;
  EXPECT_NE(msg.find("XZ orientation"), std::string::npos) << msg;
}

TEST(Calibration, MissingEndStopAndShortSegmentsAreRefused) {
  auto segs = simulate_rig(planted_truth(), kMpu6050SigmaDps, 3);
  auto only_minus = segs;
  only_minus.resize(3);
  EXPECT_NE(message_of([&] { fit(only_minus, CalibMethod::kTopToTop); }).find("sensor 1 at +90"),
            std::string::npos);
  segs[1].samples.resize(250);  // 2.5 s: 200 at +rate, 50 at -rate
  segs[1].samples.erase(segs[1].samples.begin() + 200, segs[1].samples.begin() + 240);
  const std::string msg = message_of([&] { fit(segs, CalibMethod::kLeastSquares); });
  EXPECT_NE(msg.find("segment 'YZ@-90'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("10 at -rate"), std::string::npos) << msg;
}

TEST(Calibration, SingularMatrixIsRefusedByValidate) {
  CalibMatrices m = CalibMatrices::nominal(Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX());
  m.M(1, kPosPlus90).col(2).setZero();
  const std::string msg = message_of([&] { m.validate(); });
  EXPECT_NE(msg.find("sensor 2 at +90"), std::string::npos) << msg;
}

}  // namespace
}  // namespace driftless::est
