// The register-level MPU-6050 emulator against the register map: identity, reset state, scaling,
// big-endian order, timing from SMPLRT_DIV / DLPF_CFG, FIFO and overflow, temperature formula.
#include <cstring>

#include <gtest/gtest.h>

#include "hil_bridge/clock.hpp"
#include "hil_bridge/i2c/emulated_bus.hpp"
#include "hil_bridge/i2c/mpu6050_emulator.hpp"

namespace driftless::hil {
namespace {

using namespace mpu6050;

// constant readings, so every sample is known exactly
class ConstantGenerator final : public ImuGenerator {
 public:
  ImuReading r;
  int calls = 0;
  ImuReading sample(int, double) override {
    ++calls;
    return r;
  }
};

struct Rig {
  VirtualClock clock;
  ConstantGenerator gen;
  Mpu6050Emulator chip{0, gen, clock};
  EmulatedI2cBus bus{clock};  // no bus time: timing checks stay exact
  Rig() { bus.attach(0x68, &chip); }
  std::uint8_t get(std::uint8_t reg) {
    std::uint8_t v = 0;
    EXPECT_EQ(bus.read_regs(0x68, reg, &v, 1), I2cResult::kOk);
    return v;
  }
  void set(std::uint8_t reg, std::uint8_t v) { EXPECT_EQ(bus.write_reg(0x68, reg, v), I2cResult::kOk); }
  int fifo_count() {
    std::uint8_t c[2];
    EXPECT_EQ(bus.read_regs(0x68, kFifoCountH, c, 2), I2cResult::kOk);
    return c[0] << 8 | c[1];
  }
};

TEST(Mpu6050Emulator, PowerOnStateIsAsleepWithIdentity) {
  Rig rig;
  EXPECT_EQ(rig.get(kWhoAmI), 0x68);
  EXPECT_EQ(rig.get(kPwrMgmt1), 0x40);
  rig.clock.advance(1.0);
  EXPECT_EQ(rig.get(kIntStatus), 0);  // asleep: no samples
  EXPECT_EQ(rig.chip.samples_generated(), 0u);
  EXPECT_EQ(rig.bus.read_regs(0x69, kWhoAmI, nullptr, 0), I2cResult::kNack);  // nobody at 0x69
}

TEST(Mpu6050Emulator, DataRegistersAreBigEndianScaledByFullScale) {
  Rig rig;
  rig.gen.r.gyro_dps = {100.0, -100.0, 0.5};
  rig.gen.r.accel_mps2 = {0.0, 0.0, kStandardGravityMps2};
  rig.gen.r.temp_c = 25.0;
  rig.set(kPwrMgmt1, kClkPllXGyro);
  rig.set(kConfig, 3);
  rig.set(kSmplrtDiv, 9);
  for (int fs = 0; fs < 4; ++fs) {
    rig.set(kGyroConfig, static_cast<std::uint8_t>(fs << 3));
    rig.clock.advance(0.0101);
    std::uint8_t b[14];
    ASSERT_EQ(rig.bus.read_regs(0x68, kAccelXoutH, b, 14), I2cResult::kOk);
    const RawRecord r = decode_record(b);
    const double lsb = gyro_lsb_per_dps(fs);
    EXPECT_EQ(r.gyro[0], static_cast<std::int16_t>(std::lround(100.0 * lsb))) << "FS_SEL " << fs;
    EXPECT_EQ(r.gyro[1], static_cast<std::int16_t>(std::lround(-100.0 * lsb)));
    EXPECT_EQ(r.gyro[2], static_cast<std::int16_t>(std::lround(0.5 * lsb)));
    EXPECT_EQ(r.accel[2], 16384);  // 1 g at +-2 g
  }
  // FS_SEL 0, 100 deg/s = 13100 = 0x332C: high byte first at GYRO_XOUT_H
  rig.set(kGyroConfig, 0);
  rig.clock.advance(0.0101);
  EXPECT_EQ(rig.get(kGyroXoutH), 0x33);
  EXPECT_EQ(rig.get(kGyroXoutH + 1), 0x2C);
  // temperature: raw = (25 - 36.53) * 340 = -3920.2 -> -3920; back: -3920/340 + 36.53
  std::uint8_t t[2];
  ASSERT_EQ(rig.bus.read_regs(0x68, kTempOutH, t, 2), I2cResult::kOk);
  EXPECT_EQ(be16(t), -3920);
  EXPECT_NEAR(temp_c_from_raw(be16(t)), 25.0, 0.5 / 340.0);
}

TEST(Mpu6050Emulator, SaturatesAtFullScale) {
  Rig rig;
  rig.gen.r.gyro_dps = {300.0, -300.0, 249.0};
  rig.set(kPwrMgmt1, kClkPllXGyro);
  rig.clock.advance(0.01);
  std::uint8_t b[6];
  ASSERT_EQ(rig.bus.read_regs(0x68, kGyroXoutH, b, 6), I2cResult::kOk);
  EXPECT_EQ(be16(b), 32767);
  EXPECT_EQ(be16(b + 2), -32768);
  EXPECT_EQ(be16(b + 4), 32619);  // 249 * 131
  EXPECT_TRUE(is_saturated(be16(b)));
  EXPECT_FALSE(is_saturated(be16(b + 4)));
}

TEST(Mpu6050Emulator, SampleRateFollowsSmplrtDivAndDlpf) {
  struct Case {
    int dlpf, div;
    double rate_hz;
  };
  for (const Case c : {Case{3, 9, 100.0}, Case{3, 0, 1000.0}, Case{0, 7, 1000.0}, Case{0, 79, 100.0},
                       Case{6, 4, 200.0}}) {
    Rig rig;
    rig.set(kConfig, static_cast<std::uint8_t>(c.dlpf));
    rig.set(kSmplrtDiv, static_cast<std::uint8_t>(c.div));
    rig.set(kPwrMgmt1, kClkPllXGyro);
    EXPECT_DOUBLE_EQ(rig.chip.sample_rate_hz(), c.rate_hz);
    rig.clock.advance(2.0);
    rig.get(kWhoAmI);  // any transaction brings the chip up to date
    EXPECT_EQ(rig.chip.samples_generated(), static_cast<std::uint64_t>(std::lround(2.0 * c.rate_hz)))
        << "DLPF_CFG " << c.dlpf << " SMPLRT_DIV " << c.div;
  }
  // the DLPF group delay grows with the filter (register map: 0.98 ms at 256 Hz .. 18.6 ms at 5 Hz)
  Rig rig;
  rig.set(kConfig, 0);
  const double d0 = rig.chip.gyro_delay_s();
  rig.set(kConfig, 6);
  EXPECT_NEAR(d0, 0.00098, 1e-9);
  EXPECT_NEAR(rig.chip.gyro_delay_s(), 0.0186, 1e-9);
}

TEST(Mpu6050Emulator, FifoFillsOverflowsAndResets) {
  Rig rig;
  rig.set(kPwrMgmt1, kClkPllXGyro);
  rig.set(kSmplrtDiv, 9);
  rig.set(kConfig, 3);
  rig.set(kFifoEn, kFifoEnTempGyroAccel);
  rig.set(kUserCtrl, kUserFifoEn | kUserFifoReset);
  rig.clock.advance(0.105);  // 10 samples
  EXPECT_EQ(rig.fifo_count(), 10 * kRecordBytes);
  EXPECT_EQ(rig.get(kIntStatus) & kIntFifoOflow, 0);
  // 14 bytes in register order: the same record a burst read gives
  std::uint8_t rec[14], burst[14];
  ASSERT_EQ(rig.bus.read_regs(0x68, kFifoRw, rec, 14), I2cResult::kOk);
  ASSERT_EQ(rig.bus.read_regs(0x68, kAccelXoutH, burst, 14), I2cResult::kOk);
  EXPECT_EQ(std::memcmp(rec, burst, 14), 0);
  EXPECT_EQ(rig.fifo_count(), 9 * kRecordBytes);
  // 1024 bytes hold 73 records: the 74th overflows, the flag latches until INT_STATUS is read
  rig.clock.advance(0.70);
  EXPECT_EQ(rig.fifo_count(), kFifoSizeBytes);
  EXPECT_GT(rig.chip.overflow_bytes_lost(), 0u);
  EXPECT_NE(rig.get(kIntStatus) & kIntFifoOflow, 0);
  EXPECT_EQ(rig.get(kIntStatus) & kIntFifoOflow, 0);  // cleared on read
  rig.set(kUserCtrl, kUserFifoEn | kUserFifoReset);
  EXPECT_EQ(rig.fifo_count(), 0);
  EXPECT_EQ(rig.get(kUserCtrl), kUserFifoEn);  // the reset bit clears itself
}

TEST(Mpu6050Emulator, DeviceResetRestoresPowerOnState) {
  Rig rig;
  rig.set(kPwrMgmt1, kClkPllXGyro);
  rig.set(kGyroConfig, 0x18);
  rig.set(kPwrMgmt1, kPwrDeviceReset);
  EXPECT_EQ(rig.get(kPwrMgmt1), 0x40);
  EXPECT_EQ(rig.get(kGyroConfig), 0);
  EXPECT_EQ(rig.get(kWhoAmI), 0x68);
}

TEST(EmulatedI2cBus, InjectedFaultsHitTheChosenTransactions) {
  Rig rig;
  rig.bus.fail_next(0x68, 2, I2cResult::kNack);
  std::uint8_t v = 0;
  EXPECT_EQ(rig.bus.read_regs(0x68, kWhoAmI, &v, 1), I2cResult::kNack);
  EXPECT_EQ(rig.bus.read_regs(0x68, kWhoAmI, &v, 1), I2cResult::kNack);
  EXPECT_EQ(rig.bus.read_regs(0x68, kWhoAmI, &v, 1), I2cResult::kOk);
  rig.bus.unplug(0x68, 1.0, 2.0);
  rig.set(kPwrMgmt1, kClkPllXGyro);
  rig.clock.sleep_until(1.5);
  EXPECT_EQ(rig.bus.read_regs(0x68, kWhoAmI, &v, 1), I2cResult::kNack);
  rig.clock.sleep_until(2.5);
  EXPECT_EQ(rig.get(kPwrMgmt1), 0x40);  // came back in its power-on state
  rig.bus.unplug_adapter(3.0, 4.0);
  rig.clock.sleep_until(3.5);
  EXPECT_EQ(rig.bus.read_regs(0x68, kWhoAmI, &v, 1), I2cResult::kNoAdapter);
  EXPECT_FALSE(rig.bus.reopen());
  rig.clock.sleep_until(4.5);
  EXPECT_EQ(rig.bus.read_regs(0x68, kWhoAmI, &v, 1), I2cResult::kNoAdapter);  // latched until reopened
  EXPECT_TRUE(rig.bus.reopen());
  EXPECT_EQ(rig.bus.read_regs(0x68, kWhoAmI, &v, 1), I2cResult::kOk);
}

}  // namespace
}  // namespace driftless::hil
