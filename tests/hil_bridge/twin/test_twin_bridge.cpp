// The twin side of the bridge: the Simulator as a sample source, its servos commanded by the
// bridge's motors, and the twin's sensor model driving the register-level MPU-6050 emulators
// (read by the I2C driver) and the emulated microcontroller on a pty (read by the serial source).
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/filter.hpp"
#include "estimator/geometry.hpp"
#include "estimator/log.hpp"
#include "hil_bridge/i2c/emulated_bus.hpp"
#include "hil_bridge/i2c/i2c_source.hpp"
#include "hil_bridge/live_loop.hpp"
#include "hil_bridge/source_rig.hpp"
#include "hil_bridge/twin/sensor_model_generator.hpp"
#include "hil_bridge/twin/twin_source.hpp"
#include "tests/temp_path.hpp"

namespace driftless::hil {
namespace {

TEST(TwinSource, StreamsTheSimulatorAtItsRate) {
  twin::Scenario sc = twin::default_scenario();
  sc.duration_s = 3.0;
  VirtualClock clock;
  TwinSource src(clock, sc, /*realtime=*/false);
  ASSERT_TRUE(src.configure().ok());
  ASSERT_TRUE(src.activate().ok());
  TwinMotors motors(src);
  EXPECT_FALSE(motors.command(1, -1).ok());  // the scenario drives the twin's servos
  Sample s;
  int n = 0;
  while (src.read(s) == ReadStatus::kSample) {
    EXPECT_NEAR(s.t_s, n / sc.sample_rate_hz, 1e-9);
    EXPECT_TRUE(s.gyros_finite());
    ++n;
  }
  EXPECT_EQ(n, static_cast<int>(std::lround(3.0 * sc.sample_rate_hz)));
  EXPECT_EQ(motors.end_stop(1), EndStop::kPlus);  // the default schedule starts at (+,+)
  log::Metadata meta;
  src.describe(meta);
  EXPECT_TRUE(meta.has("hinge1_axis"));
}

TEST(SensorModelGenerator, DrivesTheEmulatedChipsThroughTheDriver) {
  // GIVEN the twin's ideal sensor model behind two emulated MPU-6050s
  VirtualClock clock(10.0);
  BoxAtRestGenerator::Params box;
  SensorModelGenerator gen(twin::ideal_sensor(), twin::ideal_sensor(), 100.0, 3, box, nullptr);
  Mpu6050Emulator chip1(0, gen, clock), chip2(1, gen, clock);
  EmulatedI2cBus bus(clock, &clock);
  bus.attach(0x68, &chip1);
  bus.attach(0x69, &chip2);
  I2cSource src(bus, clock, {});
  ASSERT_TRUE(src.configure().ok());
  ASSERT_TRUE(src.activate().ok());
  // WHEN the driver reads 100 samples
  Sample s;
  int n = 0;
  Eigen::Vector3d mean1 = Eigen::Vector3d::Zero();
  for (int i = 0; i < 10000 && n < 100; ++i) {
    if (src.read(s) == ReadStatus::kSample) {
      mean1 += s.gyro1_dps;
      ++n;
      // THEN gravity shows in sensor 2's y (platform 2 at +90 deg about x), within one LSB
      EXPECT_NEAR(s.accel2_mps2.y(), kStandardGravityMps2, kStandardGravityMps2 / 16384.0);
    }
  }
  ASSERT_EQ(n, 100);
  mean1 /= n;
  // AND sensor 1 reads the Earth rate (z: 15.041 deg/h sin 52 deg) to within the quantisation
  EXPECT_NEAR(mean1.z(), 15.041 / 3600.0 * std::sin(52.0 * kRadPerDeg), 0.5 / 131.0);
  EXPECT_NEAR(mean1.x(), 0.0, 0.5 / 131.0);
}

// reads `seconds` of samples from a twin source
std::vector<Sample> read_for(TwinSource& src, double seconds) {
  std::vector<Sample> out;
  Sample s;
  const auto n = static_cast<std::size_t>(std::lround(seconds * src.sample_rate_hz()));
  while (out.size() < n && src.read(s) == ReadStatus::kSample) out.push_back(s);
  return out;
}

TEST(TwinMotors, CommandedFlipMovesTheSimulatedPlatform) {
  // GIVEN the default box (platforms on their + stops), its servos handed to the bridge
  twin::Scenario sc = twin::default_scenario();
  sc.duration_s = 60.0;
  VirtualClock clock;
  TwinSource src(clock, sc, /*realtime=*/false, /*bridge_flips=*/true);
  ASSERT_TRUE(src.configure().ok());
  ASSERT_TRUE(src.activate().ok());
  TwinMotors motors(src);
  // WHEN nothing is commanded for 25 s (the scenario alone would flip platform 2 at 20 s)
  const std::vector<Sample> quiet = read_for(src, 25.0);
  ASSERT_EQ(quiet.size(), 2500u);
  // THEN both platforms stay on their + stops: the scenario's schedule no longer flips them
  for (const Sample& s : quiet) {
    ASSERT_EQ(s.plat1_deg, 90.0) << s.t_s;
    ASSERT_EQ(s.plat2_deg, 90.0) << s.t_s;
  }
  EXPECT_EQ(motors.end_stop(1), EndStop::kPlus);

  // WHEN the bridge commands platform 1 to its - stop
  ASSERT_TRUE(motors.command(1, -1).ok());
  EXPECT_EQ(motors.end_stop(1), EndStop::kNone);  // moving: no switch closed
  const std::vector<Sample> flip = read_for(src, 10.0);
  ASSERT_EQ(flip.size(), 1000u);
  // THEN the MuJoCo platform turns from about +90 to about -90 deg (stop errors: default.yaml
  // puts the stops 0.12 / -0.08 deg off), sensor 1's z gyro (hinge 1 is box z) sees the turn,
  // the log's known angle is empty while it moves, and platform 2 stays where it was
  double max_rate = 0.0, min_true = 1e9;
  bool seen_moving = false;
  for (const Sample& s : flip) {
    max_rate = std::max(max_rate, std::abs(s.gyro1_dps.z()));
    min_true = std::min(min_true, s.true_plat1_deg);
    seen_moving = seen_moving || std::isnan(s.plat1_deg);
    EXPECT_EQ(s.plat2_deg, 90.0);
    EXPECT_NEAR(s.true_plat2_deg, 90.0, 1.0);
  }
  EXPECT_TRUE(seen_moving);
  EXPECT_GT(max_rate, 30.0);  // the servo's cruise rate, far above bias + Earth rate
  EXPECT_NEAR(flip.front().true_plat1_deg, 90.0, 1.0);
  EXPECT_NEAR(flip.back().true_plat1_deg, -90.0, 1.0);
  EXPECT_NEAR(min_true, -90.0, 1.5);
  // AND once settled the switches say so and the log's known angle is -90
  EXPECT_EQ(flip.back().plat1_deg, -90.0);
  EXPECT_EQ(motors.end_stop(1), EndStop::kMinus);
  EXPECT_EQ(src.simulator()->flips().flips(), 1);
  // a command toward where the platform already is starts nothing
  ASSERT_TRUE(motors.command(1, -1).ok());
  EXPECT_EQ(motors.end_stop(1), EndStop::kMinus);
  // bad commands are refused with a status, never a throw
  EXPECT_FALSE(motors.command(3, 1).ok());
  EXPECT_FALSE(motors.command(1, 0).ok());
  log::Metadata meta;
  src.describe(meta);
  EXPECT_EQ(meta.get("flip_control").value_or(""), "bridge");
}

TEST(TwinMotors, BridgeFlipScheduleDrivesTheTwinInTheLiveLoop) {
  // GIVEN the `twin` rig with bridge-driven flips (5 s standstills) in the live loop
  RigOptions opt;
  opt.twin_bridge_flips = true;
  opt.standstill_s = 5.0;
  auto rig = make_source_rig("twin", opt);
  ASSERT_NE(rig->motors, nullptr);
  ASSERT_NE(rig->schedule, nullptr);
  ASSERT_TRUE(rig->source->configure().ok());
  log::Metadata meta;
  rig->source->describe(meta);
  const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     ("driftless-twin-bridge-" + std::to_string(::getpid()) + ".csv");
  // the paper's filter (mode: paper) expects eq. (5)'s order of positions
  est::DriftlessFilter filter(est::paper_config(), est::box_geometry_from_metadata(meta));
  LiveStats st;
  {
    log::LogWriter writer(path, meta, rig->source->fields());
    LiveParams lp;
    lp.duration_s = 60.0;
    LiveLoop loop(lp, *rig->clock, &writer, &filter);
    loop.set_motors(rig->source, rig->motors, rig->schedule);
    std::atomic<bool> stop{false};
    st = loop.run(*rig->source, nullptr, stop);
    writer.finish(st.complete, st.end_reason);
  }
  // THEN the log holds every row and the platforms went through eq. (5)'s cycle
  // (+,+) -> (+,-) -> (-,-) -> (-,+) -> (+,+), the same order as the twin's own schedule (Fig. 3)
  EXPECT_TRUE(st.complete);
  log::Metadata back;
  const std::vector<Sample> rows = log::read_all(path, &back);
  std::filesystem::remove(path);
  ASSERT_EQ(rows.size(), 6000u);
  EXPECT_EQ(back.get("flip_control").value_or(""), "bridge");
  std::vector<std::pair<double, double>> positions;
  for (const Sample& s : rows) {
    if (std::isnan(s.plat1_deg) || std::isnan(s.plat2_deg)) continue;
    if (positions.empty() || positions.back() != std::make_pair(s.plat1_deg, s.plat2_deg))
      positions.emplace_back(s.plat1_deg, s.plat2_deg);
  }
  ASSERT_GE(positions.size(), 4u);
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const geo::FlipSigns want = geo::flip_cycle_at(static_cast<long long>(i));
    EXPECT_EQ(positions[i], std::make_pair(90.0 * want.plat1, 90.0 * want.plat2)) << "position " << i;
  }
  // the true MuJoCo angles follow the commands, and the paper-mode estimator updated at the
  // standstills with every measured position where eq. (5) expects it
  EXPECT_NEAR(rows.back().true_plat1_deg, positions.back().first, 1.0);
  EXPECT_GE(filter.counters().updates, 3u);
  EXPECT_EQ(filter.counters().schedule_mismatches, 0u);
  EXPECT_EQ(filter.counters().rejected, 0u);
}

TEST(TwinMotors, ScenarioDrivenTwinRefusesCommands) {
  twin::Scenario sc = twin::default_scenario();
  sc.duration_s = 1.0;
  VirtualClock clock;
  TwinSource src(clock, sc, false);
  ASSERT_TRUE(src.configure().ok());
  TwinMotors motors(src);
  const Status s = motors.command(1, -1);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message.find("--twin-flips bridge"), std::string::npos) << s.message;
  RigOptions opt;
  EXPECT_EQ(make_source_rig("twin", opt)->motors, nullptr);  // the scenario flips, no bridge motors
}

// the emulated microcontroller with the twin's sensor model (--emu-sensor), read over a pty
std::vector<Sample> emu_serial_samples(const std::string& preset, std::size_t n) {
  RigOptions opt;
  opt.emu_sensor = preset;
  opt.seed = 5;
  const std::string tag = "emu-sensor-" + preset + "-" + std::to_string(::getpid());
  opt.work_dir = test::temp_path(tag).string();
  std::filesystem::create_directories(opt.work_dir);
  auto rig = make_source_rig("emu-serial", opt);
  EXPECT_EQ(rig->start(), "");
  const Status c = rig->source->configure();
  EXPECT_TRUE(c.ok()) << c.message;
  std::vector<Sample> out;
  if (!c.ok()) return out;
  EXPECT_TRUE(rig->source->activate().ok());
  SteadyClock wall;
  const double t_end = wall.now_s() + 10.0;
  Sample s;
  while (out.size() < n && wall.now_s() < t_end) {
    if (rig->source->read(s) == ReadStatus::kSample) out.push_back(s);
  }
  rig->source->deactivate();
  rig.reset();
  std::filesystem::remove_all(opt.work_dir);
  return out;
}

TEST(EmuSerial, EmuSensorDrivesTheEmulatedMicrocontroller) {
  // GIVEN emu-serial with --emu-sensor mpu6050 (seed 5)
  const std::vector<Sample> got = emu_serial_samples("mpu6050", 50);
  ASSERT_EQ(got.size(), 50u);
  // THEN the frames carry the twin's sensor model: the same preset, seed and box run here give
  // every sample to within the MPU-6050's quantisation (1/131 deg/s, 1/16384 g), platforms at +90
  const twin::SensorParams sp = twin::sensor_preset("mpu6050");
  BoxAtRestGenerator::Params box;
  box.seed = 5;
  SensorModelGenerator ref(sp, sp, 100.0, 5, box, nullptr);
  for (std::size_t k = 0; k < got.size(); ++k) {
    const double t = static_cast<double>(k) / 100.0;
    ASSERT_NEAR(got[k].t_s, t, 1e-9);
    const ImuReading r1 = ref.sample(0, t), r2 = ref.sample(1, t);
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(got[k].gyro1_dps[a], r1.gyro_dps[a], 0.5 / 131.0 + 1e-9) << k << " " << a;
      EXPECT_NEAR(got[k].gyro2_dps[a], r2.gyro_dps[a], 0.5 / 131.0 + 1e-9) << k << " " << a;
      EXPECT_NEAR(got[k].accel1_mps2[a], r1.accel_mps2[a], 0.5 * kStandardGravityMps2 / 16384.0 + 1e-9);
    }
  }
  // AND it is not the built-in generator: its biases are (0.5, -0.3, 0.8) / (-0.6, 0.4, 0.2)
  // deg/s; the MPU-6050 preset draws turn-on biases of several deg/s
  const std::vector<Sample> ideal = emu_serial_samples("ideal", 20);
  ASSERT_EQ(ideal.size(), 20u);
  for (const Sample& s : ideal) {
    // ideal sensors: the Earth rate only (< 0.004 deg/s), quantised
    EXPECT_LT(s.gyro1_dps.cwiseAbs().maxCoeff(), 0.5 / 131.0 + 0.005);
    EXPECT_LT(s.gyro2_dps.cwiseAbs().maxCoeff(), 0.5 / 131.0 + 0.005);
  }
  // an unknown preset is refused before anything starts
  RigOptions bad;
  bad.emu_sensor = "no-such-chip";
  EXPECT_THROW(make_source_rig("emu-serial", bad), std::exception);
}

}  // namespace
}  // namespace driftless::hil
