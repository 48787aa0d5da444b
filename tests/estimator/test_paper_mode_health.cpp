// Paper mode on data that is not the paper's (docs/estimator.md section 6.1): rest angles other
// than +-flip_angle_deg, a schedule other than eq. (5)'s, are health findings with their cause and
// fix, not an "ok"; and a gate re-lock reports the NIS that triggered it. Tests' own synthesiser.
#include <cmath>

#include <gtest/gtest.h>

#include "estimator/pipeline.hpp"
#include "tests/estimator/synth.hpp"
#include "tests/temp_path.hpp"

namespace driftless::est {
namespace {

std::filesystem::path temp_path(const std::string& name) {
  auto dir = test::temp_path("driftless_test_paper_mode_health");
  std::filesystem::create_directories(dir);
  return dir / name;
}

EstimateSummary estimate_paper(const test::SynthParams& p, const std::string& name) {
  const auto path = temp_path(name);
  test::synth_log(p, path);
  log::LogReader reader(path);
  EstimatorConfig cfg = paper_config();
  cfg.noise_density_dps_rthz = 0.005;  // = 0.05 deg/s per sample at 100 Hz, as synthesised
  return run_estimate(reader, cfg, nullptr);
}

const HealthFinding* find(const HealthReport& h, HealthCause c) {
  for (const HealthFinding& f : h.findings)
    if (f.cause == c) return &f;
  return nullptr;
}

test::SynthParams static_box() {
  test::SynthParams p;
  p.duration_s = 240.0;
  p.noise_sigma_dps = 0.05;
  return p;
}

TEST(PaperModeHealth, ThePapersScheduleHasNoPaperFinding) {
  // GIVEN eq. (5)'s sequence at +-90 deg (the log states no flip_angle_deg: 90 assumed)
  // WHEN paper mode estimates it
  const EstimateSummary s = estimate_paper(static_box(), "paper.csv");
  // THEN no paper-mode finding, every standstill counted and none off
  EXPECT_EQ(find(s.health, HealthCause::kPaperRestAngles), nullptr);
  EXPECT_EQ(find(s.health, HealthCause::kPaperSchedule), nullptr);
  EXPECT_GT(s.counters.paper_standstills, 15u);
  EXPECT_EQ(s.counters.rest_angle_mismatches, 0u);
  EXPECT_EQ(s.health.verdict, HealthVerdict::kOk);
}

TEST(PaperModeHealth, RestsAt45DegWhilePaperModeAssumes90FailWithTheFix) {
  // GIVEN eq. (5)'s sequence but the platforms rest at +-45 deg, in a log that states no
  // flip_angle_deg (paper mode assumes +-90), on a box that turns (so H matters)
  test::SynthParams p = static_box();
  p.flip_angle_deg = 45.0;
  p.body_rate_dps = [](double t) { return Eigen::Vector3d(2.0 * std::sin(0.1 * t), 1.0, -3.0 * std::cos(0.07 * t)); };
  // WHEN paper mode estimates it
  const EstimateSummary s = estimate_paper(p, "rest45.csv");
  // THEN the run fails and its first finding says where the platforms rested and what was assumed
  EXPECT_EQ(s.health.verdict, HealthVerdict::kFailed);
  ASSERT_FALSE(s.health.findings.empty());
  const HealthFinding& f = s.health.findings.front();
  EXPECT_EQ(f.cause, HealthCause::kPaperRestAngles);
  EXPECT_EQ(f.severity, HealthVerdict::kFailed);
  EXPECT_EQ(f.value, double(s.counters.paper_standstills));  // every standstill
  EXPECT_NEAR(std::fabs(f.suggested), 45.0, 0.5);             // the angle read
  EXPECT_EQ(f.sigma, 90.0);                                   // the angle assumed
  EXPECT_EQ(find(s.health, HealthCause::kPaperSchedule), nullptr);  // the order was eq. (5)'s
}

TEST(PaperModeHealth, AScheduleThatIsNotEq5IsAFinding) {
  // GIVEN platform 2 held at +90 deg while platform 1 flips: (90, 90), (-90, 90), ... which is
  // not eq. (5)'s (+,+) (+,-) (-,-) (-,+)
  test::SynthParams p = static_box();
  p.hold_platform2 = true;
  // WHEN paper mode estimates it
  const EstimateSummary s = estimate_paper(p, "one_platform.csv");
  // THEN a schedule finding (not "ok", exit 0), with the standstills off out of all, ahead of the rest
  ASSERT_FALSE(s.health.findings.empty());
  const HealthFinding& f = s.health.findings.front();
  EXPECT_EQ(f.cause, HealthCause::kPaperSchedule);
  EXPECT_EQ(f.value, double(s.counters.schedule_mismatches));
  EXPECT_GT(s.counters.schedule_mismatches, 0u);
  EXPECT_EQ(f.count, s.counters.paper_standstills);
  EXPECT_EQ(f.severity, 2 * s.counters.schedule_mismatches >= s.counters.paper_standstills ? HealthVerdict::kFailed
                                                                                            : HealthVerdict::kDegraded);
  EXPECT_NE(s.health.verdict, HealthVerdict::kOk);
  EXPECT_EQ(find(s.health, HealthCause::kPaperRestAngles), nullptr);  // the angles were +-90
}

TEST(PaperModeHealth, FewOffStandstillsAreDegradedManyFailed) {
  // GIVEN the filter's counts at the end of a paper-mode pass (closed cases)
  FilterCounters c;
  c.paper_standstills = 10;
  c.schedule_mismatches = 4;
  HealthReport few;
  // WHEN 4 of 10 are off, THEN degraded; WHEN 5 of 10, THEN failed
  add_paper_mode_findings(few, c, 90.0);
  EXPECT_EQ(few.verdict, HealthVerdict::kDegraded);
  c.schedule_mismatches = 5;
  HealthReport half;
  add_paper_mode_findings(half, c, 90.0);
  EXPECT_EQ(half.verdict, HealthVerdict::kFailed);
  // AND an earlier finding stays behind them, the worse verdict kept
  HealthReport h;
  h.verdict = HealthVerdict::kDegraded;
  h.findings.push_back({});
  h.findings.back().cause = HealthCause::kRelocks;
  c.schedule_mismatches = 1;
  add_paper_mode_findings(h, c, 90.0);
  ASSERT_EQ(h.findings.size(), 2u);
  EXPECT_EQ(h.findings[0].cause, HealthCause::kPaperSchedule);
  EXPECT_EQ(h.findings[1].cause, HealthCause::kRelocks);
  EXPECT_EQ(h.verdict, HealthVerdict::kDegraded);
}

TEST(RelockNis, TheRelockReportsTheNisThatTriggeredIt) {
  // GIVEN a converged filter and then a 1 deg/s step in sensor 1's x bias, far outside the gate
  test::SynthParams p;
  p.duration_s = 400.0;
  p.noise_sigma_dps = 0.05;
  EstimatorConfig cfg;
  cfg.q_override_dps2_per_s = 1e-14;
  cfg.noise_density_dps_rthz = 0.005;
  DriftlessFilter f(cfg, test::synth_geometry(p));
  UpdateRecord relock;
  test::synth_samples(p, [&](const Sample& s) {
    Sample x = s;
    if (s.t_s > 250.0) x.gyro1_dps.x() += 1.0;
    const PushStatus st = f.push(x);
    const bool updated = st == PushStatus::kUpdated || st == PushStatus::kRejected;
    if (updated && f.last_update().relocked && !relock.relocked) relock = f.last_update();
  });
  // WHEN it re-locks, THEN the record keeps the NIS above the gate that made it re-lock, and the
  // NIS on the widened P (much smaller) separately
  ASSERT_TRUE(relock.relocked);
  EXPECT_GT(relock.relock_nis, relock.nis_gate);
  EXPECT_LT(relock.nis, 0.1 * relock.relock_nis);
}

}  // namespace
}  // namespace driftless::est
