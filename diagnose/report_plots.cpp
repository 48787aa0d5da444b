// The report's plots: gnuplot data and scripts under DIR/plots/, drawn to PNG.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include <fmt/core.h>

#include "diagnose/parallel.hpp"
#include "diagnose/report_plots.hpp"
#include "diagnose/report_text.hpp"
#include "estimator/output_file.hpp"
#include "report/json.hpp"

namespace driftless::diagnose {
namespace {

using report_text::gnuplot_png;
std::string n(double v) { return report::json_number(v); }

// a long log has more blocks than the plot has pixels (1 h at 0.1 s: 36 000 per channel, and
// gnuplot took over a second on them): above kPlotBuckets * 2 blocks the residual is drawn as a
// band per channel, from the smallest to the largest block mean of each of kPlotBuckets time
// bins (the cloud the points would make), with the bin's mean smoothed bias
constexpr std::size_t kPlotBuckets = 1500;

// writes DIR/NAME (before gnuplot reads it), a line or none per item as `line` makes it
template <class Items, class Line>
std::filesystem::path write_dat(const std::filesystem::path& dir, const char* name, const Items& items, Line&& line) {
  std::ostringstream d;
  for (const auto& item : items) line(d, item);
  const auto dat = dir / name;
  io::write_file(dat, d.str());
  return dat;
}

struct PlotRow {
  double t_s;
  std::array<double, 6> lo_dps, hi_dps, bias_dps;  // lo = hi = the block mean when not binned
};

PlotRow bin_row(const CompareResult& r, std::size_t a, std::size_t e) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  PlotRow row{r.block_t_s[(a + e - 1) / 2], {}, {}, {}};
  for (int c = 0; c < 6; ++c) {
    double mn = kNaN, mx = kNaN, bias = 0.0;
    for (std::size_t b = a; b < e; ++b) {
      const double v = r.block_residual_dps[c][b];
      bias += r.block_bias_dps[c][b];
      if (!std::isfinite(v)) continue;
      mn = std::isfinite(mn) ? std::min(mn, v) : v;
      mx = std::isfinite(mx) ? std::max(mx, v) : v;
    }
    row.lo_dps[c] = mn, row.hi_dps[c] = mx, row.bias_dps[c] = bias / static_cast<double>(e - a);
  }
  return row;
}

// rows of the residual plot; true in `binned` when they are bins (a band), false for blocks
std::vector<PlotRow> residual_rows(const CompareResult& r, bool* binned) {
  const std::size_t m = r.block_t_s.size();
  *binned = m > 2 * kPlotBuckets;
  const std::size_t bins = *binned ? kPlotBuckets : m;
  std::vector<PlotRow> rows;
  for (std::size_t k = 0; k < bins; ++k) rows.push_back(bin_row(r, k * m / bins, (k + 1) * m / bins));
  return rows;
}

// residual after the selected effects and the smoothed bias (points, or bands on a long log),
// per sensor; the smoothed bias itself below (it is a nuisance, drawn so its size is visible)
Plot residual_plot(const CompareResult& r, const std::filesystem::path& dir) {
  const auto dat = dir / "residual.dat";
  bool binned = false;
  {
    std::ostringstream d;
    for (const PlotRow& row : residual_rows(r, &binned)) {
      d << fmt::format("{:.3f}", row.t_s);
      for (int c = 0; c < 6; ++c) d << ' ' << n(row.lo_dps[c]) << ' ' << n(row.hi_dps[c]) << ' ' << n(row.bias_dps[c]);
      d << '\n';
    }
    io::write_file(dat, d.str());  // before gnuplot reads it
  }
  // a single-sensor log draws sensor 1 only (sensor 2's columns are null)
  const std::string file = dat.filename().string();
  std::string s = fmt::format("set termoption noenhanced\nset multiplot layout {},1\nset xlabel 't (s)'\nset key outside right\n"
                              "set datafile missing 'null'\nset style fill transparent solid 0.35 noborder\n", r.sensors + 1);
  for (int sn = 0; sn < r.sensors; ++sn) {
    s += fmt::format("set ylabel 'deg/s'\nset title 'sensor {}: block-mean residual after the selected effects and the "
                     "smoothed bias{}'\nplot ", sn + 1, binned ? fmt::format(" (band: its range in each of {} time bins)", kPlotBuckets) : "");
    for (int a = 0; a < 3; ++a) {
      const int c = sn * 3 + a, col = 2 + 3 * c;
      s += binned ? fmt::format("'{}' u 1:{}:{} w filledcurves lc {} t '{}'", file, col, col + 1, a + 1, channel_name(c))
                  : fmt::format("'{}' u 1:{} w p pt 7 ps 0.25 lc {} t '{}'", file, col, a + 1, channel_name(c));
      s += a < 2 ? ", " : "\n";
    }
  }
  s += "set title 'smoothed bias (nuisance: turn-on bias and drift)'\nplot ";
  const int nc = 3 * r.sensors;
  for (int c = 0; c < nc; ++c) s += fmt::format("'{}' u 1:{} w l t '{}'{}", file, 4 + 3 * c, channel_name(c), c < nc - 1 ? ", " : "\n");
  s += "unset multiplot\n";
  return {"Residual over time", gnuplot_png(dir, "residual", s, 900, 720)};
}

Plot windows_plot(const CompareResult& r, const std::filesystem::path& dir) {
  const auto dat = write_dat(dir, "windows.dat", r.windows, [&](std::ostringstream& d, const WindowSummary& w) {
    d << fmt::format("{:.3f}", 0.5 * (w.t0_s + w.t1_s));
    for (int c = 0; c < 6; ++c) d << ' ' << n(w.rms_dps[c]) << ' ' << n(r.channels[c].noise_floor_dps);
    d << '\n';
  });
  std::string s = "set termoption noenhanced\nset xlabel 't (s)'\nset ylabel 'rms (deg/s)'\nset yrange [0:*]\nset key outside right\n"
                  "set title 'windowed residual rms after the selected effects (dashed: the model noise floor)'\nplot ";
  const int nc = 3 * r.sensors;
  for (int c = 0; c < nc; ++c) {
    s += fmt::format("'{0}' u 1:{1} w lp lc {3} t '{2}', '' u 1:{4} w l dt 2 lc {3} notitle{5}", dat.filename().string(), 2 + 2 * c,
                     channel_name(c), c + 1, 3 + 2 * c, c < nc - 1 ? ", " : "\n");
  }
  return {"Windowed residual RMS", gnuplot_png(dir, "windows", s)};
}

// per sensor: the residual's ADEV with its 95 % interval (error bars) against the model's
// ADEV and its 95 % band for a record this long
Plot allan_plot(const CompareResult& r, const std::filesystem::path& dir) {
  const auto dat = dir / "adev.dat";
  {
    std::ostringstream d;
    std::size_t np = 0;
    for (const auto& ch : r.channels) np = std::max(np, ch.adev.points.size());
    for (std::size_t i = 0; i < np; ++i) {
      for (int c = 0; c < 6; ++c) {
        const auto& ch = r.channels[c];
        if (i < ch.adev.points.size() && i < ch.adev_model.size()) {
          const auto& p = ch.adev.points[i];
          d << n(p.tau_s) << ' ' << n(p.adev) << ' ' << n(p.adev_lo) << ' ' << n(p.adev_hi) << ' ' << n(ch.adev_model[i]) << ' '
            << n(ch.adev_model_lo[i]) << ' ' << n(ch.adev_model_hi[i]) << ' ';
        } else {
          d << "null null null null null null null ";
        }
      }
      d << '\n';
    }
    io::write_file(dat, d.str());  // before gnuplot reads it
  }
  std::string s = fmt::format("set termoption noenhanced\nset multiplot layout 1,{}\nset logscale xy\nset xlabel 'tau (s)'\n"
                              "set ylabel 'ADEV (deg/s)'\nset key bottom left\nset datafile missing 'null'\n"
                              "set style fill transparent solid 0.2 noborder\n", r.sensors);
  for (int sn = 0; sn < r.sensors; ++sn) {
    s += fmt::format("set title 'sensor {}: residual (95 % CI) and model (95 % band)'\nplot ", sn + 1);
    for (int a = 0; a < 3; ++a) {
      const int c = sn * 3 + a, o = 7 * c;
      s += fmt::format("'{0}' u {1}:{6}:{7} w filledcurves lc {8} notitle, '' u {1}:{5} w l lc {8} dt 2 t '{9} model', "
                       "'' u {1}:{2}:{3}:{4} w yerrorbars pt 7 ps 0.5 lc {8} t '{9}'{10}",
                       dat.filename().string(), o + 1, o + 2, o + 3, o + 4, o + 5, o + 6, o + 7, a + 1, channel_name(c), a < 2 ? ", " : "\n");
    }
  }
  s += "unset multiplot\n";
  return {"Allan deviation", gnuplot_png(dir, "adev", s, 1100, 460)};
}

// bars from zero: the residual rms after the selected effects by regime
Plot regimes_plot(const CompareResult& r, const std::filesystem::path& dir) {
  const auto dat = write_dat(dir, "regimes.dat", r.regimes, [&](std::ostringstream& d, const RegimeSummary& g) {
    if (g.group == "flip" && g.name == "during flips") return;  // no truth there: in the table only
    d << '"' << g.group << ": " << g.name << '"';
    for (int c = 0; c < 6; ++c) d << ' ' << n(g.rms_dps[c]);
    d << '\n';
  });
  std::string s = "set termoption noenhanced\nset style data histograms\nset style histogram clustered gap 1\n"
                  "set style fill solid 0.8\n"
                  "set yrange [0:*]\nset xtics rotate by -30\nset ylabel 'rms (deg/s)'\nset key outside right\n"
                  "set title 'residual rms by regime, after the selected effects (during flips: table only, no truth there)'\nplot ";
  const int nc = 3 * r.sensors;
  for (int c = 0; c < nc; ++c) s += fmt::format("'{}' u {}:xtic(1) t '{}'{}", dat.filename().string(), 2 + c, channel_name(c), c < nc - 1 ? ", " : "\n");
  return {"Residual by regime", gnuplot_png(dir, "regimes", s, 900, 480)};
}

}  // namespace

std::vector<Plot> draw_plots(const CompareResult& r, const std::filesystem::path& plot_dir) {
  std::filesystem::create_directories(plot_dir);
  // each figure is its own data file, script and gnuplot process: they are drawn side by side
  // on the machine's cores (0.1 s of gnuplot each), in this order in the report
  using Draw = Plot (*)(const CompareResult&, const std::filesystem::path&);
  static constexpr std::array<Draw, 4> kDraw = {residual_plot, windows_plot, allan_plot, regimes_plot};
  std::vector<Plot> plots(kDraw.size());
  for_each_index(static_cast<int>(kDraw.size()), [&](int i) {
    plots[static_cast<std::size_t>(i)] = kDraw[static_cast<std::size_t>(i)](r, plot_dir);
  });
  return plots;
}

}  // namespace driftless::diagnose
