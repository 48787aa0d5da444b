// driftless estimate: run the DriftLess filter over a measurement log and write the bias
// estimates, corrected outputs, attitude drift and (for simulated logs) errors against truth.
// Formats: docs/estimator.md.
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <fmt/core.h>

#include "cli/command.hpp"
#include "cli/estimate_figures.hpp"
#include "cli/estimate_health.hpp"
#include "cli/estimate_outputs.hpp"
#include "cli/estimate_passes.hpp"
#include "estimator/calibration.hpp"
#include "estimator/pipeline.hpp"
#include "estimator/smoother.hpp"
#include "estimator/tune.hpp"
#include "calibration/calib_file.hpp"
#include "calibration/prior.hpp"
#include "estimator/output_file.hpp"

namespace driftless::cli {
namespace {

namespace fs = std::filesystem;

struct EstimateArgs {
  std::string log;
  std::string out;
  std::string mode;  // empty = config / general
  std::string config;
  std::string calib;  // calib.yaml from driftless calibrate (docs/calibration.md)
  std::string calib_out;  // --selfcal: write the estimated G and temperature coefficients as calib.yaml
  std::string prior_out;  // with --calib-out: the same as a twin model prior
  bool plot = false;
  bool corrected = false;  // write corrected.csv (--corrected)
  bool smooth = false;     // corrected.csv from the fixed-interval smoother (--smooth)
  bool selfcal = false;   // self-calibrating mode: g-sensitivity states (docs/estimator.md section 1b)
  bool no_selfcal = false;  // the six-state model even where it does not fit (no automatic choice, section 1i)
  bool box_at_rest = false;  // the box stands still on the Earth: the vertical Earth rate is a measurement
  bool strict = false;    // exit 1 on a degraded health verdict too (failed always exits 1)
  std::string tune;       // "auto": noise density and bias wander from the log (docs/estimator.md section 6.2)
  double attitude_start_sigma_dps = est::EstimateRunOptions{}.attitude_start_sigma_dps;
};

// --calib-out / --prior-out: what the self-calibrating pass estimated, as calib.yaml and as a twin
// model prior (docs/calibration.md "calib.yaml from a self-calibration")
void write_selfcal_files(const EstimateArgs& a, const log::Metadata& meta, const est::EstimateSummary& s) {
  if (a.calib_out.empty()) return;
  calib::SelfCalibration sc;
  sc.source = "driftless estimate --selfcal on " + a.log;
  sc.latitude_deg = meta.latitude_deg();
  sc.sample_rate_hz = meta.sample_rate_hz();
  sc.hinge1_axis = meta.hinge1_axis();
  sc.hinge2_axis = meta.hinge2_axis();
  sc.G_dps_per_g = s.gsens_dps_per_g;
  sc.G_sigma = s.gsens_sigma_dps_per_g;
  sc.scale_states = s.scale_states;
  sc.E_frac = s.scale_misalign_frac;
  sc.E_sigma_frac = s.scale_misalign_sigma_frac;
  sc.temp_states = s.temp_states;
  for (int i = 0; i < 2; ++i) {
    const auto iu = static_cast<std::size_t>(i);
    sc.temp_coef_dps_per_degc[iu] = s.temp_coef_dps_per_degc.segment<3>(3 * i);
    sc.temp_coef_sigma_dps_per_degc[iu] = s.temp_coef_sigma_dps_per_degc.segment<3>(3 * i);
  }
  sc.temp_ref_c = s.temp_ref_c;
  sc.stop_states = s.stop_states;
  sc.end_stop_deg = s.stop_angle_deg;
  sc.end_stop_sigma_deg = s.stop_angle_sigma_deg;
  calib::save_selfcal_calib(a.calib_out, sc);
  fmt::print("  wrote {} (g-sensitivity{}{}{} with 1-sigma; M nominal)\n", a.calib_out,
             sc.scale_states ? ", scale/misalignment" : "", sc.stop_states ? ", end-stop angles" : "",
             sc.temp_states ? " and bias temperature coefficients" : "");
  if (a.prior_out.empty()) return;
  io::write_file(a.prior_out, calib::model_prior_yaml(calib::load_calib(a.calib_out)));
  fmt::print("  wrote {} (model prior for the twin)\n", a.prior_out);
}

// For tests/cli/estimate_smooth_stop.sh: with DRIFTLESS_TEST_SMOOTH_HOLD=FILE the second pass, once
// it has handed kHoldAfterRows rows to corrected.csv, creates FILE and waits (at most 120 s) for a
// stop, so that a signal lands inside the pass at a known row on any machine load. Unset: nothing.
class SmoothHold {
 public:
  static constexpr std::uint64_t kHoldAfterRows = 100;
  SmoothHold() {
    if (const char* p = std::getenv("DRIFTLESS_TEST_SMOOTH_HOLD")) path_ = p;
  }
  void after_row() {
    if (path_.empty() || ++rows_ != kHoldAfterRows) return;
    io::write_file(path_, std::to_string(rows_) + "\n");
    for (int i = 0; i < 12000 && !stop_requested().load(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }

 private:
  std::string path_;
  std::uint64_t rows_ = 0;
};

// --smooth: the backward pass over the updates, then the log again with the smoothed correction
// into corrected.csv (docs/estimator.md section 6.3). Every row is marked locked when the forward
// filter locked at all: the smoothed correction at any time uses the whole log
// A stop (SIGINT/SIGTERM) ends the second pass at the next row: corrected.csv keeps the rows
// written, and the time of the last one is returned (NaN: none) for summary.json's stopped_at_t_s
double write_smoothed(const EstimateArgs& a, const log::ReaderOptions& read_opt, const est::EstimatorConfig& cfg,
                      est::FixedIntervalSmoother& sm, EstimateFiles& files, const est::EstimateSummary& s) {
  sm.smooth();
  log::LogReader again(a.log, read_opt);
  const bool locked = std::isfinite(s.locked_from_t_s);
  double last_t_s = kNaN;
  SmoothHold hold;
  est::smoothed_outputs(
      cfg, est::box_geometry_from_metadata(again.metadata()),
      [&again](Sample& x) { return !stop_requested().load() && again.next(x); }, sm,
      [&](const Sample& x, const est::SampleOutput& o) {
        files.on_smoothed_sample(x, o, locked);
        last_t_s = x.t_s;
        hold.after_row();
      });
  return last_t_s;
}

// what --tune auto did with Q: measured, bounded (and applied), or kept
std::string q_text(const est::TuneResult& t) {
  if (t.q_upper_bound) {
    return fmt::format("at most {:.4g} (deg/s)^2/s (no wander above the noise: the revisits' upper bound){}",
                       t.q_dps2_per_s, t.q_estimated ? "" : ", above the configured value, which is kept");
  }
  return t.q_estimated ? fmt::format("{:.4g} (deg/s)^2/s", t.q_dps2_per_s) : "not measured, configured value kept";
}

// --tune auto: a first pass over the log measures N and K (docs/estimator.md section 6.2)
est::TuneResult tune_config(const EstimateArgs& a, est::EstimatorConfig& cfg) {
  log::LogReader first(a.log);
  const est::TuneResult t = est::tune_from_log(first, cfg);
  est::apply_tune(t, cfg);
  cfg.validate();
  fmt::print("tune auto: noise density {} ({} block pairs of {:g} s), bias random walk Q {} ({} revisits)\n",
             t.noise_estimated ? fmt::format("{:.4g} deg/s/sqrt(Hz)", t.noise_density_dps_rthz)
                               : "not measured, configured value kept",
             t.noise_block_pairs, t.block_s,
             q_text(t), t.wander_pairs);
  return t;
}

// the health verdict on the console; the exit code: failed always 1, degraded 1 with --strict
int report_health(const EstimateArgs& a, const est::EstimatorConfig& cfg, const est::HealthReport& h) {
  const auto lines = health_lines(h, cfg);
  const bool bad = h.verdict != est::HealthVerdict::kOk;
  for (const auto& l : lines) fmt::print(bad ? stderr : stdout, "{}{}\n", bad ? "driftless estimate: " : "  ", l);
  if (h.verdict == est::HealthVerdict::kFailed) {
    // the first finding is the cause (never locked, clipping, a schedule paper mode does not fit, ...)
    const bool no_rows = !h.findings.empty() && h.findings.front().cause == est::HealthCause::kNoDataRows;
    fmt::print(stderr, "driftless estimate: health failed{}: the estimates are not usable (exit 1)\n",
               no_rows            ? ", the log has no data rows"
               : !h.locked        ? ", the filter never locked"
               : h.locked_at_end ? ""
                                 : ", the filter lost its lock and did not lock again");
    return kExitFailed;
  }
  if (h.verdict == est::HealthVerdict::kDegraded && a.strict) {
    fmt::print(stderr, "driftless estimate: health degraded and --strict given (exit 1)\n");
    return kExitFailed;
  }
  return kExitOk;
}

// the console's attitude line: the drifts, or why they are withheld
void print_attitude_line(const est::EstimateSummary& summary) {
  if (summary.attitude_available && std::isfinite(summary.attitude_withheld_from_s)) {
    fmt::print("  attitude: compared from t = {:.1f} s, withheld from t = {:.1f} s ({}; see the warning)\n",
               summary.attitude_start_s, summary.attitude_withheld_from_s,
               summary.attitude_withheld_why == est::AttitudeWithheld::kBothFlipping ? "both platforms flipped at once"
               : summary.attitude_withheld_why == est::AttitudeWithheld::kTimeGap    ? "a time gap"
                                                                                    : "no sensor gave the box rate");
  } else if (summary.attitude_available && !std::isfinite(summary.final_corrected.angle_deg) &&
             summary.reference.verdict != est::RefFitVerdict::kFits &&
             summary.reference.verdict != est::RefFitVerdict::kNotChecked) {
    fmt::print("  attitude: withheld (ref_q does not turn with the gyros: see the health finding "
               "reference_mismatch)\n");
  } else if (summary.attitude_available && !std::isfinite(summary.attitude_start_s)) {
    fmt::print("  attitude: not compared (the filter never locked on: see the health verdict)\n");
  } else if (summary.attitude_available) {
    fmt::print("  attitude drift from t = {:.1f} s: {:.2f} deg/h with DriftLess, {:.2f} deg/h with the bias "
               "fixed at that start, {:.2f} deg/h uncorrected\n",
               summary.attitude_start_s, summary.drift_corrected_deg_per_h, summary.drift_fixed_deg_per_h,
               summary.drift_raw_deg_per_h);
  }
}

// the configuration before the log is read: --config, --mode and the flags
est::EstimatorConfig base_config(const EstimateArgs& a) {
  est::EstimatorConfig cfg;
  if (!a.config.empty()) {
    std::ifstream in(a.config);
    if (!in) throw std::runtime_error("cannot read --config " + a.config);
    cfg = est::parse_estimator_config(in, a.config, a.mode == "paper" ? est::paper_config() : est::EstimatorConfig{});
  } else if (a.mode == "paper") {
    cfg = est::paper_config();
  }
  if (!a.mode.empty()) est::set_config_value(cfg, "mode", a.mode);
  if (a.selfcal) cfg.self_calibration = true;
  if (a.no_selfcal) cfg.self_calibration = false;
  if (a.box_at_rest) cfg.box_at_rest = true;
  if (!a.calib_out.empty() && !cfg.self_calibration) {
    throw std::invalid_argument("--calib-out needs --selfcal (or self_calibration: true in --config): without it "
                                "the g-sensitivity is not estimated");
  }
  return cfg;
}

// --calib: the calibrated matrices M replace R in eq. (1)-(2) (docs/calibration.md)
void apply_calib(const EstimateArgs& a, const log::Metadata& meta, est::EstimatorConfig& cfg) {
  const calib::CalibFile c = calib::load_calib(a.calib);
  if ((c.hinge1_axis.normalized() - meta.hinge1_axis().normalized()).norm() > 1e-6 ||
      (c.hinge2_axis.normalized() - meta.hinge2_axis().normalized()).norm() > 1e-6) {
    throw std::invalid_argument(fmt::format(
        "--calib {}: calibrated for hinge axes [{} {} {}] / [{} {} {}] but the log {} has [{} {} {}] / "
        "[{} {} {}]: not the same box", a.calib, c.hinge1_axis.x(), c.hinge1_axis.y(), c.hinge1_axis.z(),
        c.hinge2_axis.x(), c.hinge2_axis.y(), c.hinge2_axis.z(), a.log, meta.hinge1_axis().x(),
        meta.hinge1_axis().y(), meta.hinge1_axis().z(), meta.hinge2_axis().x(), meta.hinge2_axis().y(),
        meta.hinge2_axis().z()));
  }
  // M (unless nominal); G and E: with --selfcal the prior of their states (value and sigma),
  // else fixed corrections (y <- y - G f / g with the log's accelerometer columns, samples
  // without them stay as they are; M (I + E)^-1 for M); the temperature states start at the
  // calibrated coefficients
  cfg.calibration = c.to_filter_calibration();
}

// config_used.txt: the configuration of the pass whose results the outputs hold
void write_config_used(const fs::path& dir, const est::EstimatorConfig& cfg) {
  std::ostringstream used;
  est::write_estimator_config(used, cfg);
  io::write_file(dir / "config_used.txt", used.str());
}

// the console summary of the kept pass
void print_results(const EstimateArgs& a, const est::EstimateSummary& summary, bool truth, bool interrupted) {
  const auto& b = summary.bias_dps;
  const auto& sg = summary.sigma_dps;
  fmt::print("{}: {} rows, {} updates ({} rejected)\n", a.log, summary.rows, summary.counters.updates,
             summary.counters.rejected);
  fmt::print("  b1 = ({:+.5f}, {:+.5f}, {:+.5f}) +- ({:.5f}, {:.5f}, {:.5f}) deg/s\n", b[0], b[1], b[2], sg[0],
             sg[1], sg[2]);
  fmt::print("  b2 = ({:+.5f}, {:+.5f}, {:+.5f}) +- ({:.5f}, {:.5f}, {:.5f}) deg/s\n", b[3], b[4], b[5], sg[3],
             sg[4], sg[5]);
  print_attitude_line(summary);
  if (truth && summary.truth.updates > 0) {
    fmt::print("  against truth: bias error rms {:.5f} deg/s over all updates ({:.5f} over the second half), "
               "mean NEES {:.2f} (95 % band {:.2f}..{:.2f})\n",
               summary.truth.bias_error_rms_dps, summary.truth.bias_error_rms_second_half_dps,
               summary.truth.nees_mean, summary.truth.nees_mean_band_lo, summary.truth.nees_mean_band_hi);
  }
  fmt::print("  wrote {}/{{estimate.csv,{} attitude.csv, summary.json}}{}\n", a.out, a.corrected ? " corrected.csv," : "",
             interrupted ? fmt::format(" (interrupted at t = {:.3f} s: summary.json says complete: false)",
                                       summary.t_last_s)
                         : "");
}

// --plot: the figures of the kept pass, each drawn or the reason it was not (as a warning)
std::vector<FigureOutcome> draw_figures(const EstimateArgs& a, const log::Metadata& meta, const EstimatePass& p,
                                        bool truth, bool attitude, bool interrupted,
                                        std::vector<std::string>& warnings) {
  std::vector<FigureOutcome> figures;
  if (!a.plot) return figures;
  if (interrupted) {
    warnings.push_back("figures not drawn: the run was interrupted");
    return figures;
  }
  const auto& summary = p.summary;
  double rate = meta.sample_rate_hz();
  if (!std::isfinite(rate) && summary.rows > 1) rate = double(summary.rows - 1) / (summary.t_last_s - summary.t_first_s);
  EstimateFigureInputs fig{&p.files->series(), truth, attitude, rate, summary.locked_from_t_s,
                           a.attitude_start_sigma_dps, summary.attitude_start_s};
  figures = write_estimate_figures(p.dir, fig);
  for (const auto& f : figures) {
    if (!f.written) warnings.push_back(fmt::format("{} not drawn: {}", f.stem, f.reason));
  }
  return figures;
}

int run_estimate_cmd(const EstimateArgs& a) {
  est::EstimatorConfig cfg = base_config(a);
  SelfcalChoice choice;
  choice.mode = a.no_selfcal ? est::SelfcalMode::kOff : cfg.self_calibration ? est::SelfcalMode::kOn
                                                                             : est::SelfcalMode::kAuto;
  // the first pass's reader: its header and columns decide the outputs
  const PassInputs in{a.log, !a.calib.empty(), a.smooth, a.attitude_start_sigma_dps};
  log::LogReader reader(a.log, first_reader_options(in, cfg, choice.mode));
  if (!a.calib.empty()) apply_calib(a, reader.metadata(), cfg);
  cfg.validate();
  est::TuneResult tune;
  if (a.tune == "auto") tune = tune_config(a, cfg);

  const bool truth = (reader.fields() & kFieldTrueBias) != 0;
  const bool attitude = (reader.fields() & kFieldRefQ) != 0;
  fs::create_directories(a.out);
  const fs::path dir(a.out);
  if (a.corrected) {
    // corrected.csv: about 110 bytes per log row; the log's rows from its size (about 370 bytes each
    // for a twin log, fewer for hardware logs: the estimate errs on the large side)
    std::error_code ec;
    const double log_bytes = static_cast<double>(fs::file_size(a.log, ec));
    if (!ec) warn_if_disk_too_small("estimate", dir, 0.6 * log_bytes, "corrected.csv");
  }
  EstimateFilesOptions file_opt;
  file_opt.truth = truth;
  file_opt.corrected = a.corrected;
  file_opt.smoothed = a.smooth;
  file_opt.keep_series = a.plot;
  write_config_used(dir, cfg);
  EstimatePass pass = run_passes(in, cfg, reader, dir, file_opt, choice);
  if (choice.used) write_config_used(dir, pass.cfg);
  const auto& summary = pass.summary;
  // --smooth: corrected.csv holds the smoother's rows only when its second pass ran to the end
  double stopped_at_t_s = summary.t_last_s;
  bool smoothed = false;
  if (pass.smoother && !stop_requested().load()) {
    stopped_at_t_s = write_smoothed(a, pass.read_opt, pass.cfg, *pass.smoother, *pass.files, summary);
    smoothed = !stop_requested().load();
  }
  commit_pass(pass, dir);
  pass.dir = dir;
  const bool interrupted = stop_requested().load();

  auto warnings = summary.warnings;
  const std::vector<FigureOutcome> figures =
      draw_figures(a, reader.metadata(), pass, truth, attitude, interrupted, warnings);
  auto final_summary = summary;
  final_summary.warnings = warnings;
  SummaryContext ctx;
  ctx.log_path = a.log;
  ctx.mode = pass.cfg.mode;
  // a self-calibrating pass interrupted leaves the six-state pass's outputs, which are whole
  ctx.complete = !interrupted || (choice.interrupted && !a.smooth);
  ctx.stopped_at_t_s = stopped_at_t_s;
  ctx.smooth_requested = a.smooth;
  ctx.smoothed = smoothed;
  ctx.figures = &figures;
  ctx.config = &pass.cfg;
  ctx.tune = a.tune == "auto" ? &tune : nullptr;
  ctx.selfcal_choice = &choice;
  write_estimate_summary(dir / "summary.json", ctx, final_summary);

  for (const auto& w : warnings) fmt::print(stderr, "driftless estimate: warning: {}\n", w);
  print_results(a, summary, truth, interrupted && !choice.interrupted);
  print_choice(choice);
  if (interrupted) return interrupted_exit_code();
  write_selfcal_files(a, reader.metadata(), summary);
  std::fflush(stdout);
  return report_health(a, pass.cfg, summary.health);
}

const bool registered_estimate = register_command(30, [](CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "estimate", "Run the DriftLess bias filter over a measurement log: bias estimates (deg/s), "
                  "corrected outputs, attitude drift (deg/h); docs/estimator.md");
  auto a = std::make_shared<EstimateArgs>();
  cmd->add_option("--log", a->log, "Measurement log (CSV, driftless-log 1; docs/log-format.md)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", a->out, "Output folder (created): estimate.csv, attitude.csv, summary.json [, corrected.csv]")
      ->required();
  cmd->add_option("--mode", a->mode,
                  "paper: eq. (5) switching with 6-dim stacked residuals, printed recursion; "
                  "general: H from the platform angles in force (default)")
      ->check(CLI::IsMember({"paper", "general"}));
  cmd->add_option("--config", a->config,
                  "Estimator configuration, 'key: value' lines (units in the key names: _s, _deg, "
                  "_dps, _dps_rthz, _dps2; docs/estimator.md)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--calib", a->calib,
                  "Calibration file (calib.yaml) from 'driftless calibrate' (the matrices M per sensor and "
                  "end stop replace the hinge rotations) or from 'estimate --selfcal --calib-out'. Its G "
                  "(deg/s per g) and scale/misalignment E (fraction): with --selfcal the start value and "
                  "1-sigma of their states, else fixed corrections; the temperature states start at its "
                  "coefficients (deg/s per degC), the end-stop states at its end_stops (deg); docs/calibration.md")
      ->check(CLI::ExistingFile);
  auto* calib_out = cmd->add_option(
      "--calib-out", a->calib_out,
      "With --selfcal: write the estimated g-sensitivity (deg/s per g), scale/misalignment "
      "(fraction), bias temperature coefficients (deg/s per degC) and end-stop angle errors (deg), "
      "each with its 1-sigma, as "
      "calib.yaml for --calib on the next log of the same sensors (M stays nominal); docs/calibration.md");
  cmd->add_option("--prior-out", a->prior_out,
                  "With --calib-out: the same as a twin model-config file (a scenario's model: block; "
                  "compare/diagnose/render --model)")
      ->needs(calib_out);
  auto* corrected = cmd->add_flag("--corrected", a->corrected,
                "Also write corrected.csv: the corrected gyro and fused rates per log row (deg/s), about "
                "110 bytes a row (0.6 GB for a 14 h log at 100 Hz); the bias estimates are in estimate.csv "
                "either way");
  cmd->add_flag("--smooth", a->smooth,
                "With --corrected: corrected.csv from the offline fixed-interval (Rauch-Tung-Striebel) "
                "smoother over the whole log: the correction (deg/s) at every row uses the updates before "
                "and after it, so it has no steps between updates; a second pass over the log, rows marked "
                "smoothed = 1; docs/estimator.md section 6.3")
      ->needs(corrected);
  cmd->add_flag("--plot", a->plot,
                "Also write Fig. 4 (bias vs truth, deg/s), Fig. 5 (Allan deviation, deg/s vs s) and "
                "Fig. 9 (attitude error, deg vs s) as PNG + SVG with their gnuplot scripts");
  auto* selfcal = cmd->add_flag(
      "--selfcal", a->selfcal,
      "Self-calibrating mode: each sensor's g-sensitivity (deg/s per g, 9 states a sensor, driven by the "
      "log's accel columns or ref_q), scale/misalignment and end-stop angles are estimated with the bias; "
      "summary.json reports them with their sigma; docs/estimator.md section 1b. Without it the mode is "
      "chosen from the data: a six-state pass first, and a self-calibrating pass when its health shows an "
      "error a constant bias cannot absorb (section 1i)");
  cmd->add_flag("--no-selfcal", a->no_selfcal,
                "The six-state model (bias only) even where its health calls for the self-calibration: no "
                "second, self-calibrating pass (docs/estimator.md section 1i)")
      ->excludes(selfcal);
  cmd->add_flag("--box-at-rest", a->box_at_rest,
                "The box stands still on the Earth (a lab test): each standstill also measures the rate "
                "about 'up' (accel columns, else ref_q) as the vertical Earth rate at the log's latitude; "
                "with --selfcal this observes the bias common to both sensors about the vertical");
  cmd->add_flag("--strict", a->strict,
                "Exit 1 when the health verdict is 'degraded' too (gate rejections, NIS outside its "
                "band, unobservable components, re-locks); 'failed' (never locked) always exits 1");
  cmd->add_option("--tune", a->tune,
                  "auto: measure the noise density (deg/s/sqrt(Hz)) and the bias random walk "
                  "((deg/s)^2/s) from the log's standstills in a first pass and use them instead of "
                  "the configured ones; docs/estimator.md section 6.2")
      ->check(CLI::IsMember({"auto"}));
  cmd->add_option("--attitude-start-sigma", a->attitude_start_sigma_dps,
                  "deg/s: the attitude comparison (attitude.csv, Fig. 9, drift in deg/h) starts once "
                  "every bias sigma is below this, i.e. once the filter has locked on; there the "
                  "'bias fixed at start' integration takes the estimate and keeps it; 0 starts at "
                  "the log's first ref_q")
      ->capture_default_str()
      ->check(non_negative_number("deg/s"));
  return [a] { return run_estimate_cmd(*a); };
}, Interrupt::kPolls);

}  // namespace
}  // namespace driftless::cli
