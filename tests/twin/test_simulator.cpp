// The simulator's truth: gyro truth = R_i^T w_body (+ platform rate during flips), Earth rate at
// the scenario latitude, static fast path = full physics, and byte-identical logs per seed.
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "estimator/log.hpp"
#include "estimator/geometry.hpp"
#include "tests/temp_path.hpp"
#include "tests/twin/mujoco_fixture.hpp"
#include "twin/simulator.hpp"

namespace driftless::twin {
namespace {

using testing::MujocoTest;

class SimulatorTest : public MujocoTest {};

Eigen::Matrix3d R_body_from_plat(const Scenario& s, int i, double angle_rad) {
  return Eigen::AngleAxisd(angle_rad, s.model.box.hinge_axis(i)).toRotationMatrix();
}

Scenario short_static(double duration_s) {
  Scenario s = default_scenario();
  s.duration_s = duration_s;
  s.flip_schedule.standstill_s = 4;
  return s;
}

// checks eq. (1) without errors on every sample: y_i = R_i^T w_body + theta_dot_i a_i
void expect_ideal_gyro_model(Simulator& sim, double tol_radps, int* moving_samples = nullptr) {
  Sample s;
  int moving = 0;
  while (sim.next(s)) {
    const SampleTruth& t = sim.truth();
    for (int i = 1; i <= 2; ++i) {
      const Eigen::Matrix3d R = R_body_from_plat(sim.scenario(), i, t.plat_rad[i - 1]);
      const Eigen::Vector3d expected =
          R.transpose() * t.w_body_radps + t.plat_rate_radps[i - 1] * sim.scenario().model.box.hinge_axis(i);
      ASSERT_LT((t.w_sensor_radps[i - 1] - expected).norm(), tol_radps)
          << "sensor " << i << " at t = " << t.t_s << " s";
      if (std::abs(t.plat_rate_radps[i - 1]) > 0.1) ++moving;
    }
  }
  if (moving_samples) *moving_samples = moving;
}

// GIVEN a static box at 52 deg N, WHEN it stands still, THEN its true rate is the Earth rate,
// 15.041 deg/h, split over the box axes by its attitude
TEST_F(SimulatorTest, StaticBoxSeesTheEarthRate) {
  Scenario sc = short_static(2);
  sc.motion.static_box.attitude_ypr_deg = Eigen::Vector3d(30, 20, -10);
  Simulator sim(sc);
  Sample s;
  ASSERT_TRUE(sim.next(s));
  const Eigen::Quaterniond q = quat_from_ypr(30 * kRadPerDeg, 20 * kRadPerDeg, -10 * kRadPerDeg);
  const Eigen::Vector3d expected = q.conjugate() * geo::earth_rate_enu_radps(52.0);
  EXPECT_LT((sim.truth().w_body_radps - expected).norm(), 1e-15);
  EXPECT_NEAR(s.true_rate_body_dps.norm() * 3600.0, 15.041, 0.001);
  EXPECT_NEAR(geo::earth_rate_enu_radps(52.0).z(), kEarthRateRadps * std::sin(52 * kRadPerDeg), 0);
}

// GIVEN a static box, WHEN platforms rest and flip, THEN each gyro's truth is R_i^T w_body at
// standstill and adds the platform rate theta_dot a_i during a flip (1e-9 rad/s)
TEST_F(SimulatorTest, GyroTruthIsRotatedBodyRatePlusPlatformRate) {
  Simulator sim(short_static(12));
  int moving = 0;
  expect_ideal_gyro_model(sim, 1e-9, &moving);
  EXPECT_GT(moving, 50) << "no flip happened in the test window";
}

// the same on a moving base (pan/tilt at up to 50 deg/s)
TEST_F(SimulatorTest, GyroTruthHoldsOnAMovingBase) {
  Scenario sc = load_scenario("pan_tilt");
  sc.duration_s = 15;
  sc.flip_schedule.standstill_s = 3;
  Simulator sim(sc);
  expect_ideal_gyro_model(sim, 1e-9);
}

// GIVEN the static default scenario, WHEN run with the fast path and with full physics,
// THEN the truth agrees to 1e-9 rad/s at every sample, and the fast path skips most steps
TEST_F(SimulatorTest, FastStandstillPathMatchesFullPhysics) {
  const Scenario sc = short_static(20);
  Simulator fast(sc, SimOptions{true});
  Simulator full(sc, SimOptions{false});
  Sample a, b;
  double worst = 0;
  while (fast.next(a)) {
    ASSERT_TRUE(full.next(b));
    for (int i = 0; i < 2; ++i) {
      worst = std::max(worst, (fast.truth().w_sensor_radps[i] - full.truth().w_sensor_radps[i]).norm());
      ASSERT_NEAR(fast.truth().plat_rad[i], full.truth().plat_rad[i], 1e-9);
    }
    ASSERT_EQ(std::isnan(a.plat1_deg), std::isnan(b.plat1_deg)) << "t = " << a.t_s;
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_LT(fast.physics_steps(), full.physics_steps() / 2);
}

TEST_F(SimulatorTest, KnownPlatformAnglesFollowTheReadbackMode) {
  Scenario sc = short_static(8);
  Simulator ends(sc);
  sc.platform_readback = PlatformReadback::encoder;
  Simulator enc(sc);
  Sample a, b;
  int empty = 0;
  while (ends.next(a) && enc.next(b)) {
    if (std::isnan(a.plat2_deg)) ++empty;
    else EXPECT_EQ(std::abs(a.plat2_deg), 90.0);
    EXPECT_NEAR(b.plat2_deg, b.true_plat2_deg, 1e-12);
  }
  EXPECT_GT(empty, 100);  // a flip of ~1.7 s leaves the end-stop read-back empty
}

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST_F(SimulatorTest, SameSeedGivesAByteIdenticalLog) {
  const auto dir = test::temp_path("driftless_test_sim");
  std::filesystem::create_directories(dir);
  Scenario sc = load_scenario("vehicle");
  sc.duration_s = 6;
  sc.flip_schedule.standstill_s = 2;
  simulate_to_log(sc, dir / "a.csv");
  simulate_to_log(sc, dir / "b.csv");
  sc.seed += 1;
  simulate_to_log(sc, dir / "c.csv");
  const std::string a = slurp(dir / "a.csv");
  EXPECT_GT(a.size(), 10000u);
  EXPECT_EQ(a, slurp(dir / "b.csv"));
  EXPECT_NE(a, slurp(dir / "c.csv"));
  log::Metadata meta;
  const auto rows = log::read_all(dir / "a.csv", &meta);
  EXPECT_EQ(rows.size(), 600u);
  EXPECT_TRUE(meta.complete());
}

TEST_F(SimulatorTest, StoppedRunLeavesAValidIncompleteLog) {
  const auto dir = test::temp_path("driftless_test_sim");
  std::filesystem::create_directories(dir);
  const auto r = simulate_to_log(short_static(30), dir / "stopped.csv", [](double f) { return f < 0.1; });
  EXPECT_FALSE(r.complete);
  log::Metadata meta;
  const auto rows = log::read_all(dir / "stopped.csv", &meta);
  EXPECT_FALSE(meta.complete());
  EXPECT_EQ(rows.size(), r.rows);
  EXPECT_LT(rows.size(), 3000u);
}

TEST_F(SimulatorTest, PoseFromSampleSetsBoxAndPlatforms) {
  Simulator sim(short_static(1));
  Sample s;
  sim.next(s);
  s.set_q_enu_from_body(Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ())));
  s.true_plat1_deg = 12.0;
  pose_world_from_sample(sim.world(), s, Carrier::pan_tilt);
  EXPECT_NEAR(sim.world().platform_angle_rad(1), 12.0 * kRadPerDeg, 1e-15);
  const mjtNum* xq = sim.world().data()->xquat + 4 * sim.world().box_body();
  EXPECT_NEAR(xq[0], std::cos(0.25), 1e-12);
}

}  // namespace
}  // namespace driftless::twin

namespace driftless::twin {
namespace {

// GIVEN sensor 1 with only a known constant bias and sensor 2 ideal, WHEN simulated, THEN the
// log's gyro columns are truth + bias and true_bias carries exactly that bias
TEST_F(SimulatorTest, GyroColumnsAreTheSensorModelAppliedToTheTruth) {
  Scenario sc = short_static(6);
  sc.model.sensor1 = ideal_sensor();
  set_effect_enabled(sc.model.sensor1, "constant_bias", true);
  sc.model.sensor1.constant_bias.value_dps = Eigen::Vector3d(1.0, -2.0, 3.0);
  sc.model.sensor1.constant_bias.sigma_dps = Eigen::Vector3d::Zero();
  sc.model.sensor2 = ideal_sensor();
  Simulator sim(sc);
  Sample s;
  while (sim.next(s)) {
    const Eigen::Vector3d w1 = sim.truth().w_sensor_radps[0] * kDegPerRad;
    const Eigen::Vector3d w2 = sim.truth().w_sensor_radps[1] * kDegPerRad;
    ASSERT_LT((s.true_bias1_dps - Eigen::Vector3d(1, -2, 3)).norm(), 1e-12);
    ASSERT_LT((s.gyro1_dps - s.true_bias1_dps - w1).norm(), 1e-9) << "t = " << s.t_s;
    ASSERT_LT((s.gyro2_dps - w2).norm(), 1e-12);
    ASSERT_LT(s.true_bias2_dps.norm(), 1e-15);
  }
}

}  // namespace
}  // namespace driftless::twin
