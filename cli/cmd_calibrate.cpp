// driftless calibrate: the pan/tilt calibration of paper section 4, on a recorded log + rig plan
// or on the twin's simulated rig; writes calib.yaml (docs/calibration.md).
#include <algorithm>
#include <cmath>
#include <fstream>
#include <memory>
#include <string>

#include <fmt/core.h>

#include "cli/command.hpp"
#include "estimator/output_file.hpp"
#include "estimator/calibration.hpp"
#include "estimator/log.hpp"
#include "calibration/calib_file.hpp"
#include "calibration/prior.hpp"
#include "calibration/rig_sim.hpp"
#include "calibration/rig_plan.hpp"

namespace driftless::cli {
namespace {

struct CalibrateOptions {
  std::string scenario, log, plan, out, method, save_log, save_plan, prior_out;
};

est::CalibMethod parse_method(const std::string& m) {
  if (m == "least_squares") return est::CalibMethod::kLeastSquares;
  if (m == "top_to_top") return est::CalibMethod::kTopToTop;
  throw std::invalid_argument("--method: expected least_squares or top_to_top, got '" + m + "'");
}

void print_summary(const est::CalibFit& fit, const calib::RigConditions& rig,
                   const calib::ExtractReport& rep, const est::GSensitivityFit& g) {
  fmt::print("calibration ({}), {} segments, Earth rate {}\n", est::method_name(fit.method),
             rig.plan.segments.size(), rep.earth_rate_removed ? "removed" : "NOT removed");
  for (const auto& n : rep.notes) fmt::print("  note: {}\n", n);
  const est::CalibMatrices m = fit.matrices();
  for (int i = 0; i < 2; ++i) {
    for (int p = 0; p < 2; ++p) {
      const auto& f = fit.fit[i][p];
      fmt::print("  sensor {} at {}: {} samples, residual rms [{:.4f} {:.4f} {:.4f}] deg/s, "
                 "max sigma(M) {:.2e}\n",
                 i + 1, est::position_name(p), f.n_samples, f.residual_rms_dps.x(),
                 f.residual_rms_dps.y(), f.residual_rms_dps.z(), f.M_sigma.maxCoeff());
    }
    const auto e = est::describe_errors(m, i, i == 0 ? rig.hinge1_axis : rig.hinge2_axis);
    fmt::print("  sensor {}: scale error [{:+.3f} {:+.3f} {:+.3f}] %, non-orthogonality "
               "[{:+.3f} {:+.3f} {:+.3f}] deg, end-stop travel error {:+.3f} deg\n",
               i + 1, 100 * e.scale_error.x(), 100 * e.scale_error.y(), 100 * e.scale_error.z(),
               e.nonorthogonality_deg.x(), e.nonorthogonality_deg.y(), e.nonorthogonality_deg.z(),
               e.travel_error_deg);
    if (g.valid) {
      const auto iu = static_cast<std::size_t>(i);
      fmt::print("  sensor {}: g-sensitivity |G| {:.4f} deg/s/g (max sigma {:.4f}) from {} segment biases\n", i + 1,
                 g.G_dps_per_g[iu].norm(), g.G_sigma[iu].maxCoeff(), g.segments);
    }
  }
  if (!g.valid) fmt::print("  g-sensitivity not fitted: {}\n", g.reason);
}

// --prior-out: the calibrated errors as a twin model-config file
void write_prior(const CalibrateOptions& o) {
  if (o.prior_out.empty()) return;
  const calib::CalibFile c = calib::load_calib(o.out);
  io::write_file(o.prior_out, calib::model_prior_yaml(c));
  fmt::print("wrote {} (model prior)\n", o.prior_out);
}

int run_from_log(const CalibrateOptions& o) {
  log::Metadata meta;
  const std::vector<Sample> samples = log::read_all(o.log, &meta);
  const calib::RigPlan plan = calib::load_rig_plan(o.plan);
  calib::ExtractReport rep;
  const auto segs = calib::extract_segments(samples, meta, plan, o.log, &rep);
  est::CalibFitOptions fo;
  fo.method = parse_method(o.method.empty() ? "least_squares" : o.method);
  const est::CalibFit fit = est::fit_calibration(segs, fo);
  const est::GSensitivityFit g = est::fit_g_sensitivity(segs, fit);
  calib::RigConditions rig;
  rig.source = "log " + o.log + ", plan " + o.plan;
  rig.latitude_deg = rep.latitude_deg;
  rig.sample_rate_hz = rep.sample_rate_hz;
  rig.earth_rate_removed = rep.earth_rate_removed && fo.method == est::CalibMethod::kLeastSquares;
  rig.mean_temp_c = rep.mean_temp_c;
  rig.hinge1_axis = meta.hinge1_axis();
  rig.hinge2_axis = meta.hinge2_axis();
  rig.plan = plan;
  rig.samples_used = rep.samples_used;
  calib::save_calib(o.out, fit, rig, &g);
  print_summary(fit, rig, rep, g);
  fmt::print("wrote {}\n", o.out);
  write_prior(o);
  return 0;
}

int run_from_scenario(const CalibrateOptions& o) {
  const calib::CalibScenario cs = calib::load_calib_scenario(o.scenario);
  calib::RigRun run;
  {
    Progress progress("calibration rig");
    run = calib::run_rig(cs, [&](double f) {
      progress.update(f);
      return !stop_requested().load();
    });
    progress.done();
  }
  if (stop_requested().load()) {
    // interrupted: the rig run is partial, so no fit and no calibration file that would look whole
    fmt::print(stderr, "driftless calibrate: stopped before the rig run finished; nothing written\n");
    return interrupted_exit_code();
  }
  if (!o.save_log.empty()) {
    log::LogWriter w(o.save_log, run.meta,
                     kFieldAccel | kFieldTemp | kFieldRefQ | kFieldRefP | kFieldTrueBias |
                         kFieldTrueRate | kFieldTruePlat);
    for (const auto& s : run.samples) w.write(s);
    w.finish(true);
    fmt::print("wrote {} (rig log)\n", o.save_log);
  }
  if (!o.save_plan.empty()) {
    calib::save_rig_plan(o.save_plan, run.plan);
    fmt::print("wrote {} (rig plan)\n", o.save_plan);
  }
  calib::ExtractReport rep;
  const auto segs = calib::extract_segments(run.samples, run.meta, run.plan, o.scenario, &rep);
  est::CalibFitOptions fo;
  fo.method = parse_method(o.method.empty() ? cs.rig.method : o.method);
  const est::CalibFit fit = est::fit_calibration(segs, fo);
  const est::GSensitivityFit g = est::fit_g_sensitivity(segs, fit);
  calib::RigConditions rig;
  rig.source = "scenario " + o.scenario + " (the twin's pan/tilt rig)";
  rig.latitude_deg = rep.latitude_deg;
  rig.sample_rate_hz = rep.sample_rate_hz;
  rig.earth_rate_removed = rep.earth_rate_removed && fo.method == est::CalibMethod::kLeastSquares;
  rig.mean_temp_c = rep.mean_temp_c;
  rig.hinge1_axis = run.meta.hinge1_axis();
  rig.hinge2_axis = run.meta.hinge2_axis();
  rig.plan = run.plan;
  rig.samples_used = rep.samples_used;
  calib::save_calib(o.out, fit, rig, &g);
  print_summary(fit, rig, rep, g);
  // the fit against the twin's own true M, absolute and in units of the fit's 1-sigma
  double worst = 0.0, worst_sigma = 0.0;
  for (int i = 0; i < 2; ++i) {
    for (int p = 0; p < 2; ++p) {
      const Eigen::Matrix3d d = (fit.fit[i][p].M - run.true_M.M(i, p)).cwiseAbs();
      worst = std::max(worst, d.maxCoeff());
      worst_sigma = std::max(worst_sigma, d.cwiseQuotient(fit.fit[i][p].M_sigma).maxCoeff());
    }
  }
  fmt::print("  against the twin's true M (sensor model + MuJoCo rest angles): max |dM| = {:.2e}, "
             "max |dM|/sigma = {:.2f}\n", worst, worst_sigma);
  fmt::print("wrote {}\n", o.out);
  write_prior(o);
  return 0;
}

const bool registered_calibrate = register_command(40, [](CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "calibrate",
      "Calibrate the box on a pan/tilt unit (paper section 4): fit M per sensor and end stop "
      "from a recorded log + rig plan, or run the simulated rig of a scenario; writes calib.yaml "
      "(docs/calibration.md)");
  auto o = std::make_shared<CalibrateOptions>();
  auto* scen = cmd->add_option("--scenario", o->scenario,
                               "Scenario with a calibration: block; runs the twin's pan/tilt rig "
                               "(e.g. models/scenarios/calibration.yaml)")
                   ->check(CLI::ExistingFile);
  auto* logo = cmd->add_option("--log", o->log, "Recorded rig log (driftless-log 1; gyro deg/s, "
                                                "ref_q for the Earth rate)")
                   ->check(CLI::ExistingFile);
  auto* plano = cmd->add_option("--plan", o->plan, "Rig plan (YAML; segment times s, rates deg/s, "
                                                   "end stops deg; docs/calibration.md)")
                    ->check(CLI::ExistingFile);
  cmd->add_option("--out", o->out, "Output calibration file (calib.yaml)")->required();
  cmd->add_option("--method", o->method,
                  "least_squares (Earth rate removed; the default) or top_to_top (the paper's averaging); "
                  "with --scenario the default is the scenario's calibration.method");
  cmd->add_option("--prior-out", o->prior_out,
                  "Also write the calibrated errors as a twin model-config file (model: block with "
                  "scale %, misalignment %, mounting deg, stop errors deg) for simulate --model");
  cmd->add_option("--save-log", o->save_log, "With --scenario: also write the simulated rig log");
  cmd->add_option("--save-plan", o->save_plan, "With --scenario: also write its rig plan");
  scen->excludes(logo)->excludes(plano);
  logo->needs(plano);
  plano->needs(logo);
  return [o] {
    if (o->scenario.empty() && o->log.empty())
      throw std::invalid_argument("calibrate: give --scenario FILE, or --log FILE --plan FILE");
    return o->scenario.empty() ? run_from_log(*o) : run_from_scenario(*o);
  };
}, Interrupt::kPolls);

}  // namespace
}  // namespace driftless::cli
