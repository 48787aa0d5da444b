// The serial link: frame codec, and the serial source over a real pseudo-terminal pair with the
// firmware emulator writing frames from its own thread at 100 Hz and 1 kHz, with faults.
#include <unistd.h>

#include <cmath>
#include <functional>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "hil_bridge/clock.hpp"
#include "hil_bridge/serial/firmware_emulator.hpp"
#include "hil_bridge/serial/frame.hpp"
#include "hil_bridge/serial/serial_source.hpp"

namespace driftless::hil {
namespace {

TEST(SerialFrame, CrcMatchesTheCcittFalseCheckValue) {
  const std::string check = "123456789";
  EXPECT_EQ(serial::crc16_ccitt(reinterpret_cast<const std::uint8_t*>(check.data()), check.size()), 0x29B1);
}

TEST(SerialFrame, RoundTripsAndLaysOutBytesAsDocumented) {
  serial::SampleFrame f;
  f.seq = 0x1234;
  f.t_us = 0xA1B2C3D4;
  for (int i = 0; i < 14; ++i) {
    f.sensor1[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(i);
    f.sensor2[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(100 + i);
  }
  f.config = 0x05;
  f.end_stops = serial::kStop1Plus | serial::kStop2Minus;
  f.status = serial::kStatusSensor2Failed;
  std::vector<std::uint8_t> b;
  serial::encode(f, b);
  ASSERT_EQ(b.size(), serial::kSampleFrameBytes);
  EXPECT_EQ(b[0], 0xA5);
  EXPECT_EQ(b[1], 0x5A);
  EXPECT_EQ(b[2], 0x01);
  EXPECT_EQ(b[3], 37);
  EXPECT_EQ(b[4], 0x34);  // seq, little-endian
  EXPECT_EQ(b[5], 0x12);
  EXPECT_EQ(b[6], 0xD4);  // t_us, little-endian
  EXPECT_EQ(b[9], 0xA1);
  EXPECT_EQ(b[10], 0);    // sensor 1 registers from 0x3B
  EXPECT_EQ(b[24], 100);  // sensor 2 registers from 0x3B
  EXPECT_EQ(b[38], 0x05);
  EXPECT_EQ(b[39], 0x06);
  EXPECT_EQ(b[40], 0x02);
  const std::uint16_t crc = serial::crc16_ccitt(b.data() + 2, 39);
  EXPECT_EQ(b[41], crc & 0xFF);
  EXPECT_EQ(b[42], crc >> 8);

  serial::Decoder d;
  d.feed(b.data(), b.size());
  serial::SampleFrame g;
  ASSERT_EQ(d.next(&g, nullptr), serial::Decoder::Result::kSample);
  EXPECT_EQ(g.seq, f.seq);
  EXPECT_EQ(g.t_us, f.t_us);
  EXPECT_EQ(g.sensor2, f.sensor2);
  EXPECT_EQ(g.end_stops, f.end_stops);
  EXPECT_EQ(d.next(&g, nullptr), serial::Decoder::Result::kNone);
}

TEST(SerialFrame, DecoderResynchronisesAfterCorruptionAndStrayBytes) {
  std::vector<std::uint8_t> b;
  serial::SampleFrame f;
  for (std::uint16_t s = 0; s < 4; ++s) {
    f.seq = s;
    if (s == 2) b.insert(b.end(), {0xA5, 0x00, 0x5A, 0xA5});  // stray bytes, one false sync
    serial::encode(f, b);
  }
  b[4 + 43 + 20] ^= 0x80;  // damage frame 1
  serial::Decoder d;
  // byte by byte, as a slow link delivers them
  std::vector<std::uint16_t> seqs;
  int corrupt = 0;
  for (std::uint8_t byte : b) {
    d.feed(&byte, 1);
    for (auto r = d.next(&f, nullptr); r != serial::Decoder::Result::kNone; r = d.next(&f, nullptr)) {
      if (r == serial::Decoder::Result::kSample) seqs.push_back(f.seq);
      if (r == serial::Decoder::Result::kCorrupt) ++corrupt;
    }
  }
  EXPECT_EQ(seqs, (std::vector<std::uint16_t>{0, 2, 3}));
  EXPECT_GE(corrupt, 1);
}

std::string temp_link(const std::string& tag) {
  return (std::filesystem::temp_directory_path() /
          ("driftless-test-" + tag + "-" + std::to_string(::getpid())))
      .string();
}

struct Stream {
  std::vector<Sample> samples;
  std::vector<SourceEvent> events;
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

// streams from the emulator until it is done and the tty is drained (bounded by wall time)
Stream stream(FirmwareEmulator& emu, SerialSourceParams sp, double max_wall_s, Motors** motors_out = nullptr,
           const std::function<void(double, Motors&)>& on_sample = {}) {
  SteadyClock clock;
  SerialSource src(clock, sp);
  SerialMotors motors(src);
  if (motors_out) *motors_out = &motors;
  Stream run;
  const Status c = src.configure();
  EXPECT_TRUE(c.ok()) << c.message;
  if (!c.ok()) return run;
  EXPECT_TRUE(src.activate().ok());
  const double t_end = clock.now_s() + max_wall_s;
  Sample s;
  while (clock.now_s() < t_end) {
    const ReadStatus st = src.read(s);
    src.take_events(run.events);
    if (st == ReadStatus::kSample) {
      run.samples.push_back(s);
      if (on_sample) on_sample(s.t_s, motors);
    } else if (st == ReadStatus::kDisconnected) {
      clock.sleep_for(0.02);
      src.reconnect();
      src.take_events(run.events);
    } else if (st == ReadStatus::kPending && emu.finished()) {
      break;
    }
  }
  src.deactivate();
  return run;
}

void expect_monotonic_and_accounted(const Stream& run, double rate_hz) {
  std::uint64_t skipped = 0;
  for (std::size_t i = 1; i < run.samples.size(); ++i) {
    const double dt = run.samples[i].t_s - run.samples[i - 1].t_s;
    ASSERT_GT(dt, 0.0) << "sample " << i;
    skipped += static_cast<std::uint64_t>(std::llround(dt * rate_hz)) - 1;
  }
  EXPECT_EQ(skipped, run.lost()) << "every jump in time is reported, with the number lost";
}

FirmwareParams firmware(const std::string& tag, double rate_hz, double duration_s) {
  FirmwareParams p;
  p.link_path = temp_link(tag);
  p.rate_hz = rate_hz;
  p.duration_s = duration_s;
  p.generator.noise_density_dps_rthz = 0.0;
  return p;
}

TEST(SerialSource, StreamsAt100HzOverAPty) {
  FirmwareParams fp = firmware("100hz", 100.0, 1.0);
  fp.t0_us = 0xFFFFFFFFu - 300000u;  // the 32-bit microsecond counter wraps 0.3 s in
  FirmwareEmulator emu(fp);
  ASSERT_EQ(emu.start(), "");
  SerialSourceParams sp;
  sp.path = emu.tty_path();
  sp.sample_rate_hz = 100.0;
  const Stream run = stream(emu, sp, 5.0);
  ASSERT_EQ(run.samples.size(), 100u);
  EXPECT_TRUE(run.events.empty()) << run.events.front().text;
  for (std::size_t i = 0; i < run.samples.size(); ++i) {
    const Sample& s = run.samples[i];
    EXPECT_NEAR(s.t_s, i * 0.01, 1e-9);
    // no noise: the bias plus the Earth rate seen through the platform, quantised to 1/131 deg/s
    EXPECT_NEAR(s.gyro1_dps.z(), 0.8 + 15.041 / 3600.0 * std::sin(52.0 * kRadPerDeg), 0.5 / 131.0 + 1e-6);
    EXPECT_EQ(s.plat1_deg, 90.0);
    EXPECT_EQ(s.plat2_deg, 90.0);
    EXPECT_NEAR(s.temp1_c, 30.0, 1.0 / 340.0);
  }
}

TEST(SerialSource, KeepsUpWith1kHzOverAPty) {
  FirmwareEmulator emu(firmware("1khz", 1000.0, 1.0));
  ASSERT_EQ(emu.start(), "");
  SerialSourceParams sp;
  sp.path = emu.tty_path();
  sp.sample_rate_hz = 1000.0;
  const Stream run = stream(emu, sp, 5.0);
  EXPECT_EQ(run.samples.size(), 1000u);
  EXPECT_EQ(emu.frames_sent(), 1000u);
  expect_monotonic_and_accounted(run, 1000.0);
  EXPECT_EQ(run.lost(), 0u);
}

TEST(SerialSource, CorruptMissingAndStrayFramesAreReportedNotInvented) {
  FirmwareParams fp = firmware("faults", 100.0, 1.0);
  fp.faults.corrupt_seq = {10, 11, 50};
  fp.faults.drop_seq = {30, 31, 32};
  fp.faults.garbage_before_seq = {70};
  fp.faults.fail_sensor2_from_s = 0.8;
  fp.faults.fail_sensor2_to_s = 0.85;
  FirmwareEmulator emu(fp);
  ASSERT_EQ(emu.start(), "");
  SerialSourceParams sp;
  sp.path = emu.tty_path();
  const Stream run = stream(emu, sp, 5.0);
  EXPECT_EQ(run.samples.size(), 100u - 6u);  // 3 corrupt + 3 dropped
  EXPECT_GE(run.count(EventKind::kCorruptFrame), 3);
  EXPECT_EQ(run.count(EventKind::kSequenceGap), 3);  // after 9, 29 and 49
  EXPECT_EQ(run.lost(), 6u);
  EXPECT_EQ(run.count(EventKind::kBusError), 2);  // sensor 2 fails, then reads again
  int empty2 = 0;
  for (const auto& s : run.samples) empty2 += !s.gyro2_dps.allFinite();
  EXPECT_EQ(empty2, 5);
  expect_monotonic_and_accounted(run, 100.0);
}

TEST(SerialSource, PauseIsATimeoutAndAGap) {
  FirmwareParams fp = firmware("pause", 100.0, 1.0);
  fp.faults.pause_from_s = 0.3;
  fp.faults.pause_to_s = 0.6;
  FirmwareEmulator emu(fp);
  ASSERT_EQ(emu.start(), "");
  SerialSourceParams sp;
  sp.path = emu.tty_path();
  sp.stall_timeout_s = 0.15;
  const Stream run = stream(emu, sp, 5.0);
  EXPECT_EQ(run.samples.size(), 70u);
  EXPECT_GE(run.count(EventKind::kTimeout), 1);
  EXPECT_EQ(run.lost(), 30u);
  expect_monotonic_and_accounted(run, 100.0);
}

TEST(SerialSource, TtyThatVanishesAndComesBackIsReopened) {
  FirmwareParams fp = firmware("hangup", 100.0, 1.2);
  fp.faults.hangup_from_s = 0.4;
  fp.faults.hangup_to_s = 0.7;
  FirmwareEmulator emu(fp);
  ASSERT_EQ(emu.start(), "");
  SerialSourceParams sp;
  sp.path = emu.tty_path();
  const Stream run = stream(emu, sp, 5.0);
  EXPECT_EQ(run.count(EventKind::kDisconnected), 1);
  EXPECT_EQ(run.count(EventKind::kReconnected), 1);
  // frames 40..69 were never sent (and any still buffered in the closed pty are gone too); the
  // host clock estimates the gap, so received + lost spans the 120 frames within a few periods
  EXPECT_GE(run.samples.size(), 75u);
  EXPECT_LE(run.samples.size(), 90u);
  EXPECT_NEAR(static_cast<double>(run.samples.size() + run.lost()), 120.0, 8.0);
  expect_monotonic_and_accounted(run, 100.0);
}

TEST(SerialSource, SaturationIsReportedAndWrittenEmpty) {
  FirmwareParams fp = firmware("sat", 100.0, 0.5);
  fp.generator.extra_rate_dps = [](double t) {
    return Eigen::Vector3d(0.0, 0.0, t >= 0.2 && t < 0.3 ? 300.0 : 0.0);
  };
  FirmwareEmulator emu(fp);
  ASSERT_EQ(emu.start(), "");
  SerialSourceParams sp;
  sp.path = emu.tty_path();
  const Stream run = stream(emu, sp, 5.0);
  ASSERT_EQ(run.samples.size(), 50u);
  int empty = 0;
  for (const auto& s : run.samples) empty += std::isnan(s.gyro1_dps.z());
  EXPECT_EQ(empty, 10);
  // box z is sensor 1 z and (platform 2 at +90 deg about x) sensor 2 y: start and end for each
  EXPECT_EQ(run.count(EventKind::kSaturation), 4);
  for (const auto& s : run.samples) EXPECT_EQ(std::isnan(s.gyro2_dps.y()), std::isnan(s.gyro1_dps.z()));
}

TEST(SerialSource, MotorsFlipOverTheLinkAndEndStopsComeBack) {
  FirmwareParams fp = firmware("motors", 100.0, 1.5);
  fp.motors.speed_dps = 900.0;  // 0.2 s per flip keeps the test short
  FirmwareEmulator emu(fp);
  ASSERT_EQ(emu.start(), "");
  SerialSourceParams sp;
  sp.path = emu.tty_path();
  FlipSchedule schedule({0.3, 2.0});
  const Stream run = stream(emu, sp, 5.0, nullptr, [&](double t, Motors& m) { schedule.update(t, m); });
  EXPECT_GE(emu.commands_received(), 1u);
  // platform 1 goes +90 -> -90 first: empty while moving, then -90
  bool moving_seen = false, minus_seen = false;
  for (const auto& s : run.samples) {
    moving_seen |= std::isnan(s.plat1_deg);
    minus_seen |= s.plat1_deg == -90.0;
  }
  EXPECT_TRUE(moving_seen);
  EXPECT_TRUE(minus_seen);
  EXPECT_GE(schedule.phase(), 1);
}

TEST(SerialSource, MissingTtyGivesOneClearError) {
  SteadyClock clock;
  SerialSourceParams sp;
  sp.path = "/dev/ttyDoesNotExist9";
  SerialSource src(clock, sp);
  const Status s = src.configure();
  EXPECT_EQ(s.code, Status::Code::kNotFound);
  EXPECT_NE(s.message.find("/dev/ttyDoesNotExist9: no such serial device"), std::string::npos) << s.message;
  sp.sample_rate_hz = 1000.0;
  sp.baud = 115200;  // 43 kB/s does not fit
  sp.path = "/dev/null";
  SerialSource slow(clock, sp);
  EXPECT_EQ(slow.configure().code, Status::Code::kBadConfig);
}

}  // namespace
}  // namespace driftless::hil
