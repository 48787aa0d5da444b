// One pass over a log: filter + attitude with/without correction + truth statistics.
#include <cmath>
#include <memory>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "estimator/pipeline.hpp"
#include "tests/estimator/synth.hpp"
#include "tests/temp_path.hpp"

namespace driftless::est {
namespace {

std::filesystem::path temp_path(const std::string& name) {
  auto dir = test::temp_path("driftless_test_pipeline");
  std::filesystem::create_directories(dir);
  return dir / name;
}

// The synthetic log of `p`, estimated twice: with its platform-angle columns (the default
// standstill source) and with 'standstill: gyro' (the angles not used).
std::pair<EstimateSummary, EstimateSummary> with_angles_and_gyro_only(const test::SynthParams& p, const std::string& name) {
  const auto path = temp_path(name);
  test::synth_log(p, path);
  EstimatorConfig gyro;
  gyro.standstill = StandstillSource::kGyroSignal;
  log::LogReader r1(path), r2(path);
  return {run_estimate(r1, EstimatorConfig{}, nullptr), run_estimate(r2, gyro, nullptr)};
}

TEST(PipelineTest, CorrectionCutsAttitudeDriftOnAPanTiltRun) {
  // GIVEN a 10-minute pan/tilt-like run with MPU6050-size biases and noise
  test::SynthParams p;
  p.duration_s = 600.0;
  p.noise_sigma_dps = 0.05;
  p.body_rate_dps = [](double t) {
    return Eigen::Vector3d(3.0 * std::sin(0.05 * t), 2.0 * std::sin(0.031 * t + 1.0), 5.0 * std::cos(0.02 * t));
  };
  const auto path = temp_path("pan_tilt.csv");
  test::synth_log(p, path);
  // WHEN estimate runs over it
  log::LogReader reader(path);
  const auto s = run_estimate(reader, EstimatorConfig{}, nullptr);
  // THEN the attitude drift falls by more than 20x
  EXPECT_EQ(s.rows, 60000u);
  ASSERT_TRUE(s.attitude_available);
  EXPECT_GT(s.drift_raw_deg_per_h, 100.0);  // flipping already averages part of the bias out
  EXPECT_LT(s.drift_corrected_deg_per_h, 0.05 * s.drift_raw_deg_per_h);
  ASSERT_TRUE(s.truth.available);
  EXPECT_GT(s.truth.updates, 40u);
  EXPECT_LT(s.truth.bias_error_rms_second_half_dps, 0.01);
  EXPECT_GT(s.truth.within_3sigma_fraction, 0.95);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
}

TEST(PipelineTest, AGyroThatClipsFailsTheRunAndIsNamedFirst) {
  // GIVEN a box that spins about z up to 600 deg/s, read by a sensor 1 of range +-250 deg/s, in a
  // log that states no gyro_full_scale_dps (as most logs from elsewhere)
  test::SynthParams p;
  p.duration_s = 300.0;
  p.noise_sigma_dps = 0.05;
  p.body_rate_dps = [](double t) { return Eigen::Vector3d(0.0, 0.0, 600.0 * std::sin(0.05 * t)); };
  const auto clean_path = temp_path("spin.csv");
  test::synth_log(p, clean_path);
  p.before_quantise = [](Sample& s) { s.gyro1_dps = s.gyro1_dps.cwiseMax(-250.0).cwiseMin(250.0); };
  const auto clipped_path = temp_path("spin_clipped.csv");
  test::synth_log(p, clipped_path);
  // WHEN estimate runs over each
  log::LogReader clean_reader(clean_path), clipped_reader(clipped_path);
  const auto clean = run_estimate(clean_reader, EstimatorConfig{}, nullptr);
  const auto clipped = run_estimate(clipped_reader, EstimatorConfig{}, nullptr);
  // THEN the clipped log fails, its first finding names a sensor-1 channel at 250 deg/s
  EXPECT_EQ(clipped.health.verdict, HealthVerdict::kFailed);
  ASSERT_FALSE(clipped.health.findings.empty());
  const HealthFinding& f = clipped.health.findings.front();
  EXPECT_EQ(f.cause, HealthCause::kSaturation);
  ASSERT_EQ(f.components.size(), 1u);
  EXPECT_LT(f.components[0], 3);
  EXPECT_NEAR(f.suggested, 250.0, 0.01);
  EXPECT_GT(f.value, 0.01);
  // AND the same spin within range has no saturation finding
  for (const HealthFinding& g : clean.health.findings) EXPECT_NE(g.cause, HealthCause::kSaturation);
}

TEST(PipelineTest, AttitudeFromGyroOnlyStandstillsMatchesTheOneFromTheAngles) {
  // GIVEN a turning box with a reference attitude, estimated once with the platform angles and
  // once with 'standstill: gyro' (the angles unused): during each flip the resting sensor alone
  // gives the box rate, and the flipped platform's new position is its integrated turn
  test::SynthParams p;
  p.duration_s = 300.0;
  p.noise_sigma_dps = 0.05;
  p.body_rate_dps = [](double t) {
    return Eigen::Vector3d(20.0 * std::sin(0.3 * t), 10.0 * std::cos(0.13 * t), 30.0 * std::sin(0.05 * t));
  };
  const auto [with_angles, gyro_only] = with_angles_and_gyro_only(p, "gyro_standstill.csv");
  // THEN both compare the attitude from the same start, the final errors agree within 0.02 deg
  // (the two runs' bias estimates differ by their noise) and the drifts within 0.5 deg/h
  ASSERT_TRUE(gyro_only.attitude_available);
  EXPECT_EQ(gyro_only.counters.updates, with_angles.counters.updates);
  EXPECT_NEAR(gyro_only.attitude_start_s, with_angles.attitude_start_s, 0.02);
  EXPECT_NEAR(gyro_only.final_corrected.angle_deg, with_angles.final_corrected.angle_deg, 0.02);
  EXPECT_NEAR(gyro_only.drift_corrected_deg_per_h, with_angles.drift_corrected_deg_per_h, 0.5);
  EXPECT_LT(gyro_only.drift_corrected_deg_per_h, 0.05 * gyro_only.drift_raw_deg_per_h);
  // AND no flip was taken for a simultaneous one, nothing withheld, no warning
  EXPECT_EQ(gyro_only.counters.simultaneous_flips, 0u);
  EXPECT_TRUE(std::isnan(gyro_only.attitude_withheld_from_s));
  EXPECT_TRUE(gyro_only.warnings.empty()) << gyro_only.warnings.front();
}

TEST(PipelineTest, GyroOnlyAttitudeIsWithheldFromAFlipOfBothPlatformsAtOnce) {
  // GIVEN a turning box whose platforms flip one at a time, except once, at t = 175 s, together
  test::SynthParams p;
  p.duration_s = 300.0;
  p.noise_sigma_dps = 0.05;
  p.both_at_cycle = 15;  // cycles of 10 s at rest + 1 s flip: that flip starts at 15 * 11 + 10 s
  p.body_rate_dps = [](double t) { return Eigen::Vector3d(5.0 * std::sin(0.3 * t), 3.0, -4.0 * std::cos(0.1 * t)); };
  const auto [with_angles, gyro_only] = with_angles_and_gyro_only(p, "both_at_once.csv");
  // THEN with 'standstill: gyro' the comparison starts, stops at that flip, and its figures are
  // withheld (NaN) with a degraded verdict whose finding says when and why
  ASSERT_TRUE(std::isfinite(gyro_only.attitude_start_s));
  EXPECT_EQ(gyro_only.counters.simultaneous_flips, 1u);
  EXPECT_NEAR(gyro_only.attitude_withheld_from_s, 175.0, 0.1);
  EXPECT_TRUE(std::isnan(gyro_only.drift_corrected_deg_per_h));
  EXPECT_TRUE(std::isnan(gyro_only.final_corrected.angle_deg));
  EXPECT_EQ(gyro_only.health.verdict, HealthVerdict::kDegraded);
  bool named = false;
  for (const HealthFinding& f : gyro_only.health.findings) {
    named |= f.cause == HealthCause::kAttitudeWithheld && std::fabs(f.value - 175.0) < 0.1 && f.suggested == 1.0;
  }
  EXPECT_TRUE(named);
  // AND the platforms' positions after it are right: every update accepted, as with the angles
  EXPECT_EQ(gyro_only.counters.rejected, 0u);
  EXPECT_EQ(gyro_only.counters.updates, with_angles.counters.updates);
  // AND with the angle columns nothing is withheld
  EXPECT_TRUE(std::isnan(with_angles.attitude_withheld_from_s));
  EXPECT_TRUE(std::isfinite(with_angles.drift_corrected_deg_per_h));
}

TEST(PipelineTest, ComparisonStartsWhenLockedAndAFixedBiasThenDoesNotDrift) {
  // GIVEN a noise-free moving run with constant biases (the estimate is exact once locked)
  test::SynthParams p;
  p.duration_s = 300.0;
  p.body_rate_dps = [](double t) { return Eigen::Vector3d(2.0 * std::sin(0.1 * t), 1.0, -3.0 * std::cos(0.07 * t)); };
  const auto path = temp_path("constant_bias.csv");
  test::synth_log(p, path);
  log::LogReader reader(path);
  const auto s = run_estimate(reader, EstimatorConfig{}, nullptr);
  // THEN the comparison starts after the first standstills, not at t = 0,
  ASSERT_TRUE(std::isfinite(s.attitude_start_s));
  EXPECT_GT(s.attitude_start_s, p.standstill_s);
  EXPECT_LT(s.attitude_start_s, 5.0 * (p.standstill_s + p.flip_s));
  // the bias it fixed there is the truth, and neither corrected integration drifts (closed form:
  // zero; 0.1 deg/h allows for the integrator's discretisation of the varying rate), the two
  // agree with each other, while the uncorrected one drifts at about |b| (~1.5 deg/s = 5400 deg/h)
  Vector6d truth;
  truth << p.b1_dps, p.b2_dps;
  EXPECT_LT((s.fixed_bias_dps - truth).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT(std::fabs(s.drift_corrected_deg_per_h), 0.1);
  EXPECT_LT(std::fabs(s.drift_fixed_deg_per_h), 0.1);
  EXPECT_NEAR(s.drift_fixed_deg_per_h, s.drift_corrected_deg_per_h, 1e-3);
  EXPECT_GT(s.drift_raw_deg_per_h, 1000.0);
}

TEST(PipelineTest, AWanderingBiasMakesTheFixedBiasDriftButNotDriftLess) {
  // GIVEN a static box whose biases wander (Gauss-Markov, 0.05 deg/s over 300 s) with noise
  test::SynthParams p;
  p.duration_s = 1800.0;
  p.noise_sigma_dps = 0.05;
  p.gm_sigma_dps = 0.05;
  p.gm_tau_s = 300.0;
  p.seed = 7;
  const auto path = temp_path("wander.csv");
  test::synth_log(p, path);
  log::LogReader reader(path);
  EstimatorConfig cfg;
  cfg.bias_instability_dps = 0.05;
  cfg.bias_instability_tau_s = 300.0;
  const auto s = run_estimate(reader, cfg, nullptr);
  // THEN a bias calibrated once drifts several times faster than the running DriftLess estimate
  ASSERT_TRUE(std::isfinite(s.drift_fixed_deg_per_h));
  EXPECT_GT(s.drift_fixed_deg_per_h, 3.0 * s.drift_corrected_deg_per_h)
      << "fixed " << s.drift_fixed_deg_per_h << " DriftLess " << s.drift_corrected_deg_per_h;
}

TEST(PipelineTest, AFilterThatNeverLocksGivesNoComparisonAndSaysWhy) {
  // GIVEN a run where platform 2 never flips: one bias component stays unobservable
  test::SynthParams p;
  p.duration_s = 200.0;
  p.hold_platform2 = true;
  const auto path = temp_path("no_lock.csv");
  test::synth_log(p, path);
  {
    log::LogReader reader(path);
    const auto s = run_estimate(reader, EstimatorConfig{}, nullptr);
    EXPECT_TRUE(std::isnan(s.attitude_start_s));
    EXPECT_TRUE(std::isnan(s.drift_corrected_deg_per_h));
    bool said = false;
    for (const auto& w : s.warnings) said = said || w.find("never locked") != std::string::npos;
    EXPECT_TRUE(said);
  }
  // AND a start sigma of 0 compares from the log's first sample
  log::LogReader reader(path);
  EstimateRunOptions opt;
  opt.attitude_start_sigma_dps = 0.0;
  const auto s = run_estimate(reader, EstimatorConfig{}, nullptr, opt);
  EXPECT_DOUBLE_EQ(s.attitude_start_s, 0.0);
  EXPECT_TRUE(std::isfinite(s.drift_corrected_deg_per_h));
}

// a pull source over samples held in memory (what a simulator or the sweep's box gives)
SampleSource source_of(const std::vector<Sample>& v) {
  auto i = std::make_shared<std::size_t>(0);
  return [&v, i](Sample& s) {
    if (*i >= v.size()) return false;
    s = v[(*i)++];
    return true;
  };
}

struct RealignSink : EstimateSink {
  std::vector<AttitudePoint> realigned;
  std::size_t points = 0;
  void on_attitude(const AttitudePoint& p) override {
    ++points;
    if (p.realigned) realigned.push_back(p);
  }
};

TEST(PipelineTest, AStreamGivesTheSamePassAsItsLog) {
  // GIVEN a noisy moving run, once as a log file and once as a stream of samples
  test::SynthParams p;
  p.duration_s = 200.0;
  p.noise_sigma_dps = 0.05;
  p.body_rate_dps = [](double t) { return Eigen::Vector3d(2.0 * std::sin(0.1 * t), 1.0, -3.0 * std::cos(0.07 * t)); };
  const auto path = temp_path("stream.csv");
  test::synth_log(p, path);
  std::vector<Sample> samples;
  {
    log::LogReader first(path);
    for (Sample s; first.next(s);) samples.push_back(s);
  }
  // WHEN both run through the estimate pass
  log::LogReader reader(path);
  const auto from_log = run_estimate(reader, EstimatorConfig{}, nullptr);
  const auto from_stream = run_estimate(reader.metadata(), reader.fields(), source_of(samples), EstimatorConfig{}, nullptr);
  // THEN every result is the same
  EXPECT_EQ(from_stream.rows, from_log.rows);
  EXPECT_EQ(from_stream.counters.updates, from_log.counters.updates);
  EXPECT_EQ(from_stream.bias_dps, from_log.bias_dps);
  EXPECT_EQ(from_stream.truth.nees_mean, from_log.truth.nees_mean);
  EXPECT_EQ(from_stream.drift_corrected_deg_per_h, from_log.drift_corrected_deg_per_h);
  EXPECT_EQ(from_stream.warnings, from_log.warnings);
  EXPECT_FALSE(from_log.window.available);  // no window asked for
}

TEST(PipelineTest, AnEvaluationWindowScoresEverySampleInItAndReAlignsTheAttitude) {
  // GIVEN a noise-free run turning at a constant rate with constant biases (the estimate is
  // exact once locked, the truth attitude has no discretisation error), a window from 150 s of a
  // 300 s run, the fixed bias taken from the truth, re-alignment on
  test::SynthParams p;
  p.duration_s = 300.0;
  p.body_rate_dps = [](double) { return Eigen::Vector3d(1.0, -0.5, 2.0); };
  const std::vector<Sample> samples = test::synth_all(p);
  EstimateRunOptions opt;
  opt.attitude_start_sigma_dps = 0.0;
  opt.fixed_bias_from = FixedBiasFrom::kTruth;
  opt.eval_start_s = 150.0;
  opt.realign_at_eval_start = true;
  RealignSink sink;
  const std::uint32_t fields = kFieldRefQ | kFieldTrueBias;
  // WHEN the pass runs over the stream
  const auto s = run_estimate(test::synth_metadata(p), fields, source_of(samples), EstimatorConfig{}, &sink, opt);
  // THEN the window holds every sample from 150 s (100 Hz: 15000 of them, +-1 for the float
  // time base) and, the estimate being exact after lock, errors at rounding level
  ASSERT_TRUE(s.window.available);
  EXPECT_NEAR(double(s.window.samples), 15000.0, 1.0);
  EXPECT_LT(s.window.bias_error_max_dps, 1e-6);
  EXPECT_LE(s.window.bias_error_rms_dps, s.window.bias_error_max_dps);
  EXPECT_GT(s.window.nis_updates, 10u);
  // the comparison started at the first sample holding the truth, re-aligned once at 150 s
  EXPECT_DOUBLE_EQ(s.attitude_start_s, 0.0);
  Vector6d truth;
  truth << p.b1_dps, p.b2_dps;
  EXPECT_EQ(s.fixed_bias_dps, truth);
  ASSERT_EQ(sink.realigned.size(), 1u);
  EXPECT_NEAR(sink.realigned[0].t_s, 150.0, 0.011);
  EXPECT_EQ(sink.realigned[0].corrected.angle_deg, 0.0);
  EXPECT_EQ(s.attitude_realign_s, sink.realigned[0].t_s);
  // net drift over the window: zero in closed form with the true bias held and with DriftLess
  // (0.01 deg/h for rounding); the uncorrected gyros drift (flipping averages part of |b| out)
  EXPECT_LT(s.drift_net_fixed_deg_per_h, 0.01);
  EXPECT_LT(s.drift_net_corrected_deg_per_h, 0.01);
  EXPECT_GT(s.drift_net_raw_deg_per_h, 100.0);
  // AND a window past the end scores nothing and has no net drift (the re-alignment never came)
  opt.eval_start_s = 400.0;
  const auto late = run_estimate(test::synth_metadata(p), fields, source_of(samples), EstimatorConfig{}, nullptr, opt);
  EXPECT_FALSE(late.window.available);
  EXPECT_TRUE(std::isnan(late.drift_net_corrected_deg_per_h));
  EXPECT_TRUE(std::isnan(late.attitude_realign_s));
}

// the lock flag of every row and of every update
struct LockSink : EstimateSink {
  struct Row {
    double t_s;
    PushStatus status;
    bool locked;
  };
  std::vector<Row> rows;
  std::vector<std::pair<double, bool>> updates;  // (update time, locked after it)
  void on_sample(const Sample& s, const SampleOutput& o, bool locked) override { rows.push_back({s.t_s, o.status, locked}); }
  void on_update(const UpdateRecord& r, const Matrix6d&, const Sample&, bool locked) override {
    updates.emplace_back(r.t_s, locked);
  }
};

TEST(PipelineTest, TheLockFlagStartsAtTheLockingUpdateAndDropsAtAReLock) {
  // GIVEN a noisy flip log with a 1 deg/s step on gyro 1 x at t = 250 s and a filter that expects
  // a steady bias (so the gate rejects the step, then re-locks with a widened P)
  test::SynthParams p;
  p.duration_s = 400.0;
  p.noise_sigma_dps = 0.05;
  p.before_quantise = [](Sample& s) {
    if (s.t_s > 250.0) s.gyro1_dps.x() += 1.0;
  };
  const auto path = temp_path("lock_flag.csv");
  test::synth_log(p, path);
  EstimatorConfig cfg;
  cfg.q_override_dps2_per_s = 1e-14;
  LockSink sink;
  log::LogReader reader(path);
  const auto s = run_estimate(reader, cfg, &sink);
  // THEN no row is locked before the row that made the locking update; from there on every row is
  // until the re-lock, which unlocks until the filter locks again; the counts agree
  ASSERT_TRUE(std::isfinite(s.locked_from_t_s));
  ASSERT_EQ(s.relocks.size(), 1u);
  const RelockEvent& rl = s.relocks[0];
  ASSERT_TRUE(std::isfinite(rl.locked_again_t_s));
  EXPECT_GT(rl.locked_again_t_s, rl.t_s + 5.0);  // at least one more standstill is needed
  // the unlocked rows after the first lock: one run, from the row that made the re-lock update
  // (just after its last standstill sample rl.t_s) to the row before locked_again_t_s
  std::uint64_t locked_rows = 0;
  double first_locked = kNaN, gap_start = kNaN, gap_end = kNaN;
  int gaps = 0;
  bool prev = false;
  for (const auto& r : sink.rows) {
    locked_rows += r.locked ? 1 : 0;
    if (r.locked && std::isnan(first_locked)) {
      first_locked = r.t_s;
      EXPECT_EQ(r.status, PushStatus::kUpdated);  // the row whose push made the update
    }
    if (!std::isnan(first_locked) && prev != r.locked) {
      if (!r.locked) {
        ++gaps;
        gap_start = r.t_s;
        EXPECT_EQ(r.status, PushStatus::kUpdated);  // the re-lock update is taken
      } else if (gaps > 0) {
        gap_end = r.t_s;
        EXPECT_EQ(r.status, PushStatus::kUpdated);
      }
    }
    prev = r.locked;
  }
  EXPECT_DOUBLE_EQ(first_locked, s.locked_from_t_s);
  EXPECT_EQ(gaps, 1);
  EXPECT_GT(gap_start, rl.t_s);
  EXPECT_LT(gap_start, rl.t_s + 0.5);  // the end margin and the first moving sample
  EXPECT_DOUBLE_EQ(gap_end, rl.locked_again_t_s);
  EXPECT_EQ(locked_rows, s.samples_locked);
  EXPECT_LT(s.locked_from_t_s, 60.0);
  // and the updates carry the same flag: the one before the lock is not locked, the last one is
  ASSERT_GE(sink.updates.size(), 3u);
  EXPECT_FALSE(sink.updates.front().second);
  EXPECT_TRUE(sink.updates.back().second);
  // the warning says when it locked again
  bool warned = false;
  for (const auto& w : s.warnings) warned = warned || w.find("locked again at t =") != std::string::npos;
  EXPECT_TRUE(warned);
}

}  // namespace
}  // namespace driftless::est
