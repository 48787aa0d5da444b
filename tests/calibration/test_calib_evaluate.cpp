// Calibration on a moving box (closed form, no MuJoCo): with planted errors the uncalibrated
// filter's bias error is rate-dependent; the fitted matrices cut it at least 5x.
#include <gtest/gtest.h>

#include "tests/calibration/calib_closed_form_rig.hpp"
#include "calibration/evaluate.hpp"
#include "calibration/rig_plan.hpp"

namespace driftless::calib {
namespace {

est::CalibFit fit_from_rig(est::CalibMethod method, const est::CalibMatrices& truth) {
  ProcedureParams pp;
  pp.segment_s = 30.0;
  const RigPlan plan = standard_plan(pp);
  testing::ClosedFormRig rig;
  rig.M = truth;
  log::Metadata meta;
  const auto samples = rig.run(plan, 11, &meta);
  est::CalibFitOptions o;
  o.method = method;
  return est::fit_calibration(extract_segments(samples, meta, plan, "rig"), o);
}

TEST(CalibEvaluate, CalibrationCutsTheDynamicBiasErrorFiveFold) {
  // GIVEN a box with 2 % scale, 1 deg misalignment, 0.5 % cross-coupling and a 2 deg stop error,
  // turning at up to ~30 deg/s while the platforms flip every 20 s
  const est::CalibMatrices truth = testing::planted_matrices();
  const Eigen::Vector3d bias[2] = {Eigen::Vector3d(1.5, -0.8, 0.3), Eigen::Vector3d(-2.1, 0.4, 1.1)};
  log::Metadata meta;
  const auto log = testing::dynamic_log(truth, bias, 900.0, 0.05, 5, &meta);
  EvalOptions eo;
  eo.skip_s = 300.0;

  // WHEN the filter runs without calibration, with the paper's and with the least-squares fit
  est::EstimatorConfig nominal;
  est::EstimatorConfig paper = nominal, ls = nominal;
  paper.calibration = est::to_filter_calibration(fit_from_rig(est::CalibMethod::kTopToTop, truth).matrices());
  ls.calibration = est::to_filter_calibration(fit_from_rig(est::CalibMethod::kLeastSquares, truth).matrices());
  const EvalRow raw = evaluate_log(log, meta, nominal, "raw", false, eo);
  const EvalRow none = evaluate_log(log, meta, nominal, "none", true, eo);
  const EvalRow rp = evaluate_log(log, meta, paper, "paper", true, eo);
  const EvalRow rl = evaluate_log(log, meta, ls, "ls", true, eo);
  RecordProperty("table", eval_table({raw, none, rp, rl}));

  // THEN the bias error drops at least 5x with either calibration
  EXPECT_GT(none.updates, 30u);
  EXPECT_GT(none.bias_rms_error_dps, 0.05);  // the rate-dependent error is real
  EXPECT_LT(rp.bias_rms_error_dps * 5.0, none.bias_rms_error_dps) << eval_table({none, rp, rl});
  EXPECT_LT(rl.bias_rms_error_dps * 5.0, none.bias_rms_error_dps) << eval_table({none, rp, rl});
  // and the attitude drifts far less than with the raw gyros
  EXPECT_LT(rl.attitude_final_error_deg * 5.0, raw.attitude_final_error_deg) << eval_table({raw, rl});
}

TEST(CalibEvaluate, PerfectMatricesAndNoNoiseGiveTheTrueBias) {
  const est::CalibMatrices truth = testing::planted_matrices();
  const Eigen::Vector3d bias[2] = {Eigen::Vector3d(1.5, -0.8, 0.3), Eigen::Vector3d(-2.1, 0.4, 1.1)};
  log::Metadata meta;
  const auto log = testing::dynamic_log(truth, bias, 400.0, 0.0, 5, &meta);
  est::EstimatorConfig cfg;
  cfg.calibration = est::to_filter_calibration(truth);
  EvalOptions eo;
  eo.skip_s = 200.0;
  const EvalRow r = evaluate_log(log, meta, cfg, "exact", true, eo);
  EXPECT_LT(r.bias_final_error_dps, 1e-3);
  EXPECT_LT(r.attitude_final_error_deg, 0.5);
}

TEST(CalibEvaluate, AttitudeIntegrationMatchesTheReference) {
  // GIVEN bias-free, noise-free outputs and exact matrices; the raw rates integrate to ref_q
  const est::CalibMatrices truth = testing::planted_matrices();
  const Eigen::Vector3d zero[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  log::Metadata meta;
  const auto log = testing::dynamic_log(truth, zero, 300.0, 0.0, 5, &meta);
  est::EstimatorConfig cfg;
  cfg.calibration = est::to_filter_calibration(truth);
  EvalOptions eo;
  eo.skip_s = 0.0;
  const EvalRow r = evaluate_log(log, meta, cfg, "raw exact", false, eo);
  EXPECT_LT(r.attitude_max_error_deg, 1e-3);
  // and with the nominal rotations instead of M, the planted errors show as drift
  const EvalRow n = evaluate_log(log, meta, est::EstimatorConfig{}, "raw nominal", false, eo);
  EXPECT_GT(n.attitude_max_error_deg, 1.0);
}

}  // namespace
}  // namespace driftless::calib
