#include "cli/estimate_figures.hpp"

#include <cmath>

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
  for (int i = 0; i < 3; ++i) {
    raw1[i].push_back(static_cast<float>(s.gyro1_dps[i]));
    cor1[i].push_back(static_cast<float>(o.y1c_dps[i]));
    raw_rate[i].push_back(static_cast<float>(last_raw_rate_[i]));
    cor_rate[i].push_back(static_cast<float>(last_rate_[i]));
  }
}

namespace {

// Fig. 4: bias estimate (and truth) against time, one panel per sensor
std::string fig4_bias(const fs::path& dir, bool truth) {
  std::string body = "  set multiplot layout 2,1 title 'Fig. 4: bias estimates'\n"
                     "  set xlabel 't [s]'; set ylabel 'bias [deg/s]'\n";
  for (int sensor = 1; sensor <= 2; ++sensor) {
    const int c0 = sensor == 1 ? 2 : 5;
    body += fmt::format("  set title 'sensor {}'\n  plot ", sensor);
    static constexpr const char* kColour[3] = {"#d62728", "#2ca02c", "#1f77b4"};
    for (int a = 0; a < 3; ++a) {
      body += fmt::format("'estimate.csv' using 1:{} with lines lw 2 lc rgb '{}' title 'b{}_{} estimate', ",
                          c0 + a, kColour[a], sensor, "xyz"[a]);
      if (truth) {
        body += fmt::format("'estimate.csv' using 1:{} with lines dt 2 lc rgb '{}' title 'b{}_{} true', ",
                            c0 + a + 19, kColour[a], sensor, "xyz"[a]);
      }
    }
    body.resize(body.size() - 2);
    body += "\n";
  }
  body += "  unset multiplot\n";
  return report::render(dir, report::Figure("fig4_bias", body)).message;
}

// Fig. 5: Allan deviation raw against corrected: sensor 1's axes on a static run (the paper's
// Fig. 5); when the platforms flip, the sensor outputs carry the flips, so the fused body rate
std::string fig5_allan(const fs::path& dir, const FigureSeries& sr, double rate_hz) {
  std::vector<report::AllanTableColumn> cols;
  est::AllanOptions opt;
  opt.sample_rate_hz = rate_hz;
  const bool fused = sr.platforms_moved;
  for (int pass = 0; pass < 2; ++pass) {
    for (int a = 0; a < 3; ++a) {
      const auto& src = fused ? (pass == 0 ? sr.raw_rate[a] : sr.cor_rate[a]) : (pass == 0 ? sr.raw1[a] : sr.cor1[a]);
      std::vector<double> x(src.begin(), src.end());
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
  report::write_allan_table(dir / "allan_fig5.csv", cols);
  std::string body = fmt::format(
      "  set logscale xy; set xlabel 'tau [s]'; set ylabel 'Allan deviation [deg/s]'\n"
      "  set title 'Fig. 5: Allan deviation of {}, raw (red) and DriftLess-corrected (black)'\n"
      "  plot ",
      fused ? "the fused body rate" : "sensor 1");
  for (int i = 0; i < 6; ++i) {
    body += fmt::format("'allan_fig5.csv' using 1:{} with linespoints lc rgb '{}' dt {} title columnhead({}){}",
                        2 + 3 * i, i < 3 ? "red" : "black", 1 + i % 3, 2 + 3 * i, i < 5 ? ", " : "\n");
  }
  return report::render(dir, report::Figure("fig5_allan", body)).message;
}

// Fig. 9: attitude error with and without DriftLess
std::string fig9_attitude(const fs::path& dir) {
  const std::string body =
      "  set xlabel 't [s]'; set ylabel 'attitude error [deg]'\n"
      "  set title 'Fig. 9: attitude error, bias fixed at the start (red) and DriftLess (blue)'\n"
      "  plot 'attitude.csv' using 1:10 with lines lc rgb 'red' dt 1 title 'roll (bias fixed)', "
      "'' using 1:11 with lines lc rgb 'red' dt 2 title 'pitch (bias fixed)', "
      "'' using 1:12 with lines lc rgb 'red' dt 3 title 'heading (bias fixed)', "
      "'' using 1:2 with lines lc rgb 'blue' dt 1 title 'roll', "
      "'' using 1:3 with lines lc rgb 'blue' dt 2 title 'pitch', "
      "'' using 1:4 with lines lc rgb 'blue' dt 3 title 'heading'\n";
  return report::render(dir, report::Figure("fig9_attitude", body)).message;
}

}  // namespace

std::vector<std::string> write_estimate_figures(const fs::path& dir, const EstimateFigureInputs& in) {
  std::vector<std::string> warnings;
  auto keep = [&](std::string w) {
    if (!w.empty()) warnings.push_back(std::move(w));
  };
  keep(fig4_bias(dir, in.truth));
  const FigureSeries* sr = in.series;
  if (sr != nullptr && sr->raw1[0].size() >= 3 && std::isfinite(in.sample_rate_hz)) {
    keep(fig5_allan(dir, *sr, in.sample_rate_hz));
  }
  if (in.attitude) keep(fig9_attitude(dir));
  return warnings;
}

}  // namespace driftless::cli
