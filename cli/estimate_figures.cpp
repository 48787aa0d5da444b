#include "cli/estimate_figures.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/core.h>

#include "report/gnuplot.hpp"
#include "report/plot_table.hpp"
#include "estimator/allan.hpp"

namespace driftless::cli {

namespace fs = std::filesystem;

void FigureSeries::add(const Sample& s, const est::SampleOutput& o) {
  if (!s.gyros_finite()) return;
  if (o.status == est::PushStatus::kMoving) platforms_moved = true;
  // fused body rate, holding the last value while no platform is at rest
  if (o.rate_body_dps.allFinite()) {
    last_rate_ = o.rate_body_dps;
    last_raw_rate_ = o.rate_body_raw_dps;
  }
  t_s.push_back(s.t_s);
  for (int i = 0; i < 3; ++i) {
    raw1[i].push_back(static_cast<float>(s.gyro1_dps[i]));
    cor1[i].push_back(static_cast<float>(o.y1c_dps[i]));
    raw_rate[i].push_back(static_cast<float>(last_raw_rate_[i]));
    cor_rate[i].push_back(static_cast<float>(last_rate_[i]));
  }
}

void FigureSeries::add_update(const est::UpdateRecord& r, const Sample& s) {
  if (!r.accepted) return;
  est::Vector6d truth;
  truth << s.true_bias1_dps, s.true_bias2_dps;
  updates.push_back({r.t_s, r.bias_dps - truth, r.sigma_dps});
}

int estimate_column(std::string_view name) {
  int col = 1;
  for (std::string_view list : {kEstimateColumns, kEstimateTruthColumns}) {
    for (std::size_t at = 0; at <= list.size(); ++col) {
      const std::size_t end = std::min(list.find(',', at), list.size());
      if (list.substr(at, end - at) == name) return col;
      at = end + 1;
    }
  }
  throw std::logic_error("estimate.csv has no column '" + std::string(name) + "'");
}

namespace {

constexpr const char* kAxisColour[3] = {"#d62728", "#2ca02c", "#1f77b4"};  // x, y, z
// titles use σ, ± and −
const std::string kUtf8 = "  set encoding utf8\n";
constexpr double kMinAllanSpanS = 10.0;  // s of data after lock that Fig. 5 needs (a few octaves of tau)

// estimate.csv columns (1-based), by name from the header the writer uses
int col_bias(int sensor, int axis) { return estimate_column(fmt::format("b{}_{}", sensor, "xyz"[axis])); }
int col_sigma(int sensor, int axis) { return estimate_column(fmt::format("sigma{}_{}", sensor, "xyz"[axis])); }
int col_truth(int sensor, int axis) { return estimate_column(fmt::format("true_bias{}_{}", sensor, "xyz"[axis])); }

// a dashed vertical line where the filter locked on
std::string lock_marker(double lock_s) {
  if (!std::isfinite(lock_s)) return "  unset arrow; unset label\n";
  return fmt::format(
      "  unset arrow; unset label\n"
      "  set arrow from {0:.3f}, graph 0 to {0:.3f}, graph 1 nohead dt 2 lw 1.5 lc rgb '#555555'\n"
      "  set label 'lock' at {0:.3f}, graph 0.93 offset 0.5,0 tc rgb '#555555'\n",
      lock_s);
}

// the largest |error| and 3 sigma of one sensor from `from_s` on (what the error panel must show)
double error_extent(const FigureSeries& sr, int sensor, double from_s) {
  double e = 0.0;
  for (const auto& u : sr.updates) {
    if (u.t_s < from_s) continue;
    for (int a = 0; a < 3; ++a) {
      const int i = 3 * (sensor - 1) + a;
      if (std::isfinite(u.error_dps[i])) e = std::max(e, std::abs(u.error_dps[i]));
      e = std::max(e, 3.0 * u.sigma_dps[i]);
    }
  }
  return e;
}

// Fig. 4 left: estimate - truth per axis with its +-3 sigma band, zoomed to the locked part
std::string fig4_error_panel(const FigureSeries& sr, int sensor, double lock_s) {
  const double from = std::isfinite(lock_s) ? lock_s : -1e300;
  const double y = 1.15 * std::max(error_extent(sr, sensor, from), 1e-6);
  std::string b = fmt::format(
      "  set title 'sensor {0}: estimate − truth, ±3σ dotted{1}'\n"
      "  set ylabel 'error [deg/s]'; set yrange [{2:.6g}:{3:.6g}]\n  plot ",
      sensor, std::isfinite(lock_s) ? " (axis fitted from lock)" : "", -y, y);
  for (int a = 0; a < 3; ++a) {
    b += fmt::format("'estimate.csv' using 1:(3*${0}) with lines dt 3 lw 1.5 lc rgb '{1}' notitle, "
                     "'' using 1:(-3*${0}) with lines dt 3 lw 1.5 lc rgb '{1}' notitle, ",
                     col_sigma(sensor, a), kAxisColour[a]);
  }
  for (int a = 0; a < 3; ++a) {
    b += fmt::format("'estimate.csv' using 1:(${}-${}) with linespoints pt 7 ps 0.5 lw 1.5 lc rgb '{}' title '{}'{}",
                     col_bias(sensor, a), col_truth(sensor, a), kAxisColour[a], "xyz"[a], a < 2 ? ", " : "\n");
  }
  return b;
}

// Fig. 4 right (or alone without truth): the estimates, with the truth dashed when known
std::string fig4_overlay_panel(int sensor, bool truth) {
  std::string b = fmt::format(
      "  set title 'sensor {}: estimate{}'\n  set ylabel 'bias [deg/s]'; set autoscale y\n  plot ", sensor,
      truth ? " (colour), truth (dark dashed)" : ", ±3σ dotted (no truth in the log)");
  for (int a = 0; a < 3; ++a) {
    if (!truth) {
      b += fmt::format("'estimate.csv' using 1:(${0}-3*${1}) with lines dt 3 lc rgb '{2}' notitle, "
                       "'' using 1:(${0}+3*${1}) with lines dt 3 lc rgb '{2}' notitle, ",
                       col_bias(sensor, a), col_sigma(sensor, a), kAxisColour[a]);
    }
    b += fmt::format("'estimate.csv' using 1:{} with linespoints pt 7 ps 0.5 lw 2 lc rgb '{}' title 'b{}_{}', ",
                     col_bias(sensor, a), kAxisColour[a], sensor, "xyz"[a]);
  }
  // the truth on top, dark and dashed, so it shows where the estimate covers it
  for (int a = 0; truth && a < 3; ++a) {
    b += fmt::format("'estimate.csv' using 1:{} with linespoints dt 2 lw 1.2 pt 2 ps 0.6 lc rgb '#222222' {}, ", col_truth(sensor, a),
                     a == 0 ? "title 'truth'" : "notitle");
  }
  b.resize(b.size() - 2);
  return b + "\n";
}

FigureOutcome fig4_bias(const fs::path& dir, const EstimateFigureInputs& in) {
  const FigureSeries& sr = *in.series;
  if (sr.updates.empty()) return {"fig4_bias", false, "the filter made no accepted update: no estimate to plot"};
  const double t0 = in.series->t_s.empty() ? sr.updates.front().t_s : in.series->t_s.front();
  std::string body = fmt::format(
      "  set multiplot layout 2,{} title 'Fig. 4: bias estimates of both sensors{}'\n"
      "  set xlabel 't [s]'; set xrange [{:.3f}:{:.3f}]; set offsets 0, 0, graph 0.05, graph 0.05\n"
      "  set key top right\n",
      in.truth ? 2 : 1,
      std::isfinite(in.lock_s) ? fmt::format(", lock at t = {:.1f} s", in.lock_s) : std::string(", never locked"),
      t0, in.series->t_s.empty() ? sr.updates.back().t_s : in.series->t_s.back());
  body += lock_marker(in.lock_s);
  for (int sensor = 1; sensor <= 2; ++sensor) {
    if (in.truth) body += fig4_error_panel(sr, sensor, in.lock_s);
    body += fig4_overlay_panel(sensor, in.truth);
  }
  body += "  unset multiplot\n";
  const std::string w = report::render(dir, report::Figure("fig4_bias", kUtf8 + body)).message;
  return {"fig4_bias", w.empty(), w};
}

// Allan deviation of six series (raw and corrected x, y, z) from sample `first` on
std::vector<report::AllanTableColumn> allan_columns(const FigureSeries& sr, std::size_t first, double rate_hz) {
  std::vector<report::AllanTableColumn> cols;
  est::AllanOptions opt;
  opt.sample_rate_hz = rate_hz;
  const bool fused = sr.platforms_moved;
  for (int pass = 0; pass < 2; ++pass) {
    for (int a = 0; a < 3; ++a) {
      const auto& src = fused ? (pass == 0 ? sr.raw_rate[a] : sr.cor_rate[a]) : (pass == 0 ? sr.raw1[a] : sr.cor1[a]);
      std::vector<double> x(src.begin() + static_cast<long>(first), src.end());
      const auto curve = est::allan_deviation(x, opt);
      report::AllanTableColumn c;
      c.name = fmt::format("{}{}_{}", pass == 0 ? "raw_" : "corrected_", fused ? "rate" : "gyro1", "xyz"[a]);
      for (const auto& p : curve.points) {
        c.tau_s.push_back(p.tau_s);
        c.adev.push_back(p.adev);
        c.lo.push_back(p.adev_lo);
        c.hi.push_back(p.adev_hi);
      }
      cols.push_back(std::move(c));
    }
  }
  return cols;
}

// Fig. 5: Allan deviation raw against corrected from lock on: sensor 1's axes on a static run
// (the paper's Fig. 5); when the platforms flip, the sensor outputs carry the flips, so the
// fused body rate
FigureOutcome fig5_allan(const fs::path& dir, const EstimateFigureInputs& in) {
  const FigureSeries& sr = *in.series;
  if (!std::isfinite(in.lock_s)) {
    return {"fig5_allan", false,
            "the filter never locked on: a corrected curve would mix in the samples from before the first estimate"};
  }
  if (!std::isfinite(in.sample_rate_hz)) return {"fig5_allan", false, "the sample rate is unknown"};
  const auto first = static_cast<std::size_t>(std::lower_bound(sr.t_s.begin(), sr.t_s.end(), in.lock_s) - sr.t_s.begin());
  const double span_s = sr.t_s.empty() || first >= sr.t_s.size() ? 0.0 : sr.t_s.back() - sr.t_s[first];
  if (span_s < kMinAllanSpanS) {
    return {"fig5_allan", false,
            fmt::format("only {:.1f} s of data after lock at {:.1f} s (needs {:.0f} s)", span_s, in.lock_s, kMinAllanSpanS)};
  }
  const auto cols = allan_columns(sr, first, in.sample_rate_hz);
  report::write_allan_table(dir / "allan_fig5.csv", cols);
  const double tau_lo = cols.front().tau_s.front(), tau_hi = cols.front().tau_s.back();
  std::string body = fmt::format(
      "  set logscale xy; set xlabel 'tau [s]'; set ylabel 'Allan deviation [deg/s]'; set xrange [{:.6g}:{:.6g}]\n"
      "  set title \"Fig. 5: Allan deviation of {} from lock (t ≥ {:.1f} s, {:.0f} s of data)\\n"
      "raw dashed, DriftLess-corrected solid, bands: 68 % confidence intervals\"\n  plot ",
      tau_lo / 1.3, tau_hi * 1.3, sr.platforms_moved ? "the fused body rate" : "sensor 1", in.lock_s, span_s);
  for (int i = 0; i < 6; ++i) {
    const int c = 2 + 3 * i;  // adev, then lo and hi
    body += fmt::format("'allan_fig5.csv' using 1:{}:{} with filledcurves fs transparent solid 0.12 noborder lc rgb "
                        "'{}' notitle, '' using 1:{} with linespoints pt {} ps 0.7 lw 1.5 dt {} lc rgb '{}' title "
                        "columnhead({}){}",
                        c + 1, c + 2, kAxisColour[i % 3], c, i < 3 ? 6 : 7, i < 3 ? 2 : 1, kAxisColour[i % 3], c,
                        i < 5 ? ", " : "\n");
  }
  const std::string w = report::render(dir, report::Figure("fig5_allan", kUtf8 + body)).message;
  return {"fig5_allan", w.empty(), w};
}

// Fig. 9: attitude error with DriftLess and with the bias fixed at lock, from the comparison's start
FigureOutcome fig9_attitude(const fs::path& dir, const EstimateFigureInputs& in) {
  if (!in.attitude) return {"fig9_attitude", false, "the log has no reference attitude (ref_q columns)"};
  if (!std::isfinite(in.lock_s) || !std::isfinite(in.attitude_start_s)) {
    return {"fig9_attitude", false,
            fmt::format("the filter never locked on (never had every bias sigma below {:g} deg/s), so there is "
                        "no attitude comparison",
                        in.start_sigma_dps)};
  }
  const double t0 = in.attitude_start_s;
  const double t_end = in.series != nullptr && !in.series->t_s.empty() ? in.series->t_s.back() : kNaN;
  std::string body = fmt::format(
      "  set xlabel 't [s]'; set ylabel 'attitude error [deg]'; set offsets 0, 0, graph 0.05, graph 0.05\n"
      "  set title \"Fig. 9: attitude error, integrated from ref_q at lock (t = {0:.1f} s)\\n"
      "bias fixed at lock (red) against DriftLess (blue)\"\n  set key below maxrows 3 height 1.5\n{1}",
      t0, lock_marker(t0));
  if (std::isfinite(t_end) && t_end > t0) {
    body += fmt::format("  set xrange [{:.3f}:{:.3f}]\n", t0 - 0.02 * (t_end - t0), t_end);
  }
  static constexpr const char* kAngle[3] = {"roll", "pitch", "heading"};
  body += "  plot ";
  for (int a = 0; a < 3; ++a) {
    body += fmt::format("'attitude.csv' using 1:{} with lines lw 1.5 dt {} lc rgb 'red' title '{}, bias fixed at lock', ",
                        10 + a, a + 1, kAngle[a]);
  }
  for (int a = 0; a < 3; ++a) {
    body += fmt::format("'attitude.csv' using 1:{} with lines lw 2 dt {} lc rgb 'blue' title '{}, DriftLess (running "
                        "estimate)'{}",
                        2 + a, a + 1, kAngle[a], a < 2 ? ", " : "\n");
  }
  const std::string w = report::render(dir, report::Figure("fig9_attitude", kUtf8 + body)).message;
  return {"fig9_attitude", w.empty(), w};
}

}  // namespace

std::vector<FigureOutcome> write_estimate_figures(const fs::path& dir, const EstimateFigureInputs& in) {
  static const FigureSeries kNone;
  EstimateFigureInputs use = in;
  if (use.series == nullptr) use.series = &kNone;
  std::vector<FigureOutcome> out = {fig4_bias(dir, use), fig5_allan(dir, use), fig9_attitude(dir, use)};
  // a figure that could not be drawn leaves nothing that looks like it (an earlier run's files go)
  for (const auto& o : out) {
    if (o.written) continue;
    for (const char* ext : {".png", ".svg"}) fs::remove(dir / (o.stem + ext));
  }
  return out;
}

}  // namespace driftless::cli
