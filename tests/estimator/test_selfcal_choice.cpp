// The default model choice (estimator/selfcal_choice.hpp, docs/estimator.md section 1i): which
// six-state health verdicts call for the self-calibrating pass, and when its results are kept.
// The end-to-end cases (the twin's static scenario, an outsider's uncalibrated MPU6050 pair) are in
// tests/cli/estimate_selfcal.sh and tests/cli/estimate_flip_check.sh.
#include <gtest/gtest.h>

#include "estimator/selfcal_choice.hpp"

namespace driftless::est {
namespace {

HealthReport report(HealthVerdict v, std::initializer_list<std::pair<HealthCause, HealthVerdict>> findings,
                    double rejected_fraction = 0.0) {
  HealthReport h;
  h.verdict = v;
  h.rejected_fraction = rejected_fraction;
  for (const auto& [cause, severity] : findings) {
    HealthFinding f;
    f.cause = cause;
    f.severity = severity;
    h.findings.push_back(f);
  }
  return h;
}

TEST(SelfcalChoice, AnOkSixStatePassIsKeptWithoutASecondPass) {
  // GIVEN an ok verdict, even with a note that would otherwise call for it
  const HealthReport h = report(HealthVerdict::kOk, {{HealthCause::kNoiseUnderstated, HealthVerdict::kOk}});
  // THEN no self-calibrating pass
  EXPECT_FALSE(selfcal_trigger(h, true).wanted);
}

TEST(SelfcalChoice, PositionDependentRejectionsCallForIt) {
  // GIVEN the static scenario's six-state verdict: never locked, rejections at one position pair
  const HealthReport h = report(HealthVerdict::kFailed, {{HealthCause::kNeverLocked, HealthVerdict::kFailed},
                                                         {HealthCause::kRejectionsAtPosition, HealthVerdict::kDegraded}},
                                0.5);
  const SelfcalTrigger t = selfcal_trigger(h, true);
  // THEN the self-calibrating pass is wanted, for the rejections (never_locked alone is no model error)
  EXPECT_TRUE(t.wanted);
  EXPECT_EQ(t.cause, HealthCause::kRejectionsAtPosition);
  // AND not when the log has neither accel columns nor ref_q (nothing drives G)
  EXPECT_FALSE(selfcal_trigger(h, false).wanted);
}

TEST(SelfcalChoice, EachModelErrorFindingCallsForItAndOthersDoNot) {
  for (HealthCause c : {HealthCause::kRejectionsAtPosition, HealthCause::kRejections, HealthCause::kAllRejected,
                        HealthCause::kNoiseUnderstated, HealthCause::kVerticalUnobserved}) {
    EXPECT_TRUE(selfcal_trigger(report(HealthVerdict::kDegraded, {{c, HealthVerdict::kDegraded}}), true).wanted)
        << static_cast<int>(c);
    // a note of the same cause in a run degraded by something else does not
    EXPECT_FALSE(selfcal_trigger(report(HealthVerdict::kDegraded, {{c, HealthVerdict::kOk},
                                                                   {HealthCause::kRelocks, HealthVerdict::kDegraded}}),
                                 true)
                     .wanted)
        << static_cast<int>(c);
  }
  // causes the self-calibration does not model: a short log, a clipping gyro, a late sensor, a gap
  for (HealthCause c : {HealthCause::kNeverLocked, HealthCause::kSaturation, HealthCause::kSignalChainLag,
                        HealthCause::kNoUpdate, HealthCause::kStampRate, HealthCause::kRelocks}) {
    EXPECT_FALSE(selfcal_trigger(report(HealthVerdict::kFailed, {{c, HealthVerdict::kFailed}}), true).wanted)
        << static_cast<int>(c);
  }
}

// a pass's health as the choice reads it: verdict, rejected fraction, NIS mean against its band
HealthReport pass(HealthVerdict v, double rejected_fraction, double nis_mean, double band_hi = 3.6) {
  HealthReport h = report(v, {}, rejected_fraction);
  h.nis_mean = nis_mean;
  h.nis_mean_band_lo = 2.4;
  h.nis_mean_band_hi = band_hi;
  return h;
}

TEST(SelfcalChoice, TheSelfCalibratingPassIsKeptWhereItsModelFits) {
  // GIVEN the static scenario: six-state failed with half the updates rejected, the
  // self-calibrating pass ok, nothing rejected, NIS in its band THEN it is kept
  EXPECT_TRUE(selfcal_pass_better(pass(HealthVerdict::kOk, 0.0, 2.6, 3.89), pass(HealthVerdict::kFailed, 0.5, 2.26)));
  // GIVEN Fig. 9's uncalibrated pan/tilt: both degraded, 60 % rejected against none, NIS in band
  // THEN kept (the gain is the rejections)
  EXPECT_TRUE(selfcal_pass_better(pass(HealthVerdict::kDegraded, 0.0, 2.72, 3.56),
                                  pass(HealthVerdict::kDegraded, 0.595, 6.45)));
  // GIVEN noise larger than configured: the self-calibrating pass's verdict is better but more of
  // its updates are rejected THEN the six-state results stand (the fix is --tune auto)
  EXPECT_FALSE(selfcal_pass_better(pass(HealthVerdict::kDegraded, 0.73, 3.82, 4.7), pass(HealthVerdict::kFailed, 0.5, 7.58)));
  // GIVEN an uncalibrated BMI088 pair estimated with the MPU6050's noise (navgen, seed 7): six-state
  // failed, 48 % rejected; self-calibrating degraded by its NIS above the band (the noise set too
  // low), nothing rejected THEN kept: its NIS excess is the configuration's (--tune auto makes it ok)
  HealthReport noisy_sc = pass(HealthVerdict::kDegraded, 0.0, 5.05, 4.06);
  noisy_sc.findings.push_back({});
  noisy_sc.findings.back().cause = HealthCause::kNoiseUnderstated;
  EXPECT_TRUE(selfcal_pass_better(noisy_sc, pass(HealthVerdict::kFailed, 0.483, 0.64)));
  // GIVEN fewer rejections but its NIS above its band, at the same verdict THEN not kept
  EXPECT_FALSE(selfcal_pass_better(pass(HealthVerdict::kDegraded, 0.1, 6.0), pass(HealthVerdict::kDegraded, 0.3, 9.0)));
  // GIVEN the same verdict and a gain below kSelfcalRejectionGain THEN not kept
  EXPECT_FALSE(selfcal_pass_better(pass(HealthVerdict::kDegraded, 0.27, 3.0),
                                   pass(HealthVerdict::kDegraded, 0.30, 3.0)));
  // GIVEN fewer rejections, NIS in band, but a degraded finding the six-state pass did not have (a
  // short log's late lock, the vertical no pause observes) THEN not kept
  HealthReport traded = pass(HealthVerdict::kDegraded, 0.0, 1.5, 7.2);
  traded.findings.push_back({});
  traded.findings.back().cause = HealthCause::kVerticalUnobserved;
  HealthReport rejecting = pass(HealthVerdict::kDegraded, 0.29, 12.0);
  rejecting.findings.push_back({});
  rejecting.findings.back().cause = HealthCause::kRejections;
  EXPECT_FALSE(selfcal_pass_better(traded, rejecting));
  // AND the same finding as a note does not count
  traded.findings.back().severity = HealthVerdict::kOk;
  EXPECT_TRUE(selfcal_pass_better(traded, rejecting));
  // GIVEN a worse verdict THEN not kept, whatever its rejections
  EXPECT_FALSE(selfcal_pass_better(pass(HealthVerdict::kFailed, 0.0, 3.0), pass(HealthVerdict::kDegraded, 0.5, 8.0)));
  // GIVEN no NIS (no accepted update) THEN not kept
  EXPECT_FALSE(selfcal_pass_better(pass(HealthVerdict::kOk, 0.0, kNaN), pass(HealthVerdict::kFailed, 1.0, kNaN)));
  EXPECT_LT(verdict_rank(HealthVerdict::kFailed), verdict_rank(HealthVerdict::kDegraded));
  EXPECT_LT(verdict_rank(HealthVerdict::kDegraded), verdict_rank(HealthVerdict::kOk));
}

}  // namespace
}  // namespace driftless::est
