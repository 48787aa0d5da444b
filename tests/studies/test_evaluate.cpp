// The sweep's bias evaluation is the estimate pass (est::run_estimate) over the run's samples:
// `driftless estimate` on the run's saved log, with the sweep's options, scores the same.
#include <cmath>
#include <map>

#include <gtest/gtest.h>

#include "estimator/pipeline.hpp"
#include "studies/jobs.hpp"
#include "tests/temp_path.hpp"

namespace driftless::studies {
namespace {

const char* kRun = R"(
name: evaluate
runner: fast
scenario: default
duration_s: 160
monte_carlo: 1
seed: 5
fixed:
  estimator.initial_sigma_dps: 25
  flip_schedule.standstill_s: 10
grid:
  flip_angle_deg: {set: flip_schedule.flip_angle_deg, values: [90]}
)";

TEST(Evaluate, TheSweepScoresWhatTheEstimatePassReadsFromItsSavedLog) {
  // GIVEN one fast run of 160 s whose samples are saved to a log
  const SweepConfig c = parse_sweep(kRun, "evaluate.yaml", ".");
  const auto specs = expand(c);
  const auto dir = test::temp_path("driftless_test_evaluate");
  std::filesystem::remove_all(dir);
  const Metrics metrics = make_job(c, dir)(specs.at(0));
  std::map<std::string, double> m(metrics.begin(), metrics.end());
  // WHEN the estimate pass reads that log with the sweep's options
  const RunSetup setup = SetupBuilder(c).build(specs.at(0));
  log::LogReader reader(dir / "run_0.csv");
  const est::EstimateSummary sum = est::run_estimate(reader, setup.estimator, nullptr, bias_run_options(setup));
  // THEN both count the same updates (the run ends inside a standstill: the pass's finish()
  // takes it, which the sweep's own loop used to skip) and agree on the scores to the log's
  // rounding of the samples
  EXPECT_EQ(m.at("updates"), double(sum.counters.updates));
  EXPECT_EQ(m.at("rejected"), double(sum.counters.rejected));
  EXPECT_TRUE(sum.counters.updates > 0 && sum.counters.updates < 20) << sum.counters.updates;
  ASSERT_TRUE(sum.window.available);
  const auto near = [](double a, double b) { return std::fabs(a - b) <= 1e-3 * std::fabs(b) + 1e-9; };
  EXPECT_PRED2(near, m.at("bias_err_rms_dph"), sum.window.bias_error_rms_dps * 3600.0);
  EXPECT_PRED2(near, m.at("nees_mean"), sum.window.nees_per_dof_mean);
  EXPECT_PRED2(near, m.at("sigma_final_dph"), sum.window.sigma_rms_final_dps * 3600.0);
  EXPECT_PRED2(near, m.at("att_drift_dph"), sum.drift_net_corrected_deg_per_h);
  EXPECT_PRED2(near, m.at("att_drift_zeroed_dph"), sum.drift_net_fixed_deg_per_h);
  // the window is the last three quarters (eval_start_s < 0), re-aligned at its start
  EXPECT_NEAR(sum.attitude_realign_s, 40.0, 0.011);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace driftless::studies
