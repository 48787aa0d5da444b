// Fault detection on the live stream (docs/hil.md "Fault detection", docs/fdi.md): GIVEN two
// emulated MPU-6050s on the emulated I2C bus, a box at rest flipped by the emulated motors and a
// fault planted into one chip's readings, WHEN the live loop runs the filter with the FDI beside
// it, THEN the fault is isolated to the planted sensor, axis and kind within the delays docs/fdi.md
// states, it becomes an event line in the log, and a fault-free run raises no alarm.
#include <atomic>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/filter.hpp"
#include "estimator/log.hpp"
#include "hil_bridge/fdi_watch.hpp"
#include "hil_bridge/i2c/emulated_bus.hpp"
#include "hil_bridge/i2c/i2c_source.hpp"
#include "hil_bridge/live_loop.hpp"
#include "hil_bridge/planted_fault.hpp"

namespace driftless::hil {
namespace {

// the emulated box of docs/hil.md (biases, 0.005 deg/s/sqrt(Hz)), its readings through `fault`
struct FaultyRig {
  VirtualClock clock;
  EmulatedMotors motors;
  FaultyGenerator gen;
  Mpu6050Emulator chip1{0, gen, clock}, chip2{1, gen, clock};
  EmulatedI2cBus bus{clock, &clock};
  I2cSource src;
  FlipSchedule schedule{{10.0, 10.0}};
  explicit FaultyRig(const PlantedFault& fault, EmulatedMotors::Params mp = {})
      : motors(clock, mp),
        gen(std::make_unique<BoxAtRestGenerator>(BoxAtRestGenerator::Params{}, &motors), fault),
        src(bus, clock, I2cSourceParams{}) {
    bus.attach(0x68, &chip1);
    bus.attach(0x69, &chip2);
  }
};

// s: at most the emulated chips' clock at the log's t = 0 (reset and configuration on the virtual
// clock: 0.22 s); a planted onset T (emulator time) is at about T - 0.22 s in the log
constexpr double kStartup = 0.25;

struct LiveRun {
  std::vector<std::string> events;  // "fdi: ..." lines as the loop emitted them
  FdiVerdict verdict = FdiVerdict::kNotMonitored;
  std::optional<est::FaultReport> fault;
  std::optional<double> first_alarm_s;
  Eigen::Vector3d sigma_longrun_dps = Eigen::Vector3d::Constant(kNaN);  // learned, deg/s
};

LiveRun run_with_fdi(const PlantedFault& fault, double duration_s, EmulatedMotors::Params mp = {},
                     double end_margin_s = 0.1) {
  FaultyRig rig(fault, mp);
  EXPECT_TRUE(rig.src.configure().ok());
  log::Metadata meta;
  meta.set("sample_rate_hz", "100");
  meta.set("latitude_deg", "52.0");
  est::DriftlessFilter filter(est::EstimatorConfig{}, est::box_geometry_from_metadata(meta));
  FdiWatch watch(est::FdiParams{}, end_margin_s);
  LiveParams lp;
  lp.duration_s = duration_s;
  LiveLoop loop(lp, rig.clock, nullptr, &filter);
  loop.set_motors(&rig.src, &rig.motors, &rig.schedule);
  loop.set_fdi(&watch);
  LiveRun r;
  loop.on_event([&](double, const std::string& text) {
    if (text.rfind("fdi:", 0) == 0) r.events.push_back(text);
  });
  std::atomic<bool> stop{false};
  const LiveStats st = loop.run(rig.src, nullptr, stop);
  EXPECT_TRUE(st.complete) << st.end_reason;
  r.verdict = watch.verdict();
  r.fault = watch.detector().fault();
  r.first_alarm_s = watch.detector().first_alarm_s();
  r.sigma_longrun_dps = watch.detector().residual_sigma_longrun_dps();
  return r;
}

int count_with(const std::vector<std::string>& lines, const std::string& word) {
  int n = 0;
  for (const auto& l : lines) n += l.find(word) != std::string::npos;
  return n;
}

TEST(PlantedFault, ParsesBothKindsAndNamesWhatIsWrong) {
  const PlantedFault s = parse_planted_fault("stuck:2:y@60");
  EXPECT_EQ(s.kind, PlantedFault::Kind::kStuck);
  EXPECT_EQ(s.sensor, 2);
  EXPECT_EQ(s.axis, 1);
  EXPECT_EQ(s.t_s, 60.0);
  const PlantedFault b = parse_planted_fault("bias:1:z:-0.5@12.5");
  EXPECT_EQ(b.kind, PlantedFault::Kind::kBias);
  EXPECT_EQ(b.axis, 2);
  EXPECT_EQ(b.bias_dps, -0.5);
  EXPECT_EQ(b.t_s, 12.5);
  EXPECT_EQ(b.describe(), "bias -0.5 deg/s on sensor 1 axis z from t=12.5 s");
  for (const char* bad : {"stuck:3:y@1", "stuck:1:w@1", "bias:1:x@1", "stuck:1:x", "stuck:1:x@-1", "bias:1:x:a@1",
                          "drift:1:x@1"}) {
    try {
      parse_planted_fault(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("expected stuck:S:A@T"), std::string::npos) << e.what();
    }
  }
}

// a generator whose readings are a known ramp: what the wrapper changes is visible exactly
struct RampGenerator final : ImuGenerator {
  ImuReading sample(int sensor, double t_s) override {
    ImuReading r;
    r.gyro_dps = Eigen::Vector3d(t_s, 2 * t_s, 3 * t_s) + Eigen::Vector3d::Constant(sensor);
    return r;
  }
};

TEST(PlantedFault, StuckHoldsTheLastValueBeforeTheOnsetAndBiasAdds) {
  FaultyGenerator stuck(std::make_unique<RampGenerator>(), parse_planted_fault("stuck:2:y@1"));
  stuck.sample(1, 0.99);
  EXPECT_EQ(stuck.sample(1, 0.99).gyro_dps.y(), 2 * 0.99 + 1);  // sensor 2 before the onset
  EXPECT_EQ(stuck.sample(1, 1.5).gyro_dps.y(), 2 * 0.99 + 1);   // held, bit for bit
  EXPECT_EQ(stuck.sample(1, 1.5).gyro_dps.x(), 1.5 + 1);        // other axes untouched
  EXPECT_EQ(stuck.sample(0, 1.5).gyro_dps.y(), 3.0);            // sensor 1 untouched
  FaultyGenerator bias(std::make_unique<RampGenerator>(), parse_planted_fault("bias:1:x:0.5@1"));
  EXPECT_EQ(bias.sample(0, 0.5).gyro_dps.x(), 0.5);
  EXPECT_EQ(bias.sample(0, 2.0).gyro_dps.x(), 2.5);
  EXPECT_EQ(bias.sample(0, 2.0).true_bias_dps.x(), 0.5);
}

TEST(LiveFdi, FaultFreeEmulatedRunRaisesNoAlarm) {
  const LiveRun r = run_with_fdi(PlantedFault{}, 90.0);
  EXPECT_EQ(r.verdict, FdiVerdict::kHealthy);
  EXPECT_FALSE(r.first_alarm_s.has_value());
  EXPECT_EQ(count_with(r.events, "fdi: monitoring from"), 1);
  EXPECT_EQ(r.events.size(), 1u);
}

TEST(LiveFdi, SwitchesThatOpenLateDoNotInflateTheLearnedNoise) {
  // GIVEN end-stop switches that stay closed for the first 3 deg of a flip (the first samples of
  // a move carry the hinge rate while the angle still reads the stop, as on the serial link)
  EmulatedMotors::Params late;
  late.switch_window_deg = 3.0;
  // WHEN the watch holds rest samples for the filter's end margin (0.1 s)
  const LiveRun r = run_with_fdi(PlantedFault{}, 90.0, late);
  // THEN it learns the white-noise level on every axis (0.005 deg/s/sqrt(Hz): ~0.07 deg/s long
  // run) and raises no alarm
  EXPECT_EQ(r.verdict, FdiVerdict::kHealthy);
  EXPECT_LT(r.sigma_longrun_dps.maxCoeff(), 0.1) << r.sigma_longrun_dps.transpose();
  // AND without the margin the moving samples stay out of the learning (the hinge rate makes them
  // not quiet: the noise is learned from quiet rest samples after the filter locked), but the
  // monitoring sees them: an alarm that is not a sensor's
  const LiveRun raw = run_with_fdi(PlantedFault{}, 90.0, late, 0.0);
  EXPECT_LT(raw.sigma_longrun_dps.maxCoeff(), 0.1) << raw.sigma_longrun_dps.transpose();
  EXPECT_TRUE(raw.first_alarm_s.has_value());
  EXPECT_NE(raw.verdict, FdiVerdict::kFault);
}

TEST(LiveFdi, StuckAxisIsIsolatedAtOnceAndLogged) {
  const LiveRun r = run_with_fdi(parse_planted_fault("stuck:2:y@45"), 60.0);
  ASSERT_EQ(r.verdict, FdiVerdict::kFault);
  ASSERT_TRUE(r.fault);
  EXPECT_EQ(r.fault->kind, est::FaultKind::kStuck);
  EXPECT_EQ(r.fault->sensor, 2);
  EXPECT_EQ(r.fault->axis, 1);
  // docs/fdi.md: alarm after stuck_s = 0.3 s (<= 0.5 s), isolated in the same sample
  EXPECT_GE(r.fault->t_alarm_s, 45.0 - kStartup + 0.3);
  EXPECT_LE(r.fault->t_alarm_s, 45.5);
  EXPECT_EQ(r.fault->t_isolated_s, r.fault->t_alarm_s);
  EXPECT_EQ(count_with(r.events, "fdi: fault isolated: stuck on sensor 2 axis y"), 1);
}

TEST(LiveFdi, BiasStepIsIsolatedWithinTwoFlips) {
  // (planted at 80 s: the detector learns the noise once the filter has locked, ~36 s, from 20 s of
  // quiet rest samples: monitoring from ~62 s)
  const LiveRun r = run_with_fdi(parse_planted_fault("bias:1:x:0.5@80"), 145.0);
  ASSERT_EQ(r.verdict, FdiVerdict::kFault);
  ASSERT_TRUE(r.fault);
  EXPECT_EQ(r.fault->kind, est::FaultKind::kBiasStep);
  EXPECT_EQ(r.fault->sensor, 1);
  EXPECT_EQ(r.fault->axis, 0);
  EXPECT_NEAR(r.fault->magnitude, 0.5, 0.1);  // deg/s
  // docs/fdi.md: alarm < 0.1 s at rest (up to the next rest sample if the step comes mid-flip),
  // isolation within two flips (<= 50 s with 20 s standstills; here 10 s). The onset is on the
  // emulator's clock, which runs kStartup ahead of the log's time (the chips' start-up)
  ASSERT_TRUE(r.first_alarm_s);
  EXPECT_GE(*r.first_alarm_s, 80.0 - kStartup);
  EXPECT_LE(*r.first_alarm_s, 80.0 + 3.0);
  EXPECT_LE(r.fault->t_isolated_s - 80.0, 50.0);
  EXPECT_EQ(count_with(r.events, "fdi: alarm at"), 1);
  EXPECT_EQ(count_with(r.events, "fdi: fault isolated: bias_step on sensor 1 axis x"), 1);
}

}  // namespace
}  // namespace driftless::hil
