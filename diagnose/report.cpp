#include "diagnose/report.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <fmt/core.h>

#include "estimator/output_file.hpp"
#include "report/gnuplot.hpp"
#include "report/html.hpp"
#include "report/json.hpp"

namespace driftless::diagnose {
namespace {

using report::html_escape;
using report::json_number;
using report::json_string;

std::string read_file(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// renders a figure through the one gnuplot runner; the PNG bytes, or "" when gnuplot is missing,
// failed, or found no data to draw (its messages are kept in plots/<stem>.gp.log)
std::string gnuplot_png(const std::filesystem::path& dir, const std::string& stem, const std::string& script) {
  report::Figure f(stem, script);
  f.width_px = 900;
  f.height_px = 420;
  f.svg = false;
  f.csv_defaults = false;
  f.font = "sans,9";
  f.empty_is_failure = true;
  std::filesystem::remove(dir / (stem + ".png"));
  if (!report::render(dir, f).ok) return {};
  return read_file(dir / (stem + ".png"));
}

void candidate_json(std::ostringstream& o, const Candidate& c) {
  o << "{\"effect\": " << json_string(c.effect) << ", \"sensor\": " << json_string(c.sensor) << ", \"axis\": "
    << json_string(c.axis) << ", \"kind\": \"" << c.kind << "\", \"testable\": " << (c.testable ? "true" : "false")
    << ", \"applicable\": " << (c.applicable ? "true" : "false") << ", \"params\": [";
  for (std::size_t i = 0; i < c.params.size(); ++i) {
    const auto& p = c.params[i];
    o << (i ? ", " : "") << "{\"name\": " << json_string(p.name) << ", \"value\": " << json_number(p.value)
      << ", \"sigma\": " << json_number(p.sigma) << ", \"unit\": " << json_string(p.unit) << "}";
  }
  o << "], \"explained_fraction\": " << json_number(c.explained_fraction) << ", \"evidence\": " << json_number(c.evidence)
    << ", \"chi2\": " << json_number(c.chi2) << ", \"dof\": " << c.dof << ", \"p_value\": " << json_number(c.p_value)
    << ", \"note\": " << json_string(c.note) << ", \"residual_rms_after_dps\": {";
  for (int ch = 0; ch < 6; ++ch) o << (ch ? ", " : "") << "\"" << channel_name(ch) << "\": " << json_number(c.rms_after_dps[ch]);
  o << "}}";
}

}  // namespace

std::string diagnosis_json(const CompareResult& r, const ReportExtras& x) {
  std::ostringstream o;
  o << "{\n  \"format\": \"driftless-diagnosis 1\",\n";
  o << "  \"log\": " << json_string(r.log_path) << ",\n  \"model\": " << json_string(r.model_source) << ",\n";
  o << "  \"verdict\": \"" << r.verdict << "\",\n  \"statement\": " << json_string(r.statement) << ",\n";
  o << "  \"samples\": " << r.samples << ", \"samples_used\": " << r.samples_used << ", \"duration_s\": " << json_number(r.duration_s)
    << ", \"sample_rate_hz\": " << json_number(r.sample_rate_hz) << ", \"block_s\": " << json_number(r.block_s)
    << ", \"resampled\": " << (r.resampled ? "true" : "false") << ",\n";
  o << "  \"notes\": [";
  for (std::size_t i = 0; i < r.notes.size(); ++i) o << (i ? ", " : "") << json_string(r.notes[i]);
  o << "],\n  \"ranking\": [\n";
  for (std::size_t i = 0; i < r.ranking.size(); ++i) {
    o << "    ";
    candidate_json(o, r.ranking[i]);
    o << (i + 1 < r.ranking.size() ? ",\n" : "\n");
  }
  o << "  ],\n  \"residual_rms_dps\": {\n";
  const Candidate* best = r.ranking.empty() ? nullptr : &r.ranking.front();
  for (int c = 0; c < 6; ++c) {
    const auto& ch = r.channels[c];
    o << "    \"" << channel_name(c) << "\": {\"before\": " << json_number(ch.rms_dps)
      << ", \"after_best\": " << json_number(best ? best->rms_after_dps[c] : ch.rms_dps)
      << ", \"raw\": " << json_number(ch.raw_rms_dps) << ", \"noise_floor\": " << json_number(ch.noise_floor_dps)
      << ", \"systematic\": " << json_number(ch.systematic_rms_dps);
    if (x.after) o << ", \"after_apply\": " << json_number(x.after->channels[c].rms_dps) << ", \"systematic_after_apply\": " << json_number(x.after->channels[c].systematic_rms_dps);
    o << "}" << (c < 5 ? ",\n" : "\n");
  }
  o << "  },\n  \"channels\": {\n";
  for (int c = 0; c < 6; ++c) {
    const auto& ch = r.channels[c];
    o << "    \"" << channel_name(c) << "\": {\"mean_dps\": " << json_number(ch.mean_dps) << ", \"raw_mean_dps\": " << json_number(ch.raw_mean_dps)
      << ", \"white_noise_fit_dps_rthz\": " << json_number(ch.white_fit_dps_rthz) << ", \"ljung_box_q\": " << json_number(ch.ljung_box_q)
      << ", \"ljung_box_p\": " << json_number(ch.ljung_box_p)
      << ", \"autocorrelation_excess\": " << json_number(ch.autocorrelation_excess) << ", \"white\": " << (ch.white ? "true" : "false") << ", \"turn_on_bias_dps\": " << json_number(ch.turn_on_bias_dps)
      << ", \"adev_outside_fraction\": " << json_number(ch.adev_outside_fraction) << "}" << (c < 5 ? ",\n" : "\n");
  }
  o << "  },\n  \"regimes\": [\n";
  for (std::size_t i = 0; i < r.regimes.size(); ++i) {
    const auto& g = r.regimes[i];
    o << "    {\"group\": " << json_string(g.group) << ", \"name\": " << json_string(g.name) << ", \"samples\": " << g.samples
      << ", \"rms_dps\": [";
    for (int c = 0; c < 6; ++c) o << (c ? ", " : "") << json_number(g.rms_dps[c]);
    o << "], \"mean_dps\": [";
    for (int c = 0; c < 6; ++c) o << (c ? ", " : "") << json_number(g.mean_dps[c]);
    o << "]";
    if (x.after) {
      for (const auto& h : x.after->regimes) {
        if (h.group != g.group || h.name != g.name) continue;
        o << ", \"rms_after_apply_dps\": [";
        for (int c = 0; c < 6; ++c) o << (c ? ", " : "") << json_number(h.rms_dps[c]);
        o << "]";
      }
    }
    o << "}" << (i + 1 < r.regimes.size() ? ",\n" : "\n");
  }
  o << "  ],\n  \"worst_windows\": [\n";
  for (std::size_t i = 0; i < r.worst_windows.size(); ++i) {
    const auto& w = r.worst_windows[i];
    o << "    {\"t0_s\": " << json_number(w.t0_s) << ", \"t1_s\": " << json_number(w.t1_s) << ", \"worst_channel\": \"" << channel_name(w.worst_channel)
      << "\", \"rms_over_floor\": " << json_number(w.worst_ratio) << "}" << (i + 1 < r.worst_windows.size() ? ",\n" : "\n");
  }
  o << "  ],\n  \"correlations\": [\n";
  for (std::size_t i = 0; i < r.correlations.size(); ++i) {
    const auto& c = r.correlations[i];
    o << "    {\"signal\": " << json_string(c.signal) << ", \"channel\": \"" << channel_name(c.channel) << "\", \"rho\": " << json_number(c.rho)
      << ", \"z\": " << json_number(c.z) << "}" << (i + 1 < r.correlations.size() ? ",\n" : "\n");
  }
  o << "  ]";
  if (x.after) {
    o << ",\n  \"after_apply\": {\"model\": " << json_string(x.after_model) << ", \"applied\": " << json_string(x.applied)
      << ", \"verdict\": \"" << x.after->verdict << "\", \"statement\": " << json_string(x.after->statement) << "}";
  }
  o << "\n}\n";
  return o.str();
}

void write_report(const CompareResult& r, const std::filesystem::path& dir, const ReportExtras& x) {
  std::filesystem::create_directories(dir);
  {
    io::write_file(dir / "diagnosis.json", diagnosis_json(r, x));
  }
  const auto plot_dir = dir / "plots";
  std::filesystem::create_directories(plot_dir);
  std::vector<std::pair<std::string, std::string>> plots;  // title, png bytes
  // 1: block residual and smoothed nuisance bias over time
  {
    std::ostringstream d;
    for (std::size_t b = 0; b < r.block_t_s.size(); ++b) {
      d << fmt::format("{:.3f}", r.block_t_s[b]);
      for (int c = 0; c < 6; ++c) d << ' ' << json_number(r.block_residual_dps[c][b]) << ' ' << json_number(r.block_bias_dps[c][b]);
      d << '\n';
    }
    io::write_file(plot_dir / "residual.dat", d.str());  // written before gnuplot reads it
    std::string s = "set multiplot layout 2,1\nset xlabel 't (s)'\nset ylabel 'residual (deg/s)'\nset key outside right\nset datafile missing 'null'\n";
    for (int sn = 0; sn < 2; ++sn) {
      s += fmt::format("set title 'sensor {}: block-mean residual after the nuisance fit (points) and smoothed bias (lines)'\nplot ", sn + 1);
      for (int a = 0; a < 3; ++a) {
        const int c = sn * 3 + a;
        s += fmt::format("'{}' u 1:{} w d t '{}', '' u 1:{} w l lw 2 t 'bias {}'{}", "residual.dat", 2 + 2 * c,
                         channel_name(c), 3 + 2 * c, channel_name(c), a < 2 ? ", " : "\n");
      }
    }
    s += "unset multiplot\n";
    plots.push_back({"Residual over time", gnuplot_png(plot_dir, "residual", s)});
  }
  // 2: windowed rms
  {
    std::ostringstream d;
    for (const auto& w : r.windows) {
      d << fmt::format("{:.3f}", 0.5 * (w.t0_s + w.t1_s));
      for (int c = 0; c < 6; ++c) d << ' ' << json_number(w.rms_dps[c]);
      d << '\n';
    }
    io::write_file(plot_dir / "windows.dat", d.str());
    std::string s = "set xlabel 't (s)'\nset ylabel 'rms (deg/s)'\nset key outside right\nset title 'windowed residual rms'\nplot ";
    for (int c = 0; c < 6; ++c)
      s += fmt::format("'{}' u 1:{} w lp t '{}'{}", "windows.dat", 2 + c, channel_name(c), c < 5 ? ", " : "\n");
    plots.push_back({"Windowed residual RMS", gnuplot_png(plot_dir, "windows", s)});
  }
  // 3: ADEV of the residual vs the model
  {
    std::ostringstream d;
    std::size_t np = 0;
    for (const auto& ch : r.channels) np = std::max(np, ch.adev.points.size());
    for (std::size_t i = 0; i < np; ++i) {
      for (int c = 0; c < 6; ++c) {
        const auto& ch = r.channels[c];
        if (i < ch.adev.points.size()) d << json_number(ch.adev.points[i].tau_s) << ' ' << json_number(ch.adev.points[i].adev) << ' ' << json_number(ch.adev_model[i]) << ' ';
        else d << "null null null ";
      }
      d << '\n';
    }
    io::write_file(plot_dir / "adev.dat", d.str());
    std::string s = "set logscale xy\nset xlabel 'tau (s)'\nset ylabel 'ADEV (deg/s)'\nset key outside right\nset datafile missing 'null'\nset title 'Allan deviation of the residual (points) and of the model noise (lines)'\nplot ";
    for (int c = 0; c < 6; ++c)
      s += fmt::format("'{0}' u {1}:{2} w p t '{3}', '' u {1}:{4} w l dt 2 t '{3} model'{5}", "adev.dat", 1 + 3 * c,
                       2 + 3 * c, channel_name(c), 3 + 3 * c, c < 5 ? ", " : "\n");
    plots.push_back({"Allan deviation", gnuplot_png(plot_dir, "adev", s)});
  }
  // 4: regimes
  {
    std::ostringstream d;
    for (std::size_t i = 0; i < r.regimes.size(); ++i) {
      d << '"' << r.regimes[i].group << ": " << r.regimes[i].name << '"';
      for (int c = 0; c < 6; ++c) d << ' ' << json_number(r.regimes[i].rms_dps[c]);
      d << '\n';
    }
    io::write_file(plot_dir / "regimes.dat", d.str());
    std::string s = "set style data histograms\nset style fill solid 0.8\nset xtics rotate by -30\nset ylabel 'rms (deg/s)'\nset key outside right\nset title 'residual rms by regime'\nplot ";
    for (int c = 0; c < 6; ++c)
      s += fmt::format("'{}' u {}:xtic(1) t '{}'{}", "regimes.dat", 2 + c, channel_name(c), c < 5 ? ", " : "\n");
    plots.push_back({"Residual by regime", gnuplot_png(plot_dir, "regimes", s)});
  }

  std::ostringstream h;
  h << "<!DOCTYPE html><html><head><meta charset='utf-8'><title>driftless compare</title><style>"
       "body{font-family:sans-serif;max-width:1100px;margin:auto;padding:1em}table{border-collapse:collapse;margin:0.5em 0}"
       "td,th{border:1px solid #bbb;padding:2px 6px;font-size:90%;text-align:right}th{background:#eee}"
       "td.l{text-align:left}.v{font-size:120%;padding:0.5em;background:#f4f4d0}</style></head><body>\n";
  h << "<h1>Model versus measurement</h1>\n<p>log: <code>" << html_escape(r.log_path) << "</code><br>model: <code>" << html_escape(r.model_source)
    << "</code><br>" << r.samples << " samples, " << fmt::format("{:.1f}", r.duration_s) << " s at " << fmt::format("{:.3f}", r.sample_rate_hz)
    << " Hz; " << r.samples_used << " used (platforms at rest)" << (r.resampled ? "; <b>resampled to the model's rate</b>" : "") << "</p>\n";
  h << "<p class='v'><b>" << html_escape(r.verdict) << "</b>: " << html_escape(r.statement) << "</p>\n";
  if (!r.notes.empty()) {
    h << "<h3>Assumptions</h3><ul>";
    for (const auto& n : r.notes) h << "<li>" << html_escape(n) << "</li>";
    h << "</ul>\n";
  }
  if (x.after) {
    h << "<h2>Before / after</h2><p>applied: " << html_escape(x.applied) << "<br>new model: <code>" << html_escape(x.after_model)
      << "</code><br>after: <b>" << html_escape(x.after->verdict) << "</b>: " << html_escape(x.after->statement) << "</p>\n";
    h << "<table><tr><th>channel</th><th>rms before (deg/s)</th><th>rms after</th><th>systematic before</th><th>systematic after</th><th>noise floor</th></tr>";
    for (int c = 0; c < 6; ++c)
      h << fmt::format("<tr><td class=l>{}</td><td>{:.5f}</td><td>{:.5f}</td><td>{:.5f}</td><td>{:.5f}</td><td>{:.5f}</td></tr>", channel_name(c),
                       r.channels[c].rms_dps, x.after->channels[c].rms_dps, r.channels[c].systematic_rms_dps,
                       x.after->channels[c].systematic_rms_dps, r.channels[c].noise_floor_dps);
    h << "</table>\n<table><tr><th>regime</th><th>samples</th>";
    for (int c = 0; c < 6; ++c) h << "<th>" << channel_name(c) << " before / after</th>";
    h << "</tr>";
    for (const auto& g : r.regimes) {
      for (const auto& a : x.after->regimes) {
        if (a.group != g.group || a.name != g.name) continue;
        h << "<tr><td class=l>" << html_escape(g.group + ": " + g.name) << "</td><td>" << g.samples << "</td>";
        for (int c = 0; c < 6; ++c) h << fmt::format("<td>{:.4f} / {:.4f}</td>", g.rms_dps[c], a.rms_dps[c]);
        h << "</tr>";
      }
    }
    h << "</table>\n";
  }
  h << "<h2>Ranking of candidate effects</h2><table><tr><th>#</th><th>effect</th><th>sensor</th><th>axis</th><th>evidence</th><th>explained</th><th>p</th><th>parameters</th></tr>";
  for (std::size_t i = 0; i < r.ranking.size(); ++i) {
    const auto& c = r.ranking[i];
    std::string ps;
    for (std::size_t k = 0; k < std::min<std::size_t>(c.params.size(), 9); ++k)
      ps += fmt::format("{}{} = {:.4g} ± {:.2g} {}", k ? "<br>" : "", html_escape(c.params[k].name), c.params[k].value, c.params[k].sigma, html_escape(c.params[k].unit));
    if (!c.testable) ps = html_escape(c.note);
    h << fmt::format("<tr><td>{}</td><td class=l>{}</td><td>{}</td><td class=l>{}</td><td>{}</td><td>{:.1f} %</td><td>{:.2g}</td><td class=l>{}</td></tr>", i + 1,
                     html_escape(c.effect), html_escape(c.sensor), html_escape(c.axis), c.testable ? fmt::format("{:.1f}", c.evidence) : "n/a",
                     100.0 * c.explained_fraction, c.p_value, ps);
  }
  h << "</table>\n<h2>Residual per channel</h2><table><tr><th>channel</th><th>raw mean</th><th>raw rms</th><th>mean</th><th>rms</th><th>after best</th><th>noise floor</th><th>systematic</th><th>N fit (deg/s/&radic;Hz)</th><th>Ljung-Box p</th><th>turn-on bias</th></tr>";
  const Candidate* best = r.ranking.empty() ? nullptr : &r.ranking.front();
  for (int c = 0; c < 6; ++c) {
    const auto& ch = r.channels[c];
    h << fmt::format("<tr><td class=l>{}</td><td>{:.4f}</td><td>{:.4f}</td><td>{:.5f}</td><td>{:.5f}</td><td>{:.5f}</td><td>{:.5f}</td><td>{:.5f}</td><td>{:.5f}</td><td>{:.3g}</td><td>{:.4f}</td></tr>",
                     channel_name(c), ch.raw_mean_dps, ch.raw_rms_dps, ch.mean_dps, ch.rms_dps, best ? best->rms_after_dps[c] : ch.rms_dps,
                     ch.noise_floor_dps, ch.systematic_rms_dps, ch.white_fit_dps_rthz, ch.ljung_box_p, ch.turn_on_bias_dps);
  }
  h << "</table><p>All values in deg/s. \"mean/rms\": after the nuisance fit (turn-on bias, bias drift, the model's run-to-run effects).</p>\n";
  h << "<h2>Worst windows</h2><table><tr><th>from (s)</th><th>to (s)</th><th>worst channel</th><th>rms / noise floor</th></tr>";
  for (const auto& w : r.worst_windows)
    h << fmt::format("<tr><td>{:.1f}</td><td>{:.1f}</td><td class=l>{}</td><td>{:.2f}</td></tr>", w.t0_s, w.t1_s, channel_name(w.worst_channel), w.worst_ratio);
  h << "</table>\n<h2>By regime</h2><table><tr><th>regime</th><th>samples</th>";
  for (int c = 0; c < 6; ++c) h << "<th>" << channel_name(c) << " rms</th>";
  h << "</tr>";
  for (const auto& g : r.regimes) {
    h << "<tr><td class=l>" << html_escape(g.group + ": " + g.name) << "</td><td>" << g.samples << "</td>";
    for (int c = 0; c < 6; ++c) h << fmt::format("<td>{:.5f}</td>", g.rms_dps[c]);
    h << "</tr>";
  }
  h << "</table>\n";
  if (!r.correlations.empty()) {
    h << "<h2>Correlations of the residual with inputs</h2><table><tr><th>signal</th><th>channel</th><th>rho</th><th>z</th></tr>";
    for (const auto& c : r.correlations)
      h << fmt::format("<tr><td class=l>{}</td><td>{}</td><td>{:+.3f}</td><td>{:.1f}</td></tr>", html_escape(c.signal), channel_name(c.channel), c.rho, c.z);
    h << "</table>\n";
  }
  h << "<h2>Plots</h2>\n";
  for (const auto& [title, png] : plots) {
    if (png.empty()) h << "<p>" << html_escape(title) << ": no plot (gnuplot missing or no data to draw; data and gnuplot's messages in plots/)</p>\n";
    else h << "<h3>" << html_escape(title) << "</h3><img alt='" << html_escape(title) << "' src='data:image/png;base64," << report::base64(png) << "'>\n";
  }
  h << "</body></html>\n";
  io::write_file(dir / "report.html", h.str());
}

}  // namespace driftless::diagnose
