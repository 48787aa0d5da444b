// report.html: the verdict in one coloured sentence, the selected effects, the noise-model
// changes, the unsupported candidates greyed, per-channel and per-regime tables, plots.
#include "diagnose/report.hpp"

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <fmt/core.h>

#include "diagnose/report_plots.hpp"
#include "diagnose/report_text.hpp"
#include "diagnose/summary.hpp"
#include "estimator/output_file.hpp"
#include "report/html.hpp"

namespace driftless::diagnose {
namespace {

using report::html_escape;

const char* kStyle =
    "body{font-family:sans-serif;max-width:1150px;margin:auto;padding:1em}table{border-collapse:collapse;margin:0.5em 0}"
    "td,th{border:1px solid #bbb;padding:2px 6px;font-size:90%;text-align:right}th{background:#eee}td.l{text-align:left}"
    ".v{font-size:125%;padding:0.6em;border-radius:4px}.ok{background:#d6efcf}.miss{background:#fbe0b8}"
    ".bad{background:#f5c6c6}tr.grey td{color:#999}.absurd{color:#b00000;font-weight:bold}";

const char* verdict_class(Verdict v) {
  switch (v) {
    case Verdict::kConsistent: return "ok";
    case Verdict::kMissingEffect: return "miss";
    case Verdict::kUnexplained: return "bad";
  }
  return "bad";
}

std::string param_cell(const FittedParam& p, Effect e) {
  if (removes_model_effect(p)) return html_escape(removal_text(e, p));
  // a parameter the data do not pin down has no finite sigma: said so, not "± inf"
  const std::string sigma = std::isfinite(p.sigma) ? fmt::format(" ± {:.2g}", p.sigma) : std::string();
  std::string s = fmt::format("{} = {:.5g}{} {}{}", html_escape(p.name()), p.new_value(), sigma, html_escape(p.unit()),
                              std::isfinite(p.sigma) ? "" : " (σ not identified)");
  if (p.model_value != 0.0) s += fmt::format(" (model {:.5g}, change {:+.4g})", p.model_value, p.value);
  return p.absurd ? "<span class=absurd>" + s + " IMPLAUSIBLE</span>" : s;
}

std::string params_cell(const Candidate& c) {
  if (!c.testable) return html_escape(c.note);
  std::string s;
  for (const auto& p : c.params) s += (s.empty() ? "" : "<br>") + param_cell(p, c.effect);
  for (const auto& p : c.diagnostics) s += fmt::format("<br><i>{} = {:.3f}</i>", html_escape(p.name()), p.new_value());
  if (!c.codes.empty()) s += fmt::format("<br>{} missing codes", c.codes.size());
  if (!c.note.empty()) s += "<br><small>" + html_escape(c.note) + "</small>";
  return s;
}

void candidate_table(std::ostringstream& h, const std::vector<Candidate>& cs, bool grey, const char* evidence_head) {
  h << "<table><tr><th>step</th><th>effect</th><th>kind</th><th>sensor</th><th>axis</th><th>" << evidence_head
    << "</th><th>explained</th><th>parameters (new value ± 1σ)</th></tr>";
  for (const auto& c : cs) {
    h << fmt::format("<tr{}><td>{}</td><td class=l>{}</td><td class=l>{}</td><td>{}</td><td class=l>{}</td><td>{}</td>"
                     "<td>{:.1f} %</td><td class=l>{}</td></tr>",
                     grey ? " class=grey" : "", c.step > 0 ? std::to_string(c.step) : "-", effect_id(c.effect),
                     family_name(c.family()), sensor_text(c), axis_text(c),
                     c.testable ? fmt::format("{:.1f}", c.evidence) : "n/a", 100.0 * c.explained_fraction, params_cell(c));
  }
  h << "</table>\n";
}

void before_after(std::ostringstream& h, const CompareResult& r, const ReportExtras& x) {
  h << "<h2>Before / after</h2><p>new model: <code>" << html_escape(x.after_model) << "</code></p>";
  if (!x.applied.empty()) {
    h << "<p>written:</p><ul>";
    for (const auto& a : x.applied) h << "<li>" << html_escape(a) << "</li>";
    h << "</ul>";
  }
  if (!x.skipped.empty()) {
    h << "<p class=absurd>not written:</p><ul>";
    for (const auto& a : x.skipped) h << "<li>" << html_escape(a) << "</li>";
    h << "</ul>";
  }
  h << fmt::format("<p class='v {}'>after: <b>{}</b>: {}</p>\n", verdict_class(x.after->verdict), verdict_id(x.after->verdict),
                   html_escape(x.after->statement));
  h << "<table><tr><th>channel</th><th>rms before (deg/s)</th><th>rms after</th><th>systematic before</th>"
       "<th>systematic after</th><th>noise floor</th></tr>";
  for (int c = 0; c < 3 * r.sensors; ++c)
    h << fmt::format("<tr><td class=l>{}</td><td>{:.5f}</td><td>{:.5f}</td><td>{:.5f}</td><td>{:.5f}</td><td>{:.5f}</td></tr>",
                     channel_name(c), r.channels[c].rms_dps, x.after->channels[c].rms_dps, r.channels[c].systematic_rms_dps,
                     x.after->channels[c].systematic_rms_dps, r.channels[c].noise_floor_dps);
  h << "</table>\n";
}

void channel_table(std::ostringstream& h, const CompareResult& r) {
  h << "<h2>Residual per channel</h2><table><tr><th>channel</th><th>raw mean</th><th>raw rms</th><th>rms (nuisance "
       "fit)</th><th>rms after the selected effects</th><th>noise floor</th><th>systematic before / after</th>"
       "<th>N fit (deg/s/&radic;Hz)</th><th>Ljung-Box p</th><th>white</th><th>turn-on bias</th></tr>";
  for (int c = 0; c < 3 * r.sensors; ++c) {
    const auto& ch = r.channels[c];
    h << fmt::format("<tr><td class=l>{}</td><td>{:.4f}</td><td>{:.4f}</td><td>{:.5f}</td><td>{:.5f}</td><td>{:.5f}</td>"
                     "<td>{:.5f} / {:.5f}</td><td>{:.5f}</td><td>{:.3g}</td><td>{}</td><td>{:.4f}</td></tr>",
                     channel_name(c), ch.raw_mean_dps, ch.raw_rms_dps, ch.rms_dps, ch.rms_after_dps, ch.noise_floor_dps,
                     ch.systematic_rms_dps, ch.systematic_after_dps, ch.white_fit_dps_rthz, ch.ljung_box_p,
                     ch.white ? "yes" : "no", ch.turn_on_bias_dps);
  }
  h << "</table><p>All values in deg/s. The nuisance fit takes out the turn-on bias, the bias drift (smoothed) and the "
       "model's run-to-run effects.</p>\n";
}

void where_tables(std::ostringstream& h, const CompareResult& r) {
  h << "<h2>Worst windows</h2><table><tr><th>from (s)</th><th>to (s)</th><th>worst channel</th><th>rms / noise floor</th></tr>";
  for (const auto& w : r.worst_windows)
    h << fmt::format("<tr><td>{:.1f}</td><td>{:.1f}</td><td class=l>{}</td><td>{:.2f}</td></tr>", w.t0_s, w.t1_s,
                     channel_name(w.worst_channel), w.worst_ratio);
  h << "</table>\n<h2>By regime</h2><table><tr><th>regime</th><th>samples</th><th>in the fits</th>";
  for (int c = 0; c < 3 * r.sensors; ++c) h << "<th>" << channel_name(c) << " rms</th>";
  h << "</tr>";
  for (const auto& g : r.regimes) {
    // a regime the fits leave out (the flips) is shown greyed and says so
    const bool out_of_fit = g.samples_in_fit == 0;
    h << (out_of_fit ? "<tr class=grey>" : "<tr>") << "<td class=l>" << html_escape(g.group + ": " + g.name)
      << (out_of_fit ? " (left out of the fits)" : "") << "</td><td>" << g.samples << "</td><td>" << g.samples_in_fit << "</td>";
    for (int c = 0; c < 3 * r.sensors; ++c) h << fmt::format("<td>{:.5f}</td>", g.rms_dps[c]);
    h << "</tr>";
  }
  h << "</table>\n";
  if (r.correlations.empty()) return;
  h << "<h2>Correlations of the residual with inputs</h2><table><tr><th>signal</th><th>channel</th><th>rho</th><th>z</th></tr>";
  for (const auto& c : r.correlations)
    h << fmt::format("<tr><td class=l>{}</td><td>{}</td><td>{:+.3f}</td><td>{:.1f}</td></tr>", html_escape(c.signal),
                     channel_name(c.channel), c.rho, c.z);
  h << "</table>\n";
}

std::string html(const CompareResult& r, const ReportExtras& x, const std::vector<Plot>& plots) {
  std::ostringstream h;
  h << "<!DOCTYPE html><html><head><meta charset='utf-8'><title>driftless " << html_escape(x.command) << ": "
    << html_escape(r.log_path) << "</title><style>" << kStyle << "</style></head><body>\n";
  h << "<h1>driftless " << html_escape(x.command) << ": model versus measurement</h1>\n";
  h << fmt::format("<p class='v {}'><b>{}</b>: {}</p>\n", verdict_class(r.verdict), verdict_id(r.verdict), html_escape(r.statement));
  h << "<p>log: <code>" << html_escape(r.log_path) << "</code><br>model: <code>" << html_escape(r.model_source) << "</code><br>"
    << fmt::format("{} samples, {:.1f} s at {:.3f} Hz; {} used (platforms at rest, truth rebuilt); ", r.samples, r.duration_s,
                   r.sample_rate_hz, r.samples_used)
    << fmt::format("an effect is selected when its evidence exceeds <b>{:g}</b>", r.threshold)
    << (r.resampled ? "; <b>resampled</b>" : "") << "</p>\n";
  if (x.after) before_after(h, r, x);
  h << "<h2>Missing effects, and the model's effects the data lack (forward selection, in order)</h2>";
  if (r.selected.empty()) h << "<p>none: no physical, box, signal-chain or ADC effect is supported by the data.</p>\n";
  else candidate_table(h, r.selected, false, "evidence added");
  h << "<h2>Noise model changes (judged after the effects above)</h2>";
  if (r.noise_model.empty()) h << "<p>none: the model's noise describes what is left.</p>\n";
  else candidate_table(h, r.noise_model, false, "evidence");
  h << fmt::format("<h2>Not supported (evidence below {:g}, given the selected effects)</h2>", r.threshold);
  candidate_table(h, r.not_supported, true, "evidence");
  channel_table(h, r);
  where_tables(h, r);
  if (!r.notes.empty()) {
    h << "<h2>Assumptions and notes</h2><ul>";
    for (const auto& n : r.notes) h << "<li>" << html_escape(n) << "</li>";
    h << "</ul>\n";
  }
  h << "<h2>Plots</h2>\n";
  for (const auto& p : plots) {
    if (p.png.empty()) h << "<p>" << html_escape(p.title) << ": no plot (gnuplot missing or no data; data and messages in plots/)</p>\n";
    else h << "<h3>" << html_escape(p.title) << "</h3><img alt='" << html_escape(p.title) << "' src='data:image/png;base64,"
           << report::base64(p.png) << "'>\n";
  }
  h << "</body></html>\n";
  return h.str();
}

// through the one output helper (partial name, checked writes, rename)
void write_text(const std::filesystem::path& path, const std::string& text) { io::write_file(path, text); }

}  // namespace

void write_report(const CompareResult& r, const std::filesystem::path& dir, const ReportExtras& x) {
  std::filesystem::create_directories(dir);
  write_text(dir / "diagnosis.json", diagnosis_json(r, x));
  const std::vector<Plot> plots = draw_plots(r, dir / "plots");
  write_text(dir / "report.html", html(r, x, plots));
}

}  // namespace driftless::diagnose
