// The DriftLess filter on synthetic samples from the closed-form sensor equation.
#include <cmath>
#include <cstdio>
#include <sstream>

#include <Eigen/Eigenvalues>

#include <gtest/gtest.h>

#include "estimator/filter.hpp"
#include "estimator/stats.hpp"
#include "tests/estimator/synth.hpp"

namespace driftless::est {
namespace {

using test::SynthParams;

Vector6d truth(const SynthParams& p) {
  Vector6d b;
  b << p.b1_dps, p.b2_dps;
  return b;
}

DriftlessFilter run(const SynthParams& p, const EstimatorConfig& cfg) {
  DriftlessFilter f(cfg, test::synth_geometry(p));
  test::synth_samples(p, [&](const Sample& s) { f.push(s); });
  return f;
}

TEST(FilterTest, NoiseFreeConstantBiasesRecoveredGeneralMode) {
  // GIVEN noise-free samples with a rotating box and constant biases
  SynthParams p;
  p.duration_s = 300.0;
  p.body_rate_dps = [](double t) { return Eigen::Vector3d(5.0 * std::sin(0.3 * t), 2.0, -3.0 * std::cos(0.1 * t)); };
  EstimatorConfig cfg;
  cfg.q_override_dps2_per_s = 1e-30;  // (no wander) so the estimate settles exactly
  cfg.r_override_dps2 = 1e-6;
  cfg.variance_floor_dps2 = 1e-30;
  cfg.nis_gate_probability = 1.0;
  // WHEN the general filter runs over it
  const auto f = run(p, cfg);
  // THEN b1, b2 are recovered to 1e-9 deg/s
  EXPECT_GT(f.counters().updates, 20u);
  EXPECT_EQ(f.counters().rejected, 0u);
  EXPECT_LT((f.bias_dps() - truth(p)).cwiseAbs().maxCoeff(), 1e-9) << f.bias_dps().transpose();
}

TEST(FilterTest, NoiseFreeConstantBiasesRecoveredPaperMode) {
  SynthParams p;
  p.duration_s = 300.0;
  EstimatorConfig cfg = paper_config();
  cfg.q_override_dps2_per_s = 1e-30;
  cfg.r_override_dps2 = 1e-6;
  cfg.variance_floor_dps2 = 1e-30;
  cfg.nis_gate_probability = 1.0;
  const auto f = run(p, cfg);
  EXPECT_GT(f.counters().updates, 20u);
  EXPECT_EQ(f.counters().schedule_mismatches, 0u);
  EXPECT_EQ(f.last_update().dim, 6);
  EXPECT_LT((f.bias_dps() - truth(p)).cwiseAbs().maxCoeff(), 1e-9) << f.bias_dps().transpose();
}

}  // namespace
}  // namespace driftless::est

namespace driftless::est {
namespace {

EstimatorConfig quiet_config() {
  EstimatorConfig cfg;
  cfg.q_override_dps2_per_s = 1e-14;  // constant biases in these runs
  cfg.noise_density_dps_rthz = 0.005;  // = 0.05 deg/s per sample at 100 Hz, as synthesised
  return cfg;
}

TEST(FilterTest, TwoPositionsLeaveTheHingeComponentUnobservable) {
  // GIVEN platform 2 held at +90 deg: only platform 1 flips (about z)
  test::SynthParams p;
  p.hold_platform2 = true;
  p.noise_sigma_dps = 0.05;
  p.duration_s = 300.0;
  DriftlessFilter f(quiet_config(), test::synth_geometry(p));
  test::synth_samples(p, [&](const Sample& s) { f.push(s); });
  const Vector6d sd = f.sigma_dps();
  // THEN b1 across the hinge is estimated, b1 along hinge 1 (z) is not: its sigma stays near P0
  EXPECT_LT(sd[0], 0.01);
  EXPECT_LT(sd[1], 0.01);
  EXPECT_GT(sd[2], 2.0);
  // the unobservable direction is b1_z together with the part of b2 it maps onto (R2 b2 . z)
  Eigen::SelfAdjointEigenSolver<Matrix6d> eig(f.covariance_dps2());
  const Vector6d v = eig.eigenvectors().col(5);
  EXPECT_GT(std::fabs(v[2]), 0.5);
  EXPECT_GT(eig.eigenvalues()[5], 1000.0 * eig.eigenvalues()[4]);
}

TEST(FilterTest, StaticBoxWithWrongRotationMatricesStillEstimatesTheBiases) {
  // GIVEN a box at rest whose platforms never move (the paper's Fig. 5 run): only the Earth rate
  test::SynthParams p;
  p.standstill_s = 1e9;  // no flips
  p.duration_s = 300.0;
  p.noise_sigma_dps = 0.05;
  // WHEN the filter assumes eq. (5)'s positions from a 10 s schedule (matrices that are wrong
  // three quarters of the time)
  for (FilterMode mode : {FilterMode::kGeneral, FilterMode::kPaper}) {
    EstimatorConfig cfg = mode == FilterMode::kPaper ? paper_config() : quiet_config();
    cfg.q_override_dps2_per_s = 1e-14;
    cfg.standstill = StandstillSource::kSchedule;
    cfg.standstill_period_s = 10.0;
    DriftlessFilter f(cfg, test::synth_geometry(p));
    test::synth_samples(p, [&](const Sample& s) { f.push(s); });
    // THEN the biases come out anyway: x ~ 0 so a wrong R adds only Earth rate (0.004 deg/s) terms
    EXPECT_GT(f.counters().updates, 25u);
    EXPECT_LT((f.bias_dps() - truth(p)).cwiseAbs().maxCoeff(), 0.02) << f.bias_dps().transpose();
  }
}

TEST(FilterTest, NanSamplesNeverEnterTheState) {
  test::SynthParams p;
  p.duration_s = 60.0;
  p.noise_sigma_dps = 0.05;
  DriftlessFilter f(quiet_config(), test::synth_geometry(p));
  std::size_t k = 0, nan_pushed = 0;
  test::synth_samples(p, [&](const Sample& s) {
    f.push(s);
    if (++k % 97 == 0) {
      Sample bad = s;
      bad.t_s += 0.001;
      bad.gyro2_dps.y() = kNaN;
      const Vector6d before = f.bias_dps();
      const Matrix6d P = f.covariance_dps2();
      EXPECT_EQ(f.push(bad), PushStatus::kInvalid);
      EXPECT_EQ(f.bias_dps(), before);
      EXPECT_EQ(f.covariance_dps2(), P);
      ++nan_pushed;
    }
  });
  EXPECT_EQ(f.counters().invalid, nan_pushed);
  EXPECT_TRUE(f.bias_dps().allFinite());
  EXPECT_LT((f.bias_dps() - truth(p)).cwiseAbs().maxCoeff(), 0.02);
  // time going backwards is dropped, not thrown
  Sample back;
  back.t_s = 1.0;
  back.gyro1_dps.setZero();
  back.gyro2_dps.setZero();
  EXPECT_EQ(f.push(back), PushStatus::kTimeNotIncreasing);
}

TEST(FilterTest, SurvivesASourceSwitchWithANewTimeline) {
  // GIVEN a filter fed by one source, then by another whose time restarts at 0
  test::SynthParams p;
  p.duration_s = 120.0;
  p.noise_sigma_dps = 0.05;
  DriftlessFilter f(quiet_config(), test::synth_geometry(p));
  test::synth_samples(p, [&](const Sample& s) { f.push(s); });
  const auto updates_before = f.counters().updates;
  f.on_source_switch();
  p.seed = 2;
  test::synth_samples(p, [&](const Sample& s) { f.push(s); });
  // THEN it keeps its estimate and keeps updating
  EXPECT_EQ(f.counters().source_switches, 1u);
  EXPECT_EQ(f.counters().time_not_increasing, 0u);
  EXPECT_GT(f.counters().updates, updates_before + 5);
  EXPECT_LT((f.bias_dps() - truth(p)).cwiseAbs().maxCoeff(), 0.01);
}

TEST(FilterTest, GyroOnlyStandstillDetectionFindsTheFlips) {
  // GIVEN end-stop hardware: no angle read-back at all (columns empty), a slowly turning box
  test::SynthParams p;
  p.duration_s = 300.0;
  p.noise_sigma_dps = 0.05;
  p.body_rate_dps = [](double t) { return Eigen::Vector3d(0.5 * std::sin(0.05 * t), 0.3, 0.0); };
  EstimatorConfig cfg = quiet_config();
  cfg.standstill = StandstillSource::kGyroSignal;
  DriftlessFilter f(cfg, test::synth_geometry(p));
  test::synth_samples(p, [&](const Sample& s) {
    Sample blind = s;
    blind.plat1_deg = blind.plat2_deg = kNaN;
    f.push(blind);
  });
  // THEN every flip was seen (one update per standstill) and the biases are found
  EXPECT_GE(f.counters().updates, 25u);
  EXPECT_LE(f.counters().updates, 28u);
  EXPECT_EQ(f.counters().rejected, 0u);
  EXPECT_LT((f.bias_dps() - truth(p)).cwiseAbs().maxCoeff(), 0.02) << f.bias_dps().transpose();
}

TEST(FilterTest, NisGateRejectsAnOutlierStandstillAndReportsIt) {
  test::SynthParams p;
  p.duration_s = 200.0;
  p.noise_sigma_dps = 0.05;
  DriftlessFilter f(quiet_config(), test::synth_geometry(p));
  bool saw_reject = false;
  test::synth_samples(p, [&](const Sample& s) {
    Sample x = s;
    if (s.t_s > 155.0 && s.t_s < 160.0) x.gyro1_dps.x() += 3.0;  // a disturbed standstill
    if (f.push(x) == PushStatus::kRejected) {
      saw_reject = true;
      EXPECT_FALSE(f.last_update().accepted);
      EXPECT_GT(f.last_update().nis, f.last_update().nis_gate);
    }
  });
  EXPECT_TRUE(saw_reject);
  EXPECT_EQ(f.counters().rejected, 1u);
  EXPECT_LT((f.bias_dps() - truth(p)).cwiseAbs().maxCoeff(), 0.01);
}

TEST(FilterTest, AReLockThatCannotExplainTheInnovationEndsInARejection) {
  // GIVEN the paper's filter (stacked 6-row H of rank 5) on a turning box whose sensor 1 reads
  // 10 % high: the residual holds 0.1 M1 w, which changes from one standstill to the next and
  // lies partly outside H's range, so no widening of P brings its NIS under the gate
  SynthParams p;
  p.duration_s = 300.0;
  p.noise_sigma_dps = 0.05;
  p.body_rate_dps = [](double t) { return Eigen::Vector3d(20.0 * std::sin(0.2 * t), 15.0, -10.0 * std::cos(0.1 * t)); };
  EstimatorConfig cfg = paper_config();
  cfg.noise_density_dps_rthz = 0.005;
  DriftlessFilter f(cfg, test::synth_geometry(p));
  // WHEN it runs (before the fix each re-lock called the next: a stack overflow)
  std::uint64_t rejected_pushes = 0;
  test::synth_samples(p, [&](const Sample& s) {
    Sample x = s;
    x.gyro1_dps *= 1.1;
    if (f.push(x) == PushStatus::kRejected) ++rejected_pushes;
  });
  // THEN it re-locks, each re-lock is one try on the widened P, and the tries that fail are
  // counted as rejections
  EXPECT_GE(f.counters().relocks, 1u);
  EXPECT_GE(f.counters().rejected, f.counters().relocks);
  EXPECT_EQ(f.counters().rejected, rejected_pushes);
  EXPECT_LE(f.counters().relocks, f.counters().updates + f.counters().rejected);
}

TEST(FilterTest, ARunOfRejectionsRelocksOntoABiasStep) {
  // GIVEN a converged filter and then a 1 deg/s step in sensor 1's x bias (as after a switch
  // to another sensor, or a real bias jump), far outside the gate
  test::SynthParams p;
  p.duration_s = 600.0;
  p.noise_sigma_dps = 0.05;
  EstimatorConfig cfg = quiet_config();
  DriftlessFilter f(cfg, test::synth_geometry(p));
  test::synth_samples(p, [&](const Sample& s) {
    Sample x = s;
    if (s.t_s > 250.0) x.gyro1_dps.x() += 1.0;
    f.push(x);
  });
  // THEN the first updates after the step are rejected, then the filter re-locks
  EXPECT_GE(f.counters().rejected, static_cast<std::uint64_t>(cfg.gate_relock_after - 1));
  EXPECT_GE(f.counters().relocks, 1u);
  // AND it ends on the new bias
  Vector6d expect = truth(p);
  expect[0] += 1.0;
  EXPECT_LT((f.bias_dps() - expect).cwiseAbs().maxCoeff(), 0.02) << f.bias_dps().transpose();

  // AND with re-locking off the estimate stays frozen on the old bias
  cfg.gate_relock_after = 0;
  DriftlessFilter frozen(cfg, test::synth_geometry(p));
  test::synth_samples(p, [&](const Sample& s) {
    Sample x = s;
    if (s.t_s > 250.0) x.gyro1_dps.x() += 1.0;
    frozen.push(x);
  });
  EXPECT_EQ(frozen.counters().relocks, 0u);
  EXPECT_GT(std::fabs(frozen.bias_dps()[0] - expect[0]), 0.5);
}

TEST(FilterTest, PerSampleUpdatesAgreeWithStandstillAverages) {
  test::SynthParams p;
  p.duration_s = 60.0;
  p.noise_sigma_dps = 0.05;
  EstimatorConfig a = quiet_config(), b = quiet_config();
  b.per_sample_updates = true;
  DriftlessFilter fa(a, test::synth_geometry(p)), fb(b, test::synth_geometry(p));
  test::synth_samples(p, [&](const Sample& s) {
    fa.push(s);
    fb.push(s);
  });
  // with Q ~ 0 both are the same least-squares problem
  EXPECT_LT((fa.bias_dps() - fb.bias_dps()).cwiseAbs().maxCoeff(), 2e-3);
  EXPECT_GT(fb.counters().updates, 50u * fa.counters().updates);
}

TEST(FilterTest, CalibratedMatricesReplaceTheRotations) {
  // GIVEN sensor 1 with a 2 % scale error and a small misalignment, known from calibration
  test::SynthParams p;
  p.duration_s = 300.0;
  p.body_rate_dps = [](double t) { return Eigen::Vector3d(10.0 * std::sin(0.2 * t), 5.0, -4.0); };
  Eigen::Matrix3d C;  // y1 = C^-1 R1^T w + b1  ->  M = R1 C
  C << 1.02, 0.01, 0.0, -0.005, 0.99, 0.003, 0.0, 0.002, 1.01;
  EstimatorConfig cfg = quiet_config();
  cfg.r_override_dps2 = 1e-6;
  for (double a : {90.0, -90.0}) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(a * kRadPerDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    cfg.calibration.sensor1.push_back({a, R * C});
  }
  DriftlessFilter f(cfg, test::synth_geometry(p));
  test::synth_samples(p, [&](const Sample& s) {
    Sample x = s;
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(s.true_plat1_deg * kRadPerDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Vector3d ideal = s.gyro1_dps - s.true_bias1_dps;  // R^T w + hinge rate
    x.gyro1_dps = C.inverse() * ideal + s.true_bias1_dps;
    (void)R;
    f.push(x);
  });
  // THEN the biases come out of the calibrated model (with rotations alone they would not)
  EXPECT_LT((f.bias_dps() - truth(p)).cwiseAbs().maxCoeff(), 1e-3) << f.bias_dps().transpose();
  EXPECT_TRUE(f.body_from_sensor(1, 90.0).isApprox(cfg.calibration.sensor1[0].M_body_from_sensor));
}

TEST(ConfigTest, RoundTripsAndNamesBadLines) {
  EstimatorConfig c = paper_config();
  c.settle_s = 0.75;
  c.standstill = StandstillSource::kGyroSignal;
  std::stringstream ss;
  write_estimator_config(ss, c);
  const auto back = parse_estimator_config(ss, "cfg.yaml");
  EXPECT_EQ(back.mode, FilterMode::kPaper);
  EXPECT_EQ(back.covariance_update, CovarianceUpdate::kPrinted);
  EXPECT_EQ(back.standstill, StandstillSource::kGyroSignal);
  EXPECT_DOUBLE_EQ(back.settle_s, 0.75);
  std::stringstream bad("# tuning\nsettle_s: 0.5\nnoise_density_dps_rthz: fast\n");
  try {
    parse_estimator_config(bad, "cfg.yaml");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cfg.yaml:3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("noise_density_dps_rthz"), std::string::npos);
  }
  std::stringstream unknown("settle: 1\n");
  EXPECT_THROW(parse_estimator_config(unknown, "x"), std::invalid_argument);
  std::stringstream neg("settle_s: -1\n");
  EXPECT_THROW(parse_estimator_config(neg, "x"), std::invalid_argument);
}

}  // namespace
}  // namespace driftless::est
