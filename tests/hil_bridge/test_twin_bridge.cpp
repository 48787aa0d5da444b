// The twin side of the bridge: the Simulator as a sample source, and the twin's sensor model
// driving the register-level MPU-6050 emulators read by the I2C driver.
#include <cmath>

#include <gtest/gtest.h>

#if DRIFTLESS_HIL_WITH_TWIN
#include "hil_bridge/i2c/emulated_bus.hpp"
#include "hil_bridge/i2c/i2c_source.hpp"
#include "hil_bridge/twin/sensor_model_generator.hpp"
#include "hil_bridge/twin/twin_source.hpp"
#endif

namespace driftless::hil {
namespace {

#if DRIFTLESS_HIL_WITH_TWIN
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
#else
TEST(TwinBridge, NeedsTheTwinLibrary) { GTEST_SKIP() << "built without driftless::twin"; }
#endif

}  // namespace
}  // namespace driftless::hil
