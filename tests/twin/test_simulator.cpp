// The simulator's truth: gyro truth = R_i^T w_body (+ platform rate during flips), Earth rate at
// the scenario latitude, static fast path = full physics, and byte-identical logs per seed.
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include <fmt/core.h>

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

// How far the kinematic rest path may leave full MuJoCo stepping, per shipped scenario, and why.
// The rest path holds a platform rigidly on its stop; MuJoCo's stop is a spring-damper (solref
// 5 ms, 0.7: about 45 Hz, compliance ~0.024 rad/(N m) at the motor's 4 mN m press), so the
// difference is the stop's compression and ring under the base's inertial loads on the platform
// (inertia 6.4e-6 kg m^2 about its hinge).
struct RestBound {
  const char* scenario;
  double w_radps, f_mps2, angle_rad;  // gyro truth, specific-force truth, hinge angle
  const char* why;
};
const RestBound kRestBounds[] = {
    {"default", 1e-9, 1e-9, 1e-9, "static: the rest path starts once the platforms have settled below 1e-10 rad/s"},
    {"static", 1e-9, 1e-9, 1e-9, "static, as default"},
    {"paper_fig4", 1e-9, 1e-9, 1e-9, "static, as default"},
    {"paper_fig5", 1e-9, 1e-9, 1e-9, "static, platforms never move"},
    {"ship", 2e-6, 1e-6, 1e-7,
     "waves below 0.2 Hz load the stops quasi-statically (compression < 2e-8 rad); handing a loaded "
     "stop back to MuJoCo at a flip's start rings it by ~3e-7 rad/s"},
    {"pan_tilt", 2e-4, 3e-5, 3e-6,
     "the pan/tilt's 200 deg/s^2 acceleration steps (2.2e-5 N m) ring the 45 Hz stop: 5e-7 rad, 7e-5 rad/s"},
    {"paper_fig9", 2e-4, 3e-5, 3e-6, "pan/tilt, as pan_tilt"},
    {"vehicle", 5e-4, 1e-4, 1e-5,
     "27-32 Hz roll vibration (7.6 rad/s^2 about hinge 2) drives the 45 Hz stop near resonance: "
     "2e-6 rad, 1.5e-4 rad/s; the turns' rate steps are jolts MuJoCo steps through"},
};

void PrintTo(const RestBound& b, std::ostream* os) { *os << b.scenario; }

class RestPathTest : public SimulatorTest, public ::testing::WithParamInterface<RestBound> {};

// GIVEN a shipped scenario (its first flip and the rests around it), WHEN it runs on the kinematic
// rest path and with MuJoCo stepping throughout, THEN the truth differs by less than the
// scenario's bound at every sample, the end-stop read-back is the same, and the rest path skips
// most of the physics
TEST_P(RestPathTest, MatchesFullSteppingWithinTheStopsCompliance) {
  const RestBound& b = GetParam();
  Scenario sc = load_scenario(b.scenario);
  sc.duration_s = sc.flip_schedule.enabled ? sc.flip_schedule.standstill_s + 12.0 : 20.0;
  Simulator fast(sc, SimOptions{true});
  Simulator full(sc, SimOptions{false});
  Sample a, c;
  double worst_w = 0, worst_f = 0, worst_angle = 0;
  while (fast.next(a)) {
    ASSERT_TRUE(full.next(c));
    for (int i = 0; i < 2; ++i) {
      worst_w = std::max(worst_w, (fast.truth().w_sensor_radps[i] - full.truth().w_sensor_radps[i]).norm());
      worst_f = std::max(worst_f, (fast.truth().f_sensor_mps2[i] - full.truth().f_sensor_mps2[i]).norm());
      worst_angle = std::max(worst_angle, std::abs(fast.truth().plat_rad[i] - full.truth().plat_rad[i]));
    }
    ASSERT_EQ(std::isnan(a.plat1_deg), std::isnan(c.plat1_deg)) << "t = " << a.t_s;
    ASSERT_EQ(std::isnan(a.plat2_deg), std::isnan(c.plat2_deg)) << "t = " << a.t_s;
  }
  EXPECT_LT(worst_w, b.w_radps) << b.why;
  EXPECT_LT(worst_f, b.f_mps2) << b.why;
  EXPECT_LT(worst_angle, b.angle_rad) << b.why;
  EXPECT_LT(fast.physics_steps(), full.physics_steps() / 10);
}

INSTANTIATE_TEST_SUITE_P(EveryShippedScenario, RestPathTest, ::testing::ValuesIn(kRestBounds),
                         [](const auto& info) { return std::string(info.param.scenario); });

// GIVEN a static box flipping every 3 s (each kind of flip several times), WHEN the rest path
// replays the flips it has seen and MuJoCo steps every flip, THEN the truth agrees to 1e-9 at
// every sample, and MuJoCo stepped only the first flip of each of the four kinds
TEST_F(SimulatorTest, StaticFlipsReplayTheFirstFlipOfTheirKind) {
  Scenario sc = short_static(40);
  sc.flip_schedule.standstill_s = 3;
  Simulator fast(sc, SimOptions{true});
  Simulator full(sc, SimOptions{false});
  Sample a, c;
  double worst_w = 0, worst_f = 0, worst_angle = 0;
  int moving_samples = 0;
  while (fast.next(a)) {
    ASSERT_TRUE(full.next(c));
    for (int i = 0; i < 2; ++i) {
      worst_w = std::max(worst_w, (fast.truth().w_sensor_radps[i] - full.truth().w_sensor_radps[i]).norm());
      worst_f = std::max(worst_f, (fast.truth().f_sensor_mps2[i] - full.truth().f_sensor_mps2[i]).norm());
      worst_angle = std::max(worst_angle, std::abs(fast.truth().plat_rad[i] - full.truth().plat_rad[i]));
      if (std::abs(fast.truth().plat_rate_radps[i]) > 0.1) ++moving_samples;
    }
    ASSERT_EQ(std::isnan(a.plat1_deg), std::isnan(c.plat1_deg)) << "t = " << a.t_s;
    ASSERT_EQ(std::isnan(a.plat2_deg), std::isnan(c.plat2_deg)) << "t = " << a.t_s;
  }
  EXPECT_GE(fast.flips().flips(), 8) << "two of each kind at least";
  EXPECT_GT(moving_samples, 8 * 100) << "replayed flips move the platforms in the truth";
  EXPECT_LT(worst_w, 1e-9);
  EXPECT_LT(worst_f, 1e-9);
  EXPECT_LT(worst_angle, 1e-9);
  const double steps_per_flip = 1.65 / sc.physics_dt_s + 200;  // the move, then settling below 1e-10 rad/s
  EXPECT_LT(static_cast<double>(fast.physics_steps()), 4.0 * steps_per_flip);
}

// GIVEN a base whose rate steps (a jolt) while the platforms rest, WHEN the rest path looks
// ahead, THEN MuJoCo steps through the jolt (the rigid rest would miss the kick on the stop)
TEST_F(SimulatorTest, RestPathStepsThroughAJolt) {
  std::vector<TrajectoryPoint> pts;
  for (int k = 0; k <= 600; ++k) {
    const double t = k * 0.01;
    const double yaw = t < 3.0 ? 0.0 : 0.5 * (t - 3.0);  // the yaw rate jumps to 0.5 rad/s at 3 s
    pts.push_back({t, Eigen::Vector3d(0, 0, 1), Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()))});
  }
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "driftless_test_jolt";
  std::filesystem::create_directories(dir);
  {
    std::ofstream f(dir / "jolt.csv");
    f << "t,px,py,pz,qw,qx,qy,qz\n";
    for (const auto& p : pts) {
      const auto& q = p.q_enu_from_body;
      f << fmt::format("{},{},{},{},{},{},{},{}\n", p.t_s, 0, 0, 1, q.w(), q.x(), q.y(), q.z());
    }
  }
  Scenario sc = default_scenario();
  sc.duration_s = 6;
  sc.flip_schedule.enabled = false;
  sc.motion.type = MotionType::csv;
  sc.motion.csv.file = (dir / "jolt.csv").string();
  Simulator fast(sc, SimOptions{true});
  Simulator full(sc, SimOptions{false});
  Sample a, c;
  double worst = 0, kick = 0;
  std::uint64_t steps_before_jolt = 0;
  while (fast.next(a)) {
    full.next(c);
    if (a.t_s < 2.5) steps_before_jolt = fast.physics_steps();
    kick = std::max(kick, std::abs(full.truth().plat_rate_radps[0]));
    worst = std::max(worst, (fast.truth().w_sensor_radps[0] - full.truth().w_sensor_radps[0]).norm());
  }
  EXPECT_GT(kick, 5e-4) << "the jolt kicks platform 1 (hinge about z) on its stop";
  EXPECT_LT(worst, 1e-9) << "MuJoCo stepped the jolt on the rest path too";
  EXPECT_GT(fast.physics_steps(), steps_before_jolt + 100) << "stepped after the jolt";
  EXPECT_LT(fast.physics_steps(), full.physics_steps() / 5);
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

// GIVEN a static box whose platforms start on their - stops under an outside commander
TEST_F(SimulatorTest, AnOutsideCommanderStartsThePlatformsWhereItSaysAndFlipsThem) {
  Scenario sc = short_static(6);
  SimOptions opt;
  opt.external_flips = true;
  opt.initial_sign = {-1, -1};
  Simulator sim(sc, opt);
  Sample s;
  ASSERT_TRUE(sim.next(s));
  // THEN the run starts settled on the - stops (their planted errors included; the warm-up held
  // them there, 0.01 deg for the stops' compliance), the schedule never flips
  const BoxParams& box = sc.model.box;
  const auto stop_deg = [&](int i, int sign) { return box.stop_rad(i, sign) * kDegPerRad; };
  EXPECT_NEAR(s.true_plat1_deg, stop_deg(1, -1), 0.01);
  EXPECT_NEAR(s.true_plat2_deg, stop_deg(2, -1), 0.01);
  EXPECT_EQ(s.plat1_deg, -90.0);
  EXPECT_EQ(sim.metadata().get("flip_control").value_or(""), "external");
  // WHEN the commander flips platform 1 at 1 s, THEN it arrives on its + stop; platform 2 stays
  while (sim.next(s) && s.t_s < 1.0) {}
  sim.command_platform(1, +1);
  while (sim.next(s)) {}
  EXPECT_NEAR(s.true_plat1_deg, stop_deg(1, +1), 0.01);
  EXPECT_EQ(s.plat1_deg, 90.0);
  EXPECT_NEAR(s.true_plat2_deg, stop_deg(2, -1), 0.01);
  // AND a start other than (+,+) under the eq. (5) schedule is refused
  opt.external_flips = false;
  EXPECT_THROW(Simulator(sc, opt), std::invalid_argument);
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
  World world(sim.scenario().model.box);  // the full model: the simulator's has no carriers
  pose_world_from_sample(world, s, Carrier::pan_tilt);
  EXPECT_NEAR(world.platform_angle_rad(1), 12.0 * kRadPerDeg, 1e-15);
  EXPECT_THROW(pose_world_from_sample(sim.world(), s, Carrier::pan_tilt), std::logic_error);
  const mjtNum* xq = world.data()->xquat + 4 * world.box_body();
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
