// The motion library: kinematics consistency, pan/tilt rate limits, vehicle and ship sanity, and
// CSV/EuRoC trajectory import with slerp.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "estimator/geometry.hpp"
#include "estimator/input_error.hpp"
#include "estimator/sample.hpp"
#include "tests/temp_path.hpp"
#include "twin/motion.hpp"

namespace driftless::twin {
namespace {

std::filesystem::path temp_file(const std::string& name, const std::string& text) {
  const auto dir = test::temp_path("driftless_test_motion");
  std::filesystem::create_directories(dir);
  const auto p = dir / name;
  std::ofstream(p) << text;
  return p;
}

TEST(Motion, StaticIsExactlyStill) {
  MotionConfig cfg;
  cfg.static_box.attitude_ypr_deg = Eigen::Vector3d(30, 10, -5);
  const auto m = make_motion(cfg, 100, 1);
  EXPECT_TRUE(m->is_static());
  const MotionState s = m->at(42.0);
  EXPECT_EQ(s.w_body_radps, Eigen::Vector3d::Zero());
  EXPECT_EQ(s.a_enu_mps2, Eigen::Vector3d::Zero());
  const Eigen::Quaterniond q = quat_from_ypr(30 * kRadPerDeg, 10 * kRadPerDeg, -5 * kRadPerDeg);
  EXPECT_LT((s.q_enu_from_body.coeffs() - q.coeffs()).norm(), 1e-15);
}

// GIVEN a trajectory turning at a constant body rate, WHEN evaluated, THEN at() returns that rate
TEST(Motion, DerivativesOfAConstantRateTurnAreExact) {
  const Eigen::Vector3d w(0.3, -0.5, 0.8);  // rad/s, body axes
  std::vector<TrajectoryPoint> pts;
  for (int k = 0; k <= 2000; ++k) {
    TrajectoryPoint p;
    p.t_s = 0.01 * k;
    p.p_enu_m = Eigen::Vector3d(2.0 * p.t_s, 0, 0);
    p.q_enu_from_body = Eigen::Quaterniond(Eigen::AngleAxisd(w.norm() * p.t_s, w.normalized()));
    pts.push_back(p);
  }
  const auto m = make_trajectory_motion(pts);
  const MotionState s = m->at(7.123);
  EXPECT_LT((s.w_body_radps - w).norm(), 1e-9);
  EXPECT_LT(s.dw_body_radps2.norm(), 1e-6);
  EXPECT_LT((s.v_enu_mps - Eigen::Vector3d(2, 0, 0)).norm(), 1e-9);
  EXPECT_LT(s.a_enu_mps2.norm(), 1e-6);
}

TEST(Motion, PanTiltRatesStayWithinTheLimitAndReachIt) {
  MotionConfig cfg;
  cfg.type = MotionType::pan_tilt;
  const auto m = make_motion(cfg, 600, 7);
  double max_rate = 0;
  for (double t = 0; t < 600; t += 0.05) max_rate = std::max(max_rate, m->at(t).w_body_radps.norm());
  // each axis is limited to 50 deg/s; both together at most sqrt(2) * 50
  EXPECT_LT(max_rate * kDegPerRad, std::sqrt(2.0) * 50.0 + 0.01);
  EXPECT_GT(max_rate * kDegPerRad, 45.0);
  // known pattern: the same seed gives the same motion, another seed another one
  const auto m2 = make_motion(cfg, 600, 7), m3 = make_motion(cfg, 600, 8);
  EXPECT_EQ(m->at(123.4).q_enu_from_body.coeffs(), m2->at(123.4).q_enu_from_body.coeffs());
  EXPECT_NE(m->at(123.4).q_enu_from_body.coeffs(), m3->at(123.4).q_enu_from_body.coeffs());
}

TEST(Motion, GroundVehicleDrivesTurnsAndShakes) {
  MotionConfig cfg;
  cfg.type = MotionType::ground_vehicle;
  const auto m = make_motion(cfg, 600, 3);
  double max_speed = 0, max_yaw_rate = 0, max_pitch_rate = 0, max_accel = 0;
  for (double t = 0; t < 600; t += 0.013) {
    const MotionState s = m->at(t);
    max_speed = std::max(max_speed, s.v_enu_mps.head<2>().norm());
    max_yaw_rate = std::max(max_yaw_rate, std::abs(s.w_body_radps.z()));
    max_pitch_rate = std::max(max_pitch_rate, std::abs(s.w_body_radps.y()));
    max_accel = std::max(max_accel, s.a_enu_mps2.head<2>().norm());
  }
  EXPECT_GT(max_speed, 5.0);
  EXPECT_LT(max_speed, 16.5);  // the roof box also swings with pitch and roll
  EXPECT_GT(max_yaw_rate * kDegPerRad, 5.0);  // turns
  EXPECT_GT(max_pitch_rate * kDegPerRad, 0.5);  // bumps and vibration
  EXPECT_GT(max_accel, 0.5);
  EXPECT_FALSE(m->is_static());
  EXPECT_EQ(m->carrier(), Carrier::vehicle);
}

// the derivative of f at t from 5-point differences (O(h^4)): central, and one-sided from the
// left and the right; of the three, the one closest to `exact` (a stencil straddling a step of a
// higher derivative, at a bump's edge or where the drive's acceleration changes, is no derivative,
// but one side of the step is smooth)
template <class F, class V>
double diff_error(F f, double t, double h, const V& exact) {
  const V central = (f(t - 2 * h) - 8 * f(t - h) + 8 * f(t + h) - f(t + 2 * h)) / (12 * h);
  double best = (central - exact).norm();
  for (const double g : {h, -h}) {
    const V side = (25 * f(t) - 48 * f(t - g) + 36 * f(t - 2 * g) - 16 * f(t - 3 * g) + 3 * f(t - 4 * g)) / (12 * g);
    best = std::min(best, (side - exact).norm());
  }
  return best;
}

// GIVEN the vehicle's closed-form derivatives, WHEN compared with differences of its own pose and
// rates at 3 000 instants of a drive with turns, stops, bumps and vibration, THEN they agree to
// the differences' round-off (positions of km over h = 0.1 ms: ~1e-8 m/s)
TEST(Motion, GroundVehicleDerivativesAreThoseOfItsPose) {
  MotionConfig cfg;
  cfg.type = MotionType::ground_vehicle;
  cfg.ground_vehicle.bumps_per_km = 300;  // a bump under an axle at many of the instants
  const auto m = make_motion(cfg, 600, 5);
  const double h = 1e-4;  // s
  auto pos = [&](double t) -> Eigen::Vector3d { return m->at(t).p_enu_m; };
  auto vel = [&](double t) -> Eigen::Vector3d { return m->at(t).v_enu_mps; };
  auto rate = [&](double t) -> Eigen::Vector3d { return m->at(t).w_body_radps; };
  auto quat = [&](double t) -> Eigen::Vector4d { return m->at(t).q_enu_from_body.coeffs(); };
  double err_v = 0, err_w = 0, err_a = 0, err_dw = 0, max_dw = 0, max_a = 0;
  for (int k = 0; k < 3000; ++k) {
    const double t = 0.5 + 0.19937 * k;  // s, not on any round number
    const MotionState s = m->at(t);
    // dq/dt = q * (0, w) / 2 (w in body axes)
    const Eigen::Quaterniond half_w(0, 0.5 * s.w_body_radps.x(), 0.5 * s.w_body_radps.y(), 0.5 * s.w_body_radps.z());
    const Eigen::Vector4d dq = (s.q_enu_from_body * half_w).coeffs();
    err_v = std::max(err_v, diff_error(pos, t, h, s.v_enu_mps));
    err_w = std::max(err_w, diff_error(quat, t, h, dq));
    err_a = std::max(err_a, diff_error(vel, t, h, s.a_enu_mps2));
    err_dw = std::max(err_dw, diff_error(rate, t, h, s.dw_body_radps2));
    max_a = std::max(max_a, s.a_enu_mps2.norm());
    max_dw = std::max(max_dw, s.dw_body_radps2.norm());
  }
  EXPECT_LT(err_v, 1e-6);   // m/s
  EXPECT_LT(err_w, 2e-9);   // 1/s (quaternion rate: half the body rate, rad/s)
  EXPECT_LT(err_a, 1e-6);   // m/s^2
  EXPECT_LT(err_dw, 1e-6);  // rad/s^2
  // the differences compared something that moves: the 27-32 Hz vibration's angular acceleration
  EXPECT_GT(max_dw, 1.0);
  EXPECT_GT(max_a, 1.0);
  std::printf("max differences: v %.2g m/s, dq/dt %.2g 1/s, a %.2g m/s^2, dw %.2g rad/s^2 (max |a| %.3g, |dw| %.3g)\n",
              err_v, err_w, err_a, err_dw, max_a, max_dw);
}

TEST(Motion, ShipRollsWithItsPeriod) {
  MotionConfig cfg;
  cfg.type = MotionType::ship;
  cfg.ship.pitch_amplitude_deg = 0;
  cfg.ship.yaw_amplitude_deg = 0;
  const auto m = make_motion(cfg, 100, 1);
  // roll is periodic with roll_period_s
  const auto q0 = m->at(10.0).q_enu_from_body, q1 = m->at(10.0 + cfg.ship.roll_period_s).q_enu_from_body;
  EXPECT_LT(q0.angularDistance(q1), 1e-9);
  double max_roll_rate = 0;
  for (double t = 0; t < 20; t += 0.01) max_roll_rate = std::max(max_roll_rate, std::abs(m->at(t).w_body_radps.x()));
  const double expected = cfg.ship.roll_amplitude_deg * 2 * kPi / cfg.ship.roll_period_s;  // deg/s
  EXPECT_NEAR(max_roll_rate * kDegPerRad, expected, 0.01 * expected);
}

// GIVEN a CSV with two attitudes, WHEN evaluated between them, THEN the attitude is their slerp
TEST(Motion, CsvImportSlerpsAttitudeAndInterpolatesPosition) {
  const auto f = temp_file("traj.csv",
                           "# a comment\nt,px,py,pz,qw,qx,qy,qz\n"
                           "0,0,0,0,1,0,0,0\n"
                           "1,1,0,0,0.7071067811865476,0,0,0.7071067811865476\n"
                           "2,2,0,0,0,0,0,1\n"
                           "3,3,0,0,-0.7071067811865476,0,0,0.7071067811865476\n");
  const auto pts = read_trajectory_csv(f);
  ASSERT_EQ(pts.size(), 4u);
  MotionConfig cfg;
  cfg.type = MotionType::csv;
  cfg.csv.file = f.string();
  const auto m = make_motion(cfg, 3, 1);
  const MotionState s = m->at(0.25);
  const Eigen::Quaterniond expect(Eigen::AngleAxisd(0.25 * kPi / 2, Eigen::Vector3d::UnitZ()));
  EXPECT_LT(s.q_enu_from_body.angularDistance(expect), 1e-12);
  EXPECT_NEAR(s.p_enu_m.x(), 0.25, 1e-12);  // a straight line stays straight (Catmull-Rom)
  EXPECT_NEAR(s.w_body_radps.z(), kPi / 2, 1e-9);
  // the sign flip of the last quaternion (same attitude as +) is taken the short way
  EXPECT_NEAR(m->at(2.5).w_body_radps.z(), kPi / 2, 1e-9);
  // held before the start and after the end
  EXPECT_LT(m->at(-1).p_enu_m.norm(), 1e-15);
  EXPECT_NEAR(m->at(10).p_enu_m.x(), 3.0, 1e-15);
}

// GIVEN EuRoC ground truth with stamps of 1.4e18 ns (a double holds them to 256 ns), WHEN read,
// THEN the times keep every ns (the importers' reader, differences formed in integers)
TEST(Motion, EurocGroundTruthLayoutIsRead) {
  const auto f = temp_file("euroc.csv",
                           "#timestamp [ns], p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], "
                           "q_RS_y [], q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], "
                           "b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], "
                           "b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]\n"
                           "1403636579758555392,4.688319,-1.786938,0.783338,0.534108,-0.153029,-0.827383,-0.082152,"
                           "-0.027876,0.033207,0.800006,-0.003172,0.021267,0.078502,-0.025266,0.136696,0.075593\n"
                           "1403636579763555585,4.688177,-1.786770,0.787350,0.534640,-0.152990,-0.826976,-0.082863,"
                           "-0.029272,0.033992,0.804771,-0.003172,0.021267,0.078502,-0.025266,0.136696,0.075593\n");
  const auto pts = read_trajectory_csv(f);
  ASSERT_EQ(pts.size(), 2u);
  EXPECT_NEAR(pts[0].t_s, 0.0, 0);
  EXPECT_NEAR(pts[1].t_s, 0.005000193, 1e-15);  // as doubles: 0.005000192
  EXPECT_NEAR(pts[1].p_enu_m.z(), 0.787350, 1e-12);
  EXPECT_NEAR(pts[0].q_enu_from_body.norm(), 1.0, 1e-15);
}

TEST(Motion, BadCsvNamesFileAndLine) {
  const auto f = temp_file("bad.csv", "t,px,py,pz,qw,qx,qy,qz\n0,0,0,0,1,0,0,0\n0,1,0,0,1,0,0,0\n");
  try {
    read_trajectory_csv(f);
    FAIL();
  } catch (const driftless::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:3"), std::string::npos) << e.what();
  }
  const auto g = temp_file("nohdr.csv", "time,x\n0,1\n");
  EXPECT_THROW(read_trajectory_csv(g), driftless::InputError);
}

}  // namespace
}  // namespace driftless::twin
