// The live loop: GIVEN a source (emulated I2C sensors, a replayed log), WHEN it runs with the
// estimator, a log writer, faults and a switch-over, THEN the log is a valid driftless log with
// one row per sample, monotonic time, an event line per fault / gap / switch, and the same
// filter object carries its state across the switch.
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "estimator/filter.hpp"
#include "estimator/health.hpp"
#include "estimator/log.hpp"
#include "hil_bridge/i2c/emulated_bus.hpp"
#include "hil_bridge/i2c/i2c_source.hpp"
#include "hil_bridge/live_loop.hpp"
#include "hil_bridge/replay_source.hpp"
#include "hil_bridge/serial/firmware_emulator.hpp"
#include "hil_bridge/serial/serial_source.hpp"

namespace driftless::hil {
namespace {

namespace fs = std::filesystem;

fs::path temp_file(const std::string& name) {
  return fs::temp_directory_path() / ("driftless-live-" + std::to_string(::getpid()) + "-" + name);
}

// two emulated MPU-6050s on an emulated bus, a box at rest with emulated motors
struct EmuRig {
  VirtualClock clock;
  EmulatedMotors motors{clock, {}};
  BoxAtRestGenerator gen;
  Mpu6050Emulator chip1{0, gen, clock}, chip2{1, gen, clock};
  EmulatedI2cBus bus{clock, &clock};
  I2cSource src;
  FlipSchedule schedule{{5.0, 10.0}};
  explicit EmuRig(std::uint64_t seed = 1)
      : gen(params(seed), &motors), src(bus, clock, I2cSourceParams{}) {
    bus.attach(0x68, &chip1);
    bus.attach(0x69, &chip2);
  }
  static BoxAtRestGenerator::Params params(std::uint64_t seed) {
    BoxAtRestGenerator::Params p;
    p.seed = seed;
    return p;
  }
};

log::Metadata box_meta() {
  log::Metadata m;
  m.set("sample_rate_hz", "100");
  m.set("latitude_deg", "52.0");
  return m;
}

struct Result {
  LiveStats stats;
  std::vector<Sample> rows;
  std::vector<log::Event> events;
  log::Metadata meta;
};

Result read_back(const fs::path& path, LiveStats stats) {
  Result r;
  r.stats = stats;
  log::LogReader reader(path);
  Sample s;
  while (reader.next(s)) r.rows.push_back(s);
  r.events = reader.events();
  r.meta = reader.metadata();
  return r;
}

int events_with(const Result& r, const std::string& word) {
  int n = 0;
  for (const auto& e : r.events) n += e.text.find(word) != std::string::npos;
  return n;
}

TEST(LiveLoop, EmulatedI2cRunConvergesAndLogsEveryRow) {
  // GIVEN emulated sensors with known biases and the flip schedule
  EmuRig rig;
  ASSERT_TRUE(rig.src.configure().ok());
  const fs::path path = temp_file("converge.csv");
  est::DriftlessFilter filter(est::EstimatorConfig{}, est::box_geometry_from_metadata(box_meta()));
  {
    log::LogWriter writer(path, box_meta(), rig.src.fields());
    LiveParams lp;
    lp.duration_s = 120.0;
    LiveLoop loop(lp, rig.clock, &writer, &filter);
    loop.set_motors(&rig.src, &rig.motors, &rig.schedule);
    std::atomic<bool> stop{false};
    // WHEN it runs for 120 s
    const LiveStats st = loop.run(rig.src, nullptr, stop);
    writer.finish(st.complete, st.end_reason);
    EXPECT_TRUE(st.complete);
    EXPECT_EQ(st.samples, 12000u);
    // AND the session's lock was stepped at its updates ('driftless hil' warns from it): locked,
    // and still locked at the end with the filter's own last sigma
    EXPECT_TRUE(st.ever_locked);
    EXPECT_TRUE(st.locked_at_end);
    EXPECT_DOUBLE_EQ(st.sigma_at_end_dps, filter.correction_sigma_dps().maxCoeff());
    EXPECT_LT(st.sigma_at_end_dps, est::HealthLimits{}.lock_sigma_dps);
  }
  // THEN every sample is a row, 10 ms apart, and the estimate is near the emulated biases
  const Result r = read_back(path, {});
  ASSERT_EQ(r.rows.size(), 12000u);
  for (std::size_t i = 1; i < r.rows.size(); ++i) ASSERT_NEAR(r.rows[i].t_s - r.rows[i - 1].t_s, 0.01, 1e-9);
  EXPECT_TRUE(r.meta.complete());
  EXPECT_GE(filter.counters().updates, 8u);
  const auto& truth = EmuRig::params(1).bias_dps;
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(filter.bias1_dps()[i], truth[0][i], 0.02) << "axis " << i;
    EXPECT_NEAR(filter.bias2_dps()[i], truth[1][i], 0.02) << "axis " << i;
  }
  fs::remove(path);
}

// a log of `duration_s` recorded from emulated sensors with flipping platforms, to be replayed
void record_emu_log(const fs::path& path, std::uint64_t seed, double duration_s) {
  EmuRig rig(seed);
  ASSERT_TRUE(rig.src.configure().ok());
  log::LogWriter writer(path, box_meta(), rig.src.fields());
  LiveParams lp;
  lp.duration_s = duration_s;
  LiveLoop loop(lp, rig.clock, &writer, nullptr);
  loop.set_motors(&rig.src, &rig.motors, &rig.schedule);
  std::atomic<bool> stop{false};
  writer.finish(loop.run(rig.src, nullptr, stop).complete);
}

TEST(LiveLoop, SwitchOverKeepsTheEstimatorAndLosesNoSample) {
  // GIVEN a recorded log (the "simulation") and emulated hardware
  const fs::path rec = temp_file("recorded.csv");
  ASSERT_NO_FATAL_FAILURE(record_emu_log(rec, 7, 60.0));
  VirtualClock replay_clock;
  ReplaySource replay(replay_clock, {rec.string(), false, 1.0});
  ASSERT_TRUE(replay.configure().ok());
  EmuRig hw(8);
  ASSERT_TRUE(hw.src.configure().ok());

  // WHEN the loop switches from the replay to the hardware at T = 40 s
  const fs::path path = temp_file("switch.csv");
  est::DriftlessFilter filter(est::EstimatorConfig{}, est::box_geometry_from_metadata(box_meta()));
  Eigen::Matrix<double, 6, 1> before = Eigen::Matrix<double, 6, 1>::Constant(kNaN), after = before;
  std::uint64_t updates_before = 0;
  std::string first_source_of_switch;
  LiveStats st;
  {
    log::LogWriter writer(path, box_meta(), hw.src.fields());
    LiveParams lp;
    lp.duration_s = 80.0;
    lp.switch_at_s = 40.0;
    LiveLoop loop(lp, hw.clock, &writer, &filter);
    loop.set_motors(&hw.src, &hw.motors, &hw.schedule);
    loop.on_sample([&](const Sample& s, SampleSource& src) {
      if (&src == &replay) {
        before = filter.bias_dps();
        updates_before = filter.counters().updates;
      } else if (std::isnan(after[0])) {
        after = filter.bias_dps();
        first_source_of_switch = src.name();
      }
      (void)s;
    });
    std::atomic<bool> stop{false};
    st = loop.run(replay, &hw.src, stop);
    writer.finish(st.complete, st.end_reason);
  }
  const Result r = read_back(path, st);

  // THEN rows run 0 .. 79.99 s every 10 ms: none lost, none duplicated, time monotonic
  ASSERT_EQ(r.rows.size(), 8000u);
  for (std::size_t i = 0; i < r.rows.size(); ++i) ASSERT_NEAR(r.rows[i].t_s, i * 0.01, 1e-6) << i;
  EXPECT_EQ(st.samples_first, 4000u);
  EXPECT_EQ(st.samples_second, 4000u);
  EXPECT_NEAR(st.t_switch_s, 40.0, 1e-9);
  // AND one event line marks the switch, right after the row at 39.99 s
  ASSERT_EQ(events_with(r, "switch:"), 1);
  for (const auto& e : r.events) {
    if (e.text.find("switch:") != std::string::npos) {
      EXPECT_NEAR(e.t_s, 39.99, 1e-6);
    }
  }
  // AND the same filter ran on: it had converged before, kept its estimate across, and went on
  EXPECT_GE(updates_before, 3u);
  EXPECT_EQ(first_source_of_switch, hw.src.name());
  EXPECT_TRUE(before.isApprox(after)) << before.transpose() << "\n" << after.transpose();
  EXPECT_GT(filter.counters().updates, updates_before);
  EXPECT_EQ(filter.counters().source_switches, 1u);
  fs::remove(rec);
  fs::remove(path);
}

std::string fmt_row(double t_s, const Eigen::Vector3d& y1_dps, const Eigen::Vector3d& y2_dps, double p1_deg,
                    double p2_deg) {
  char b[256];
  std::snprintf(b, sizeof b, "%.6f,%.9f,%.9f,%.9f,%.9f,%.9f,%.9f,%.6f,%.6f\n", t_s, y1_dps[0], y1_dps[1], y1_dps[2],
                y2_dps[0], y2_dps[1], y2_dps[2], p1_deg, p2_deg);
  return b;
}

// A log written here, apart from the twin and the emulators: a box at rest on the equator (the Earth
// rate along box y), platforms about z and x resting at +-85 deg and stepping between them every
// 10 s in eq. (5)'s order, noise-free sensors with constant biases; it ends 5 s into its 7th
// standstill. Its metadata states the rest angle and the gyro range.
void write_stepping_log(const fs::path& path, const Eigen::Vector3d& b1, const Eigen::Vector3d& b2) {
  std::ofstream f(path);
  f << "# format: driftless-log 1\n# complete: true\n# sample_rate_hz: 100\n# latitude_deg: 0\n"
       "# hinge1_axis: 0 0 1\n# hinge2_axis: 1 0 0\n# gyro_full_scale_dps: 500\n# flip_angle_deg: 85\n"
       "t,gyro1_x,gyro1_y,gyro1_z,gyro2_x,gyro2_y,gyro2_z,plat1_deg,plat2_deg\n";
  const Eigen::Vector3d w_body_dps(0.0, 7.292115e-5 * 180.0 / M_PI, 0.0);
  const int sides[4][2] = {{1, 1}, {1, -1}, {-1, -1}, {-1, 1}};
  for (int k = 0; k < 6500; ++k) {
    const int* side = sides[(k / 1000) % 4];
    const double a1 = 85.0 * side[0], a2 = 85.0 * side[1];
    const Eigen::Matrix3d R1 = Eigen::AngleAxisd(a1 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Matrix3d R2 = Eigen::AngleAxisd(a2 * M_PI / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
    const Eigen::Vector3d y1 = R1.transpose() * w_body_dps + b1, y2 = R2.transpose() * w_body_dps + b2;
    f << fmt_row(k * 0.01, y1, y2, a1, a2);
  }
}

TEST(LiveLoop, AReplayUsesItsLastStandstillAndKeepsTheRecordingsBoxAndRange) {
  // GIVEN a log that ends at rest and states its rest angle (85 deg) and gyro range (500 deg/s)
  const fs::path rec = temp_file("stepping.csv");
  const Eigen::Vector3d b1(0.5, -0.3, 0.8), b2(-0.6, 0.4, 0.2);
  write_stepping_log(rec, b1, b2);
  VirtualClock clock;
  ReplaySource replay(clock, {rec.string(), false, 1.0});
  ASSERT_TRUE(replay.configure().ok());
  log::Metadata meta;
  replay.describe(meta);
  const fs::path path = temp_file("stepping-session.csv");
  est::DriftlessFilter filter(est::EstimatorConfig{}, est::box_geometry_from_metadata(meta));

  // WHEN it is replayed into a session to its end
  {
    log::LogWriter writer(path, meta, replay.fields());
    LiveLoop loop(LiveParams{}, clock, &writer, &filter);
    std::atomic<bool> stop{false};
    const LiveStats st = loop.run(replay, nullptr, stop);
    writer.finish(st.complete, st.end_reason);
    EXPECT_TRUE(st.complete) << st.end_reason;
    EXPECT_EQ(st.samples, 6500u);
  }

  // THEN all 7 standstills are updates, the last one too (as 'estimate' uses it at the end of a log)
  EXPECT_EQ(filter.counters().updates, 7u);
  EXPECT_EQ(filter.counters().rejected, 0u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(filter.bias1_dps()[i], b1[i], 1e-4) << "axis " << i;
    EXPECT_NEAR(filter.bias2_dps()[i], b2[i], 1e-4) << "axis " << i;
  }
  // AND the session's log and filter keep the recording's rest angle and gyro range
  EXPECT_NEAR(est::box_geometry_from_metadata(meta).flip_angle_deg, 85.0, 0.0);
  const Result r = read_back(path, {});
  EXPECT_EQ(r.meta.get("flip_angle_deg").value_or("(none)"), "85");
  EXPECT_EQ(r.meta.get("gyro_full_scale_dps").value_or("(none)"), "500");
  fs::remove(rec);
  fs::remove(path);
}

TEST(LiveLoop, AMalformedRowInAReplayEndsTheSessionIncompleteAndSaysWhere) {
  // GIVEN a recorded log of 20 s whose row at t = 10 s is damaged (a field that is not a number)
  const fs::path rec = temp_file("damaged.csv");
  ASSERT_NO_FATAL_FAILURE(record_emu_log(rec, 9, 20.0));
  std::string text;
  {
    std::ifstream in(rec);
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::size_t row = text.find("\n10.000000,");
  ASSERT_NE(row, std::string::npos);
  const std::size_t field = text.find(',', row + 1);
  text.replace(field + 1, 1, "x");
  std::ofstream(rec, std::ios::trunc) << text;
  const std::size_t damaged_line = 1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + row + 1, '\n'));

  // WHEN it is replayed into a session
  VirtualClock clock;
  ReplaySource replay(clock, {rec.string(), false, 1.0});
  ASSERT_TRUE(replay.configure().ok());
  LiveParams lp;
  LiveLoop loop(lp, clock, nullptr, nullptr);
  std::vector<std::string> events;
  loop.on_event([&](double, const std::string& e) { events.push_back(e); });
  std::atomic<bool> stop{false};
  const LiveStats st = loop.run(replay, nullptr, stop);

  // THEN the rows before it stand, and the session is incomplete with the file and line as its cause
  EXPECT_EQ(st.samples, 1000u);
  EXPECT_FALSE(st.complete);
  const std::string where = rec.string() + ":" + std::to_string(damaged_line);
  EXPECT_NE(st.end_reason.find("failed"), std::string::npos) << st.end_reason;
  EXPECT_NE(st.end_reason.find(where), std::string::npos) << st.end_reason << " (expected " << where << ")";
  EXPECT_EQ(st.faults, 1u);
  ASSERT_FALSE(events.empty());
  EXPECT_NE(events.back().find(where), std::string::npos) << events.back();
  fs::remove(rec);
}

TEST(LiveLoop, FaultsBecomeEventLinesAndGapsNeverCloseSilently) {
  // GIVEN emulated sensors that suffer NACKs, a FIFO overflow, an unplugged sensor and saturation
  EmuRig rig;
  rig.gen = BoxAtRestGenerator(
      [] {
        BoxAtRestGenerator::Params p;
        p.extra_rate_dps = [](double t) { return Eigen::Vector3d(0, 0, t > 30.0 && t < 30.5 ? 400.0 : 0.0); };
        return p;
      }(),
      &rig.motors);
  ASSERT_TRUE(rig.src.configure().ok());
  const fs::path path = temp_file("faults.csv");
  LiveStats st;
  {
    log::LogWriter writer(path, box_meta(), rig.src.fields());
    LiveParams lp;
    lp.duration_s = 60.0;
    LiveLoop loop(lp, rig.clock, &writer, nullptr);
    loop.set_motors(&rig.src, &rig.motors, &rig.schedule);
    const double t0 = rig.clock.now_s();
    loop.on_sample([&, done = std::array<bool, 3>{}](const Sample& s, SampleSource&) mutable {
      if (s.t_s > 10.0 && !done[0]) {
        rig.bus.fail_next(0x68, 2, I2cResult::kNack);
        done[0] = true;
      }
      if (s.t_s > 20.0 && !done[1]) {
        rig.clock.advance(1.5);  // the host stalls: the FIFO overflows
        done[1] = true;
      }
      if (s.t_s > 40.0 && !done[2]) {
        const double now = rig.clock.now_s();
        rig.bus.unplug(0x69, now, now + 2.0);
        done[2] = true;
      }
    });
    (void)t0;
    std::atomic<bool> stop{false};
    st = loop.run(rig.src, nullptr, stop);
    writer.finish(st.complete, st.end_reason);
  }
  const Result r = read_back(path, st);
  // THEN each fault has its event line
  // 2 NACKs, then 5 failed transactions before the unplugged sensor counts as gone
  EXPECT_EQ(events_with(r, "bus-error"), 2 + 5);
  EXPECT_EQ(events_with(r, "fifo-overflow"), 2);  // the stall, and the restart after reconnecting
  EXPECT_EQ(events_with(r, "disconnected"), 1);
  EXPECT_EQ(events_with(r, "reconnected"), 1);
  EXPECT_EQ(events_with(r, "saturation"), 4);
  EXPECT_GE(events_with(r, "gap:"), 2);
  // AND every jump in time is reported as lost samples, no more and no fewer
  std::uint64_t skipped = 0;
  for (std::size_t i = 1; i < r.rows.size(); ++i) {
    const double dt = r.rows[i].t_s - r.rows[i - 1].t_s;
    ASSERT_GT(dt, 0.0);
    skipped += static_cast<std::uint64_t>(std::llround(dt / 0.01)) - 1;
  }
  EXPECT_EQ(skipped, st.lost_samples);
  EXPECT_EQ(r.rows.size() + skipped, 6000u);
  EXPECT_TRUE(st.complete);
  fs::remove(path);
}

TEST(LiveLoop, DeviceGoneForGoodLeavesAnIncompleteButValidLog) {
  EmuRig rig;
  ASSERT_TRUE(rig.src.configure().ok());
  const fs::path path = temp_file("gone.csv");
  LiveStats st;
  {
    log::LogWriter writer(path, box_meta(), rig.src.fields());
    LiveParams lp;
    lp.duration_s = 60.0;
    lp.give_up_after_s = 3.0;
    LiveLoop loop(lp, rig.clock, &writer, nullptr);
    loop.on_sample([&, done = false](const Sample& s, SampleSource&) mutable {
      if (s.t_s > 5.0 && !done) {
        rig.bus.unplug_adapter(rig.clock.now_s(), 1e9);
        done = true;
      }
    });
    std::atomic<bool> stop{false};
    st = loop.run(rig.src, nullptr, stop);
    writer.finish(st.complete, st.end_reason);
  }
  EXPECT_FALSE(st.complete);
  EXPECT_NE(st.end_reason.find("lost"), std::string::npos);
  const Result r = read_back(path, st);
  EXPECT_FALSE(r.meta.complete());
  EXPECT_NEAR(static_cast<double>(r.rows.size()), 500.0, 2.0);
  EXPECT_EQ(events_with(r, "gave up"), 1);
  fs::remove(path);
}

TEST(LiveLoop, SerialLinkGoneForGoodLeavesAnIncompleteButValidLog) {
  // GIVEN the emulated microcontroller on a pty whose tty vanishes for good 1 s into the run
  FirmwareParams fp;
  fp.link_path = temp_file("gone.tty").string();
  fp.rate_hz = 100.0;
  fp.faults.hangup_from_s = 1.0;
  fp.faults.hangup_to_s = 1e9;
  FirmwareEmulator emu(fp);
  ASSERT_EQ(emu.start(), "");
  SteadyClock clock;
  SerialSourceParams sp;
  sp.path = fp.link_path;
  SerialSource src(clock, sp);
  ASSERT_TRUE(src.configure().ok());
  const fs::path path = temp_file("serial-gone.csv");
  LiveStats st;
  // WHEN the live loop records it and gives up after 1 s of failed reconnects
  {
    log::LogWriter writer(path, box_meta(), src.fields());
    LiveParams lp;
    lp.duration_s = 30.0;
    lp.give_up_after_s = 1.0;
    LiveLoop loop(lp, clock, &writer, nullptr);
    std::atomic<bool> stop{false};
    st = loop.run(src, nullptr, stop);
    writer.finish(st.complete, st.end_reason);
  }
  emu.stop();
  // THEN the run is not complete, says why, and the log holds every row before the hang-up
  EXPECT_FALSE(st.complete);
  EXPECT_NE(st.end_reason.find("lost"), std::string::npos) << st.end_reason;
  const Result r = read_back(path, st);
  EXPECT_FALSE(r.meta.complete());
  // t = 0.00 .. 0.99 s were sent; a frame still in the pty when it closed is gone with it (the
  // kernel drops it), so allow a few at the end, but no gap and nothing invented before that
  EXPECT_LE(r.rows.size(), 100u);
  EXPECT_GE(r.rows.size(), 90u);
  for (std::size_t i = 0; i < r.rows.size(); ++i) EXPECT_NEAR(r.rows[i].t_s, 0.01 * static_cast<double>(i), 1e-9);
  EXPECT_GE(events_with(r, "disconnected"), 1);
  EXPECT_EQ(events_with(r, "gave up"), 1);
  fs::remove(path);
}

}  // namespace
}  // namespace driftless::hil
