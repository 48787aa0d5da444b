// The I2C driver end to end against two emulated MPU-6050s, and every bus fault injected
// through the emulated bus. The generator writes its own time into gyro x, so each sample
// says which instant it measured: a test can tell a lost, duplicated or invented sample.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "hil_bridge/clock.hpp"
#include "hil_bridge/i2c/emulated_bus.hpp"
#include "hil_bridge/i2c/i2c_source.hpp"
#include "hil_bridge/i2c/linux_i2c.hpp"

namespace driftless::hil {
namespace {

using namespace mpu6050;

// gyro x = 10 deg/s per s of time (period 20 s, well inside +-250), sensor 2 negated;
// gyro y, z, accel and temperature constant
class ClockGenerator final : public ImuGenerator {
 public:
  double spike_from_s = 1e9, spike_to_s = -1.0;  // a 400 deg/s spike on z in this window
  ImuReading sample(int sensor, double t_s) override {
    ImuReading r;
    const double sign = sensor == 0 ? 1.0 : -1.0;
    r.gyro_dps = {sign * 10.0 * std::fmod(t_s, 20.0), 0.25, -0.5};
    if (t_s >= spike_from_s && t_s < spike_to_s) r.gyro_dps.z() = 400.0;
    r.accel_mps2 = {0.0, 0.0, kStandardGravityMps2};
    r.temp_c = 31.0 + sensor;
    return r;
  }
};

struct Rig {
  VirtualClock clock{100.0};
  ClockGenerator gen;
  Mpu6050Emulator chip1{0, gen, clock}, chip2{1, gen, clock};
  EmulatedI2cBus bus{clock, &clock};
  I2cSourceParams params;
  std::unique_ptr<I2cSource> src;
  std::vector<SourceEvent> events;

  explicit Rig(double rate_hz = 100.0, bool fifo = true) {
    bus.attach(0x68, &chip1);
    bus.attach(0x69, &chip2);
    params.sample_rate_hz = rate_hz;
    params.use_fifo = fifo;
    src = std::make_unique<I2cSource>(bus, clock, params);
  }
  void start() {
    ASSERT_TRUE(src->configure().ok());
    ASSERT_TRUE(src->activate().ok());
  }
  // reads until `n` samples arrived, reconnecting when told; gives up after `max_calls`
  std::vector<Sample> read(std::size_t n, int max_calls = 100000) {
    std::vector<Sample> out;
    Sample s;
    for (int i = 0; i < max_calls && out.size() < n; ++i) {
      const ReadStatus st = src->read(s);
      if (st == ReadStatus::kSample) out.push_back(s);
      if (st == ReadStatus::kDisconnected) {
        clock.advance(0.1);
        src->reconnect();
      }
      src->take_events(events);
    }
    return out;
  }
  int count(EventKind k) const {
    int c = 0;
    for (const auto& e : events) c += e.kind == k;
    return c;
  }
  std::uint64_t lost() const {
    std::uint64_t l = 0;
    for (const auto& e : events) l += e.lost_samples;
    return l;
  }
};

// the device time a sample measured, from its gyro x (10 deg/s per s)
double measured_time(const Sample& s) { return s.gyro1_dps.x() / 10.0; }

// every sample is honest: its timestamp keeps a fixed offset to the instant it measured, and
// timestamps step by exactly one period except where the log is told about a gap
void expect_honest(const std::vector<Sample>& v, double rate_hz, std::uint64_t reported_lost) {
  ASSERT_GE(v.size(), 2u);
  const double offset = measured_time(v[0]) - v[0].t_s;
  std::uint64_t skipped = 0;
  for (std::size_t i = 1; i < v.size(); ++i) {
    ASSERT_GT(v[i].t_s, v[i - 1].t_s) << "timestamps must increase, sample " << i;
    const double steps = (v[i].t_s - v[i - 1].t_s) * rate_hz;
    ASSERT_NEAR(steps, std::round(steps), 1e-6);
    skipped += static_cast<std::uint64_t>(std::lround(steps)) - 1;
    // the measured instant follows the timestamp (within one period after a host-clock re-anchor)
    EXPECT_NEAR(measured_time(v[i]) - v[i].t_s, offset, 1.5 / rate_hz + 1e-3) << "sample " << i;
  }
  EXPECT_EQ(skipped, reported_lost) << "every skipped sample is reported as lost, no more, no less";
}

TEST(I2cSource, ReadsBothSensorsThroughTheFifo) {
  Rig rig;
  rig.start();
  const auto v = rig.read(500);
  ASSERT_EQ(v.size(), 500u);
  for (std::size_t i = 0; i < v.size(); ++i) EXPECT_NEAR(v[i].t_s, i / 100.0, 1e-12);
  for (const auto& s : v) {
    EXPECT_NEAR(s.gyro1_dps.y(), 0.25, 0.5 / 131.0);
    EXPECT_NEAR(s.gyro2_dps.z(), -0.5, 0.5 / 131.0);
    // the chips run on their own sample clocks, woken a few bus transactions apart (< 2 ms)
    EXPECT_NEAR(s.gyro1_dps.x(), -s.gyro2_dps.x(), 10.0 * 0.002 + 1.0 / 131.0);
    EXPECT_NEAR(s.accel1_mps2.z(), kStandardGravityMps2, kStandardGravityMps2 / 16384.0);
    EXPECT_NEAR(s.temp1_c, 31.0, 1.0 / 340.0);
    EXPECT_NEAR(s.temp2_c, 32.0, 1.0 / 340.0);
  }
  expect_honest(v, 100.0, 0);
  EXPECT_TRUE(rig.events.empty());
  // the measured instants advance exactly one period per sample
  EXPECT_NEAR(measured_time(v.back()) - measured_time(v.front()), 4.99, 2.0 / 131.0 / 10.0);
}

TEST(I2cSource, ConfiguresTheChips) {
  Rig rig(1000.0);
  rig.params.gyro_fs_sel = 2;
  rig.src = std::make_unique<I2cSource>(rig.bus, rig.clock, rig.params);
  rig.start();
  EXPECT_EQ(rig.chip1.reg(kPwrMgmt1), kClkPllXGyro);  // awake, PLL on the X gyro
  EXPECT_EQ(rig.chip2.reg(kSmplrtDiv), 0);              // 1 kHz / (1 + 0)
  EXPECT_EQ(rig.chip2.reg(kConfig), 3);
  EXPECT_EQ(rig.chip1.reg(kGyroConfig), 2 << 3);
  EXPECT_DOUBLE_EQ(rig.chip1.sample_rate_hz(), 1000.0);
  const auto v = rig.read(2000);
  ASSERT_EQ(v.size(), 2000u);
  expect_honest(v, 1000.0, 0);
  EXPECT_NEAR(v[5].gyro1_dps.y(), 0.25, 0.5 / 32.8);
}

TEST(I2cSource, BurstModeReadsTheDataRegisters) {
  Rig rig(100.0, /*fifo=*/false);
  rig.start();
  const auto v = rig.read(300);
  ASSERT_EQ(v.size(), 300u);
  expect_honest(v, 100.0, rig.lost());
  EXPECT_EQ(rig.lost(), 0u);
}

TEST(I2cSource, RejectsUnreachableRatesAndMissingDevices) {
  I2cSourceParams p;
  p.sample_rate_hz = 300.0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p.sample_rate_hz = 1000.0;
  EXPECT_EQ(p.smplrt_div(), 0);
  p.dlpf_cfg = 0;
  EXPECT_EQ(p.smplrt_div(), 7);  // 8 kHz without the DLPF

  Rig rig;
  rig.bus.unplug(0x69, 0.0, 1e9);
  const Status s = rig.src->configure();
  EXPECT_EQ(s.code, Status::Code::kNotFound);
  EXPECT_NE(s.message.find("0x69"), std::string::npos) << s.message;
}

TEST(I2cSource, MissingLinuxBusGivesOneClearError) {
  VirtualClock clock;
  LinuxI2c bus("/dev/i2c-nonexistent-77");
  I2cSource src(bus, clock, {});
  const Status s = src.configure();
  EXPECT_EQ(s.code, Status::Code::kNotFound);
  EXPECT_NE(s.message.find("/dev/i2c-nonexistent-77"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("no such I2C device"), std::string::npos) << s.message;
}

TEST(I2cSource, NackAndEioAreReportedAndNothingIsLost) {
  Rig rig;
  rig.start();
  auto v = rig.read(100);
  // two failures on the count read: the FIFO keeps the data, so no sample is lost
  rig.bus.fail_next(0x69, 1, I2cResult::kNack);
  rig.bus.fail_next(0x68, 1, I2cResult::kIoError);
  auto w = rig.read(200);
  v.insert(v.end(), w.begin(), w.end());
  EXPECT_EQ(rig.count(EventKind::kBusError), 2);
  expect_honest(v, 100.0, rig.lost());
}

TEST(I2cSource, TimeoutsAreReported) {
  Rig rig;
  rig.start();
  auto v = rig.read(50);
  rig.bus.fail_next(0, 2, I2cResult::kTimeout, 0.025);
  auto w = rig.read(100);
  v.insert(v.end(), w.begin(), w.end());
  EXPECT_EQ(rig.count(EventKind::kTimeout), 2);
  expect_honest(v, 100.0, rig.lost());
}

// fails the first FIFO data read it sees (after `arm_after` of them succeeded)
class FailOneFifoRead final : public I2cTransport {
 public:
  FailOneFifoRead(I2cTransport& inner, int arm_after) : inner_(inner), left_(arm_after) {}
  std::string name() const override { return inner_.name(); }
  I2cResult transfer(std::uint8_t a, const std::uint8_t* wr, std::size_t nwr, std::uint8_t* rd,
                     std::size_t nrd) override {
    if (nwr == 1 && wr[0] == kFifoRw && nrd > 0 && left_-- == 0) {
      inner_.transfer(a, wr, nwr, rd, nrd);  // the bytes leave the FIFO, the host gets an error
      return I2cResult::kIoError;
    }
    return inner_.transfer(a, wr, nwr, rd, nrd);
  }
  bool reopen() override { return inner_.reopen(); }

 private:
  I2cTransport& inner_;
  int left_;
};

TEST(I2cSource, FailedFifoReadResetsAndReportsTheLoss) {
  Rig rig;
  FailOneFifoRead flaky(rig.bus, 30);
  rig.src = std::make_unique<I2cSource>(flaky, rig.clock, rig.params);
  rig.start();
  auto v = rig.read(400);
  ASSERT_EQ(v.size(), 400u);
  EXPECT_EQ(rig.count(EventKind::kBusError), 1);
  EXPECT_EQ(rig.count(EventKind::kFifoOverflow), 1);  // the reset after the failed read
  expect_honest(v, 100.0, rig.lost());
  rig.src.reset();  // the source talks to `flaky` until it is gone (it puts the chips to sleep)
}

TEST(I2cSource, FifoOverflowIsDetectedAndTheGapMarked) {
  Rig rig;
  rig.start();
  auto v = rig.read(100);
  rig.clock.advance(2.0);  // the host stalls: 200 samples > 73 records fit
  auto w = rig.read(200);
  v.insert(v.end(), w.begin(), w.end());
  ASSERT_EQ(rig.count(EventKind::kFifoOverflow), 1);
  EXPECT_NEAR(static_cast<double>(rig.lost()), 200.0, 2.0);
  expect_honest(v, 100.0, rig.lost());
}

TEST(I2cSource, DeviceThatDisappearsAndComesBackIsReinitialised) {
  Rig rig;
  rig.start();
  auto v = rig.read(100);
  const double t_unplug = rig.clock.now_s() + 0.05;
  rig.bus.unplug(0x69, t_unplug, t_unplug + 1.5);
  auto w = rig.read(300);
  v.insert(v.end(), w.begin(), w.end());
  EXPECT_GE(rig.count(EventKind::kDisconnected), 1);
  EXPECT_EQ(rig.count(EventKind::kReconnected), 1);
  EXPECT_NEAR(static_cast<double>(rig.lost()), 150.0, 25.0);
  expect_honest(v, 100.0, rig.lost());
}

TEST(I2cSource, ShortBrownOutIsCaughtByTheStallCheck) {
  Rig rig;
  rig.start();
  auto v = rig.read(100);
  // both chips reset themselves without a single failed transaction: they just stop sampling
  rig.chip1.power_on_reset();
  rig.chip2.power_on_reset();
  auto w = rig.read(100);
  v.insert(v.end(), w.begin(), w.end());
  EXPECT_GE(rig.count(EventKind::kTimeout), 1);
  EXPECT_EQ(rig.count(EventKind::kReconnected), 1);
  expect_honest(v, 100.0, rig.lost());
}

TEST(I2cSource, AdapterThatVanishesIsReopened) {
  Rig rig;
  rig.start();
  auto v = rig.read(100);
  const double t = rig.clock.now_s();
  rig.bus.unplug_adapter(t, t + 0.8);
  auto w = rig.read(100);
  v.insert(v.end(), w.begin(), w.end());
  EXPECT_EQ(rig.count(EventKind::kDisconnected), 1);
  EXPECT_EQ(rig.count(EventKind::kReconnected), 1);
  expect_honest(v, 100.0, rig.lost());
}

TEST(I2cSource, SaturatedAxesAreEmptyAndReported) {
  Rig rig;
  rig.gen.spike_from_s = 101.0;
  rig.gen.spike_to_s = 101.3;
  rig.start();
  const auto v = rig.read(400);
  int empty = 0;
  for (const auto& s : v) {
    if (std::isnan(s.gyro1_dps.z())) {
      ++empty;
      EXPECT_TRUE(std::isfinite(s.gyro1_dps.x()));  // only the clipped axis goes
    }
  }
  EXPECT_NEAR(empty, 30, 1);
  EXPECT_EQ(rig.count(EventKind::kSaturation), 4);  // start and end, per sensor
  expect_honest(v, 100.0, 0);
}

}  // namespace
}  // namespace driftless::hil
