// driftless estimate: run the DriftLess filter over a measurement log and write the bias
// estimates, corrected outputs, attitude drift and (for simulated logs) errors against truth.
// Formats: docs/estimator.md.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <fmt/format.h>
#include <fmt/os.h>

#include "calibration/calib_file.hpp"
#include "cli/command.hpp"
#include "cli/estimate_figures.hpp"
#include "cli/estimate_health.hpp"
#include "estimator/calibration.hpp"
#include "estimator/pipeline.hpp"
#include "estimator/tune.hpp"
#include "report/json.hpp"

namespace driftless::cli {
namespace {

namespace fs = std::filesystem;

struct EstimateArgs {
  std::string log;
  std::string out;
  std::string mode;  // empty = config / general
  std::string config;
  std::string calib;  // calib.yaml from driftless calibrate (docs/calibration.md)
  bool plot = false;
  bool strict = false;    // exit 1 on a degraded health verdict too (failed always exits 1)
  std::string tune;       // "auto": noise density and bias wander from the log (docs/estimator.md section 6.2)
  double attitude_start_sigma_dps = est::EstimateRunOptions{}.attitude_start_sigma_dps;
};

// "%.9f" but NaN -> empty field (the log format's "no value")
void put(fmt::memory_buffer& b, double v, int decimals) {
  if (std::isfinite(v)) fmt::format_to(std::back_inserter(b), ",{:.{}f}", v, decimals);
  else b.push_back(',');
}

using report::json_number;
using report::json_string;

std::string json_vec(const est::Vector6d& v) {
  return fmt::format("[{}, {}, {}, {}, {}, {}]", json_number(v[0]), json_number(v[1]), json_number(v[2]),
                     json_number(v[3]), json_number(v[4]), json_number(v[5]));
}

// writes the per-sample and per-update files while the pass runs
class FileSink : public est::EstimateSink {
 public:
  FileSink(const fs::path& dir, bool truth, bool keep_series)
      : corrected_(fmt::output_file((dir / "corrected.csv").string())),
        estimate_(fmt::output_file((dir / "estimate.csv").string())),
        attitude_(fmt::output_file((dir / "attitude.csv").string())),
        truth_(truth),
        keep_series_(keep_series) {
    corrected_.print("t,y1c_x,y1c_y,y1c_z,y2c_x,y2c_y,y2c_z,rate_x,rate_y,rate_z,status\n");
    estimate_.print(
        "t,b1_x,b1_y,b1_z,b2_x,b2_y,b2_z,sigma1_x,sigma1_y,sigma1_z,sigma2_x,sigma2_y,sigma2_z,"
        "nis,nis_gate,dim,samples,plat1_deg,plat2_deg,accepted{}\n",
        truth ? ",true_bias1_x,true_bias1_y,true_bias1_z,true_bias2_x,true_bias2_y,true_bias2_z" : "");
    attitude_.print(
        "t,roll_err_deg,pitch_err_deg,heading_err_deg,angle_err_deg,"
        "raw_roll_err_deg,raw_pitch_err_deg,raw_heading_err_deg,raw_angle_err_deg,"
        "fixed_roll_err_deg,fixed_pitch_err_deg,fixed_heading_err_deg,fixed_angle_err_deg,"
        "accumulated_err_deg,raw_accumulated_err_deg,fixed_accumulated_err_deg\n");
  }

  void on_sample(const Sample& s, const est::SampleOutput& o) override {
    auto& b = buf_;
    fmt::format_to(std::back_inserter(b), "{:.6f}", s.t_s);
    for (int i = 0; i < 3; ++i) put(b, o.y1c_dps[i], 7);
    for (int i = 0; i < 3; ++i) put(b, o.y2c_dps[i], 7);
    for (int i = 0; i < 3; ++i) put(b, o.rate_body_dps[i], 7);
    fmt::format_to(std::back_inserter(b), ",{}\n", est::to_string(o.status));
    if (b.size() > (1u << 20)) flush();
    if (keep_series_) series_.add(s, o);
  }

  void on_update(const est::UpdateRecord& r, const est::Matrix6d&, const Sample& s) override {
    fmt::memory_buffer b;
    fmt::format_to(std::back_inserter(b), "{:.6f}", r.t_s);
    for (int i = 0; i < 6; ++i) put(b, r.bias_dps[i], 9);
    for (int i = 0; i < 6; ++i) put(b, r.sigma_dps[i], 9);
    put(b, r.nis, 6);
    put(b, r.nis_gate, 6);
    fmt::format_to(std::back_inserter(b), ",{},{}", r.dim, r.samples);
    put(b, r.plat1_deg, 3);
    put(b, r.plat2_deg, 3);
    fmt::format_to(std::back_inserter(b), ",{}", r.accepted ? 1 : 0);
    if (truth_) {
      for (int i = 0; i < 3; ++i) put(b, s.true_bias1_dps[i], 9);
      for (int i = 0; i < 3; ++i) put(b, s.true_bias2_dps[i], 9);
    }
    b.push_back('\n');
    estimate_.print("{}", fmt::to_string(b));
    if (keep_series_) series_.add_update(r, s);
  }

  void on_attitude(const est::AttitudePoint& p) override {
    attitude_.print("{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},"
                    "{:.6f},{:.6f},{:.6f},{:.6f}\n",
                    p.t_s, p.corrected.roll_deg, p.corrected.pitch_deg, p.corrected.heading_deg,
                    p.corrected.angle_deg, p.raw.roll_deg, p.raw.pitch_deg, p.raw.heading_deg,
                    p.raw.angle_deg, p.fixed.roll_deg, p.fixed.pitch_deg, p.fixed.heading_deg,
                    p.fixed.angle_deg, p.corrected_accumulated_deg, p.raw_accumulated_deg,
                    p.fixed_accumulated_deg);
  }

  void flush() {
    corrected_.print("{}", std::string_view(buf_.data(), buf_.size()));
    buf_.clear();
  }
  void close() {
    flush();
    corrected_.close();
    estimate_.close();
    attitude_.close();
  }

  const FigureSeries& series() const { return series_; }

 private:
  FigureSeries series_;
  fmt::ostream corrected_, estimate_, attitude_;
  fmt::memory_buffer buf_;
  bool truth_;
  bool keep_series_;
};

// "figures": what --plot drew, and why a figure was left out
std::string json_figures(const std::vector<FigureOutcome>& figures) {
  std::string o = "[";
  for (std::size_t i = 0; i < figures.size(); ++i) {
    const auto& f = figures[i];
    o += fmt::format("{}{{\"name\": {}, \"written\": {}, \"reason\": {}}}", i ? ", " : "", json_string(f.stem),
                     f.written ? "true" : "false", f.written ? "null" : json_string(f.reason));
  }
  return o + "]";
}

// "tune": what --tune auto measured (null without it)
std::string json_tune(const est::TuneResult* t) {
  if (t == nullptr) return "null";
  return fmt::format("{{\"block_s\": {}, \"noise_block_pairs\": {}, \"noise_estimated\": {}, "
                     "\"noise_density_dps_rthz\": {}, \"wander_pairs\": {}, \"q_estimated\": {}, "
                     "\"q_dps2_per_s\": {}}}",
                     json_number(t->block_s), t->noise_block_pairs, t->noise_estimated ? "true" : "false",
                     json_number(t->noise_density_dps_rthz), t->wander_pairs, t->q_estimated ? "true" : "false",
                     json_number(t->q_dps2_per_s));
}

void write_summary(const fs::path& path, const EstimateArgs& a, const est::EstimatorConfig& cfg,
                   const est::EstimateSummary& s, const std::vector<FigureOutcome>& figures,
                   const est::TuneResult* tune) {
  auto o = fmt::output_file(path.string());
  o.print("{{\n");
  o.print("  \"log\": {},\n", json_string(a.log));
  o.print("  \"mode\": \"{}\",\n", cfg.mode == est::FilterMode::kPaper ? "paper" : "general");
  o.print("  \"rows\": {},\n  \"rows_missing_gyro\": {},\n", s.rows, s.rows_missing_gyro);
  o.print("  \"log_complete\": {},\n", s.log_complete ? "true" : "false");
  o.print("  \"t_first_s\": {}, \"t_last_s\": {},\n", json_number(s.t_first_s), json_number(s.t_last_s));
  o.print("  \"updates\": {}, \"rejected\": {}, \"standstills_too_short\": {}, \"schedule_mismatches\": {},\n",
          s.counters.updates, s.counters.rejected, s.counters.standstills_too_short,
          s.counters.schedule_mismatches);
  o.print("  \"final_bias_dps\": {},\n", json_vec(s.bias_dps));
  o.print("  \"final_sigma_dps\": {},\n", json_vec(s.sigma_dps));
  o.print("  \"attitude_start_s\": {},\n", json_number(s.attitude_start_s));
  o.print("  \"attitude_drift_deg_per_h\": {{\"with_driftless\": {}, \"bias_fixed_at_start\": {}, "
          "\"without_driftless\": {}}},\n",
          json_number(s.drift_corrected_deg_per_h), json_number(s.drift_fixed_deg_per_h),
          json_number(s.drift_raw_deg_per_h));
  o.print("  \"final_attitude_error_deg\": {{\"with_driftless\": {}, \"bias_fixed_at_start\": {}, "
          "\"without_driftless\": {}}},\n",
          json_number(s.final_corrected.angle_deg), json_number(s.final_fixed.angle_deg),
          json_number(s.final_raw.angle_deg));
  o.print("  \"fixed_bias_dps\": {},\n", json_vec(s.fixed_bias_dps));
  o.print("  \"relocks\": [");
  for (std::size_t i = 0; i < s.relocks.size(); ++i) {
    o.print("{}{{\"t_s\": {}, \"nis\": {}}}", i ? ", " : "", json_number(s.relocks[i].t_s),
            json_number(s.relocks[i].nis));
  }
  o.print("],\n");
  if (s.truth.available) {
    const auto& t = s.truth;
    o.print("  \"truth\": {{\n");
    o.print("    \"updates_evaluated\": {},\n", t.updates);
    o.print("    \"bias_error_rms_dps\": {},\n", json_number(t.bias_error_rms_dps));
    o.print("    \"bias_error_rms_second_half_dps\": {},\n", json_number(t.bias_error_rms_second_half_dps));
    o.print("    \"final_bias_error_dps\": {},\n", json_vec(t.final_error_dps));
    o.print("    \"within_3sigma_fraction\": {},\n", json_number(t.within_3sigma_fraction));
    o.print("    \"nees\": {{\"dof\": 6, \"mean\": {}, \"mean_band_95\": [{}, {}], \"single_band_95\": [{}, {}], "
            "\"fraction_in_single_band\": {}}}\n",
            json_number(t.nees_mean), json_number(t.nees_mean_band_lo), json_number(t.nees_mean_band_hi),
            json_number(t.nees_band_lo), json_number(t.nees_band_hi), json_number(t.nees_fraction_in_band));
    o.print("  }},\n");
  }
  o.print("  \"bias_error_rms_dps\": {},\n", json_number(s.truth.bias_error_rms_dps));
  o.print("{},\n", health_json(s.health, cfg));
  o.print("  \"tune\": {},\n", json_tune(tune));
  o.print("  \"figures\": {},\n", json_figures(figures));
  o.print("  \"warnings\": [");
  for (std::size_t i = 0; i < s.warnings.size(); ++i) o.print("{}{}", i ? ", " : "", json_string(s.warnings[i]));
  o.print("]\n}}\n");
}

bool stop_polled() { return stop_requested().load(); }

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
             t.q_estimated ? fmt::format("{:.4g} (deg/s)^2/s", t.q_dps2_per_s) : "not measured, configured value kept",
             t.wander_pairs);
  return t;
}

// the health verdict on the console; the exit code: failed always 1, degraded 1 with --strict
int report_health(const EstimateArgs& a, const est::EstimatorConfig& cfg, const est::HealthReport& h) {
  const auto lines = health_lines(h, cfg);
  const bool bad = h.verdict != est::HealthVerdict::kOk;
  for (const auto& l : lines) fmt::print(bad ? stderr : stdout, "{}{}\n", bad ? "driftless estimate: " : "  ", l);
  if (h.verdict == est::HealthVerdict::kFailed) {
    fmt::print(stderr, "driftless estimate: the filter never locked: the estimates are not usable (exit 1)\n");
    return 1;
  }
  if (h.verdict == est::HealthVerdict::kDegraded && a.strict) {
    fmt::print(stderr, "driftless estimate: health degraded and --strict given (exit 1)\n");
    return 1;
  }
  return 0;
}

int run_estimate_cmd(const EstimateArgs& a) {
  est::EstimatorConfig cfg;
  if (!a.config.empty()) {
    std::ifstream in(a.config);
    if (!in) throw std::runtime_error("cannot read --config " + a.config);
    cfg = est::parse_estimator_config(in, a.config, a.mode == "paper" ? est::paper_config() : est::EstimatorConfig{});
  } else if (a.mode == "paper") {
    cfg = est::paper_config();
  }
  if (!a.mode.empty()) est::set_config_value(cfg, "mode", a.mode);
  log::LogReader reader(a.log);
  // --calib: the calibrated matrices M replace R in eq. (1)-(2) (docs/calibration.md)
  if (!a.calib.empty()) {
    const calib::CalibFile c = calib::load_calib(a.calib);
    const auto& meta = reader.metadata();
    if ((c.hinge1_axis.normalized() - meta.hinge1_axis().normalized()).norm() > 1e-6 ||
        (c.hinge2_axis.normalized() - meta.hinge2_axis().normalized()).norm() > 1e-6) {
      throw std::invalid_argument(fmt::format(
          "--calib {}: calibrated for hinge axes [{} {} {}] / [{} {} {}] but the log {} has [{} {} {}] / "
          "[{} {} {}]: not the same box", a.calib, c.hinge1_axis.x(), c.hinge1_axis.y(), c.hinge1_axis.z(),
          c.hinge2_axis.x(), c.hinge2_axis.y(), c.hinge2_axis.z(), a.log, meta.hinge1_axis().x(),
          meta.hinge1_axis().y(), meta.hinge1_axis().z(), meta.hinge2_axis().x(), meta.hinge2_axis().y(),
          meta.hinge2_axis().z()));
    }
    cfg.calibration = est::to_filter_calibration(c.M);
    // y <- y - G f / g with the log's accelerometer columns (samples without them stay as they are)
    if (c.has_g_sensitivity) cfg.calibration.G_dps_per_g = c.G_dps_per_g;
  }
  cfg.validate();
  est::TuneResult tune;
  if (a.tune == "auto") tune = tune_config(a, cfg);

  const bool truth = (reader.fields() & kFieldTrueBias) != 0;
  const bool attitude = (reader.fields() & kFieldRefQ) != 0;
  fs::create_directories(a.out);
  const fs::path dir(a.out);
  {
    std::ofstream used(dir / "config_used.txt");
    est::write_estimator_config(used, cfg);
  }
  FileSink sink(dir, truth, a.plot);
  Progress progress("estimate");
  struct ProgressSink : est::EstimateSink {
    FileSink* inner;
    Progress* p;
    double t_end;
    std::uint64_t n = 0;
    void on_sample(const Sample& s, const est::SampleOutput& o) override {
      inner->on_sample(s, o);
      if ((++n & 8191u) == 0 && std::isfinite(t_end) && t_end > 0) p->update(std::min(1.0, s.t_s / t_end));
    }
    void on_update(const est::UpdateRecord& r, const est::Matrix6d& P, const Sample& s) override {
      inner->on_update(r, P, s);
    }
    void on_attitude(const est::AttitudePoint& ap) override { inner->on_attitude(ap); }
  } ps;
  ps.inner = &sink;
  ps.p = &progress;
  ps.t_end = reader.metadata().get_number("duration_s", kNaN);
  est::EstimateRunOptions run_opt;
  run_opt.attitude_start_sigma_dps = a.attitude_start_sigma_dps;
  const auto summary = est::run_estimate(reader, cfg, &ps, run_opt, &stop_polled);
  sink.close();
  progress.done(fmt::format("{} rows, {} updates", summary.rows, summary.counters.updates));

  auto warnings = summary.warnings;
  std::vector<FigureOutcome> figures;
  if (a.plot) {
    double rate = reader.metadata().sample_rate_hz();
    if (!std::isfinite(rate) && summary.rows > 1) rate = double(summary.rows - 1) / (summary.t_last_s - summary.t_first_s);
    EstimateFigureInputs fig{&sink.series(), truth, attitude, rate, summary.attitude_start_s,
                             a.attitude_start_sigma_dps};
    figures = write_estimate_figures(dir, fig);
    for (const auto& f : figures) {
      if (!f.written) warnings.push_back(fmt::format("{} not drawn: {}", f.stem, f.reason));
    }
  }
  auto final_summary = summary;
  final_summary.warnings = warnings;
  write_summary(dir / "summary.json", a, cfg, final_summary, figures, a.tune == "auto" ? &tune : nullptr);

  for (const auto& w : warnings) fmt::print(stderr, "driftless estimate: warning: {}\n", w);
  const auto& b = summary.bias_dps;
  const auto& sg = summary.sigma_dps;
  fmt::print("{}: {} rows, {} updates ({} rejected)\n", a.log, summary.rows, summary.counters.updates,
             summary.counters.rejected);
  fmt::print("  b1 = ({:+.5f}, {:+.5f}, {:+.5f}) +- ({:.5f}, {:.5f}, {:.5f}) deg/s\n", b[0], b[1], b[2], sg[0],
             sg[1], sg[2]);
  fmt::print("  b2 = ({:+.5f}, {:+.5f}, {:+.5f}) +- ({:.5f}, {:.5f}, {:.5f}) deg/s\n", b[3], b[4], b[5], sg[3],
             sg[4], sg[5]);
  if (summary.attitude_available) {
    fmt::print("  attitude drift from t = {:.1f} s: {:.2f} deg/h with DriftLess, {:.2f} deg/h with the bias "
               "fixed at that start, {:.2f} deg/h uncorrected\n",
               summary.attitude_start_s, summary.drift_corrected_deg_per_h, summary.drift_fixed_deg_per_h,
               summary.drift_raw_deg_per_h);
  }
  if (truth && summary.truth.updates > 0) {
    fmt::print("  against truth: bias error rms {:.5f} deg/s over all updates ({:.5f} over the second half), "
               "mean NEES {:.2f} (95 % band {:.2f}..{:.2f})\n",
               summary.truth.bias_error_rms_dps, summary.truth.bias_error_rms_second_half_dps,
               summary.truth.nees_mean, summary.truth.nees_mean_band_lo, summary.truth.nees_mean_band_hi);
  }
  fmt::print("  wrote {}/{{estimate.csv, corrected.csv, attitude.csv, summary.json}}\n", a.out);
  std::fflush(stdout);
  return report_health(a, cfg, summary.health);
}

const bool registered = register_command(30, [](CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "estimate", "Run the DriftLess bias filter over a measurement log: bias estimates (deg/s), "
                  "corrected outputs, attitude drift (deg/h); docs/estimator.md");
  auto a = std::make_shared<EstimateArgs>();
  cmd->add_option("--log", a->log, "Measurement log (CSV, driftless-log 1; docs/log-format.md)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", a->out, "Output folder (created): estimate.csv, corrected.csv, summary.json")
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
                  "Calibration file from 'driftless calibrate' (calib.yaml): the matrices M per "
                  "sensor and end stop (deg/s in, deg/s out) replace the hinge rotations; "
                  "docs/calibration.md")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--plot", a->plot,
                "Also write Fig. 4 (bias vs truth, deg/s), Fig. 5 (Allan deviation, deg/s vs s) and "
                "Fig. 9 (attitude error, deg vs s) as PNG + SVG with their gnuplot scripts");
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
      ->check(CLI::NonNegativeNumber);
  return [a] { return run_estimate_cmd(*a); };
});

}  // namespace
}  // namespace driftless::cli
