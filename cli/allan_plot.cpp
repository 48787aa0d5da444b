// `driftless allan --plot`: allan.png/svg (every channel with its intervals) and, per channel,
// allan_<channel>.png/svg: confidence bars, each fitted term as its own line with its region
// (where it is at least half of the model) drawn bold, the model sum, datasheet values when given,
// and the round-trip band when --validate ran (docs/allan.md, plots).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "cli/allan_result.hpp"
#include "report/gnuplot.hpp"
#include "report/text_file.hpp"

namespace driftless::cli::allan {
namespace {

struct TermStyle {
  est::NoiseTerm term;
  const char* colour;
  const char* label;
};
constexpr TermStyle kTerms[] = {{est::NoiseTerm::kQ, "#9467bd", "Q (quantisation)"},
                                {est::NoiseTerm::kN, "#1f77b4", "N (white noise)"},
                                {est::NoiseTerm::kB, "#2ca02c", "B (flicker)"},
                                {est::NoiseTerm::kGaussMarkov, "#2ca02c", "Gauss-Markov bias"},
                                {est::NoiseTerm::kK, "#d62728", "K (rate random walk)"},
                                {est::NoiseTerm::kR, "#ff7f0e", "R (rate ramp)"}};

std::string safe(const std::string& s) {
  std::string o;
  for (char c : s) o += (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-') ? c : '_';
  return o;
}

std::string cell(double v) { return std::isfinite(v) && v > 0.0 ? fmt::format("{:.6e}", v) : std::string(); }

// model.csv: tau, sum, per term (all 6), per term its region (value where share >= 0.5), datasheet N, B, K
void write_model(const std::filesystem::path& p, const ChannelResult& c, const Datasheet& ds) {
  const auto& m = c.fit.model();
  const double lo = c.fit_curve.points.front().tau_s, hi = c.fit_curve.points.back().tau_s;
  report::TextFile o(p);
  o.print("tau_s,model,Q,N,B,K,R,GM,Q_region,N_region,B_region,K_region,R_region,GM_region,ds_N,ds_B,ds_K\n");
  const int steps = 40 * static_cast<int>(std::ceil(std::log10(hi / lo))) + 1;
  for (int i = 0; i <= steps; ++i) {
    const double tau = lo * std::pow(hi / lo, static_cast<double>(i) / steps);
    const double sum = m.avar(tau);
    std::string row = fmt::format("{:.6e},{}", tau, cell(std::sqrt(sum)));
    std::string region;
    for (int t = 0; t < est::kNoiseTerms; ++t) {
      const double v = m.term_avar(static_cast<est::NoiseTerm>(t), tau);
      row += "," + cell(std::sqrt(v));
      region += "," + (v >= 0.5 * sum ? cell(std::sqrt(v)) : std::string());
    }
    const double dsN = ds.N > 0 ? ds.N / std::sqrt(tau) : 0.0, dsK = ds.K > 0 ? ds.K * std::sqrt(tau / 3.0) : 0.0;
    o.print("{}{},{},{},{}\n", row, region, cell(dsN), cell(ds.B), cell(dsK));
  }
  o.commit();
}

void write_points(const std::filesystem::path& p, const ChannelResult& c) {
  report::TextFile o(p);
  o.print("tau_s,adev,lo,hi,band_lo,band_hi\n");
  for (std::size_t i = 0; i < c.fit_curve.points.size(); ++i) {
    const auto& pt = c.fit_curve.points[i];
    std::string band = ",";
    if (c.validation) {
      for (std::size_t k = 0; k < c.validation->tau_s.size(); ++k) {
        if (std::fabs(c.validation->tau_s[k] - pt.tau_s) < 1e-9 * pt.tau_s) band = cell(c.validation->lo95[k]) + "," + cell(c.validation->hi95[k]);
      }
    }
    o.print("{:.6e},{:.6e},{:.6e},{:.6e},{}\n", pt.tau_s, pt.adev, pt.adev_lo, pt.adev_hi, band);
  }
  o.commit();
}

std::string term_label(const ChannelResult& c, est::NoiseTerm t, const char* name) {
  const est::NoiseParameter* p = nullptr;
  switch (t) {
    case est::NoiseTerm::kQ: p = &c.fit.Q; break;
    case est::NoiseTerm::kN: p = &c.fit.N; break;
    case est::NoiseTerm::kB: p = &c.fit.B; break;
    case est::NoiseTerm::kK: p = &c.fit.K; break;
    case est::NoiseTerm::kR: p = &c.fit.R; break;
    case est::NoiseTerm::kGaussMarkov: p = &c.fit.gm_sigma; break;
  }
  return p->valid ? fmt::format("{} = {:.3g} +- {:.1g}", name, p->value, p->sigma) : std::string(name);
}

std::string channel_body(const ChannelResult& c, const std::string& stem, const Datasheet& ds) {
  const char* unit = importers::unit_of(c.quantity);
  double lo = 1e300, hi = 0.0;
  for (const auto& p : c.fit_curve.points) lo = std::min(lo, p.adev_lo), hi = std::max(hi, p.adev_hi);
  std::string b = fmt::format(
      "  set logscale xy; set xlabel 'tau [s]'; set ylabel 'Allan deviation [{}]'\n  set yrange [{:.3e}:{:.3e}]\n"
      "  set key inside left bottom box opaque\n"
      "  set title '{}: Allan deviation with {:g} % intervals, fitted terms (bold: where each is at least half of the model)'\n",
      unit, lo / 4.0, hi * 3.0, c.name, 100.0 * c.fit_curve.confidence);
  if (std::isfinite(c.fit.B_min.value)) {
    // the text runs away from the nearer end of the measured taus, so it stays inside the frame
    const double mid_tau = std::sqrt(c.fit_curve.points.front().tau_s * c.fit_curve.points.back().tau_s);
    const bool text_left = c.fit.B_min.tau_s > mid_tau;
    b += fmt::format("  set label 1 at {:.6e},{:.6e} {} point pt 6 ps 2 lc rgb '#2ca02c' offset {},-1.5 '{} {:.3g} at {:.3g} s'\n",
                     c.fit.B_min.tau_s, c.fit.B_min.value, text_left ? "right" : "left", text_left ? -1 : 1,
                     c.fit.B_min.valid ? "B_min (datasheet)" : "B_min upper bound",
                     c.fit.B_min.valid ? c.fit.B_min.value : c.fit.B_min.upper_95, c.fit.B_min.tau_s);
  }
  b += "  plot ";
  if (c.validation && c.validation->records > 0) {
    b += fmt::format("'{0}_points.csv' using 1:5:6 with filledcurves lc rgb '#dddddd' title '95 % band of {1} simulated records', ",
                     stem, c.validation->records);
  }
  b += fmt::format("'{}_points.csv' using 1:2:3:4 with yerrorbars pt 7 ps 0.7 lc rgb 'black' title 'measured', ", stem);
  b += fmt::format("'{}_model.csv' using 1:2 with lines lw 2 lc rgb '#444444' title 'model sum'", stem);
  const auto& m = c.fit.model();
  for (const auto& t : kTerms) {
    const int i = static_cast<int>(t.term);
    if (!(m.coef[i] > 0.0)) continue;
    b += fmt::format(", '{0}_model.csv' using 1:{1} with lines dt 2 lc rgb '{2}' title '{3}', '{0}_model.csv' using 1:{4} with lines lw 4 lc rgb '{2}' notitle",
                     stem, 3 + i, t.colour, term_label(c, t.term, t.label), 9 + i);
  }
  if (ds.N > 0) b += fmt::format(", '{}_model.csv' using 1:15 with lines dt 3 lw 2 lc rgb 'red' title 'datasheet N'", stem);
  if (ds.B > 0) b += fmt::format(", '{}_model.csv' using 1:16 with lines dt 3 lw 2 lc rgb 'dark-green' title 'datasheet B'", stem);
  if (ds.K > 0) b += fmt::format(", '{}_model.csv' using 1:17 with lines dt 3 lw 2 lc rgb 'dark-red' title 'datasheet K'", stem);
  return b + "\n";
}

// the units of the overview's y axis: every channel is in its quantity's unit (deg/s, m/s^2), not
// the file's; a record with both names both
std::string units_in(const Result& r) {
  std::vector<std::string> seen;
  std::string u;
  for (const auto& c : r.channels) {
    const std::string one = importers::unit_of(c.quantity);
    if (std::find(seen.begin(), seen.end(), one) != seen.end()) continue;
    u += (seen.empty() ? "" : ", ") + one;
    seen.push_back(one);
  }
  return u;
}

}  // namespace

std::vector<std::string> write_plots(const std::filesystem::path& dir, const Result& r) {
  std::vector<std::string> warnings;
  // the overview: every channel's first deviation with its intervals
  std::string body = fmt::format("  set logscale xy; set xlabel 'tau [s]'; set ylabel '{} [{}]'\n  set title '{}'\n  plot ",
                                 est::to_string(r.deviations[0]), units_in(r), r.source);
  const std::string table = r.deviations[0] == est::Deviation::kAllan ? "allan.csv" : std::string(est::to_string(r.deviations[0])) + ".csv";
  for (std::size_t c = 0; c < r.channels.size(); ++c) {
    body += fmt::format("'{}' using 1:{}:{}:{} with yerrorlines title '{}'{}", table, 2 + 3 * c, 3 + 3 * c, 4 + 3 * c,
                        r.channels[c].name, c + 1 < r.channels.size() ? ", " : "\n");
  }
  if (const auto st = report::render(dir, report::Figure("allan", body)); !st.ok) warnings.push_back(st.message);
  for (const auto& c : r.channels) {
    const std::string stem = "allan_" + safe(c.name);
    write_model(dir / (stem + "_model.csv"), c, r.datasheet);
    write_points(dir / (stem + "_points.csv"), c);
    if (const auto st = report::render(dir, report::Figure(stem, channel_body(c, stem, r.datasheet))); !st.ok) warnings.push_back(st.message);
  }
  return warnings;
}

}  // namespace driftless::cli::allan
