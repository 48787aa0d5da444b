// diagnosis.json (format "driftless-diagnosis 2", docs/compare.md "Outputs").
#include <sstream>

#include "diagnose/report.hpp"
#include "report/json.hpp"

namespace driftless::diagnose {
namespace {

std::string n(double v) { return report::json_number(v); }
std::string q(const std::string& s) { return report::json_string(s); }

void param_json(std::ostringstream& o, const FittedParam& p) {
  o << "{\"name\": " << q(p.name()) << ", \"value\": " << n(p.new_value()) << ", \"change\": " << n(p.value)
    << ", \"sigma\": " << n(p.sigma) << ", \"model_value\": " << n(p.model_value) << ", \"unit\": " << q(p.unit())
    << ", \"absurd\": " << (p.absurd ? "true" : "false") << "}";
}

void params_json(std::ostringstream& o, const char* key, const std::vector<FittedParam>& ps) {
  o << ", " << q(key) << ": [";
  for (std::size_t i = 0; i < ps.size(); ++i) {
    if (i) o << ", ";
    param_json(o, ps[i]);
  }
  o << "]";
}

void candidate_json(std::ostringstream& o, const Candidate& c) {
  const EffectInfo& info = effect_info(c.effect);
  o << "{\"effect\": " << q(info.id) << ", \"family\": " << q(family_id(info.family)) << ", \"step\": " << c.step
    << ", \"sensor\": " << q(sensor_text(c)) << ", \"axis\": " << q(axis_text(c))
    << ", \"writable\": " << (info.writable ? "true" : "false") << ", \"testable\": " << (c.testable ? "true" : "false")
    << ", \"absurd\": " << (c.absurd ? "true" : "false") << ", \"evidence\": " << n(c.evidence)
    << ", \"chi2\": " << n(c.chi2) << ", \"dof\": " << c.dof << ", \"p_value\": " << n(c.p_value)
    << ", \"explained_fraction\": " << n(c.explained_fraction);
  params_json(o, "params", c.params);
  if (!c.diagnostics.empty()) params_json(o, "diagnostics", c.diagnostics);
  if (!c.codes.empty()) {
    o << ", \"codes\": [";
    for (std::size_t i = 0; i < c.codes.size(); ++i)
      o << (i ? ", " : "") << "{\"channel\": " << q(channel_name(c.codes[i].first)) << ", \"code\": " << c.codes[i].second << "}";
    o << "]";
  }
  o << ", \"note\": " << q(c.note) << "}";
}

void candidates_json(std::ostringstream& o, const char* key, const std::vector<Candidate>& cs) {
  o << "  " << q(key) << ": [\n";
  for (std::size_t i = 0; i < cs.size(); ++i) {
    o << "    ";
    candidate_json(o, cs[i]);
    o << (i + 1 < cs.size() ? ",\n" : "\n");
  }
  o << "  ],\n";
}

void channels_json(std::ostringstream& o, const CompareResult& r, const ReportExtras& x) {
  o << "  \"residual_rms_dps\": {\n";
  for (int c = 0; c < 6; ++c) {
    const auto& ch = r.channels[c];
    o << "    " << q(channel_name(c)) << ": {\"before\": " << n(ch.rms_dps) << ", \"after_selected\": " << n(ch.rms_after_dps)
      << ", \"raw\": " << n(ch.raw_rms_dps) << ", \"noise_floor\": " << n(ch.noise_floor_dps)
      << ", \"systematic\": " << n(ch.systematic_rms_dps) << ", \"systematic_after_selected\": " << n(ch.systematic_after_dps);
    if (x.after) {
      o << ", \"after_apply\": " << n(x.after->channels[c].rms_dps)
        << ", \"systematic_after_apply\": " << n(x.after->channels[c].systematic_rms_dps);
    }
    o << "}" << (c < 5 ? ",\n" : "\n");
  }
  o << "  },\n  \"channels\": {\n";
  for (int c = 0; c < 6; ++c) {
    const auto& ch = r.channels[c];
    o << "    " << q(channel_name(c)) << ": {\"mean_dps\": " << n(ch.mean_dps) << ", \"raw_mean_dps\": " << n(ch.raw_mean_dps)
      << ", \"white_noise_fit_dps_rthz\": " << n(ch.white_fit_dps_rthz) << ", \"ljung_box_q\": " << n(ch.ljung_box_q)
      << ", \"ljung_box_p\": " << n(ch.ljung_box_p) << ", \"autocorrelation_excess\": " << n(ch.autocorrelation_excess)
      << ", \"white\": " << (ch.white ? "true" : "false") << ", \"turn_on_bias_dps\": " << n(ch.turn_on_bias_dps)
      << ", \"adev_outside_fraction\": " << n(ch.adev_outside_fraction) << "}" << (c < 5 ? ",\n" : "\n");
  }
  o << "  },\n";
}

void six(std::ostringstream& o, const std::array<double, 6>& v) {
  o << "[";
  for (int c = 0; c < 6; ++c) o << (c ? ", " : "") << n(v[c]);
  o << "]";
}

void regimes_json(std::ostringstream& o, const CompareResult& r, const ReportExtras& x) {
  o << "  \"regimes\": [\n";
  for (std::size_t i = 0; i < r.regimes.size(); ++i) {
    const auto& g = r.regimes[i];
    o << "    {\"group\": " << q(g.group) << ", \"name\": " << q(g.name) << ", \"samples\": " << g.samples
      << ", \"samples_in_fit\": " << g.samples_in_fit << ", \"rms_dps\": ";
    six(o, g.rms_dps);
    o << ", \"mean_dps\": ";
    six(o, g.mean_dps);
    if (x.after) {
      for (const auto& h : x.after->regimes) {
        if (h.group != g.group || h.name != g.name) continue;
        o << ", \"rms_after_apply_dps\": ";
        six(o, h.rms_dps);
      }
    }
    o << "}" << (i + 1 < r.regimes.size() ? ",\n" : "\n");
  }
  o << "  ],\n  \"worst_windows\": [\n";
  for (std::size_t i = 0; i < r.worst_windows.size(); ++i) {
    const auto& w = r.worst_windows[i];
    o << "    {\"t0_s\": " << n(w.t0_s) << ", \"t1_s\": " << n(w.t1_s) << ", \"worst_channel\": " << q(channel_name(w.worst_channel))
      << ", \"rms_over_floor\": " << n(w.worst_ratio) << "}" << (i + 1 < r.worst_windows.size() ? ",\n" : "\n");
  }
  o << "  ],\n  \"correlations\": [\n";
  for (std::size_t i = 0; i < r.correlations.size(); ++i) {
    const auto& c = r.correlations[i];
    o << "    {\"signal\": " << q(c.signal) << ", \"channel\": " << q(channel_name(c.channel)) << ", \"rho\": " << n(c.rho)
      << ", \"z\": " << n(c.z) << "}" << (i + 1 < r.correlations.size() ? ",\n" : "\n");
  }
  o << "  ]";
}

void strings_json(std::ostringstream& o, const std::vector<std::string>& v) {
  o << "[";
  for (std::size_t i = 0; i < v.size(); ++i) o << (i ? ", " : "") << q(v[i]);
  o << "]";
}

}  // namespace

std::string diagnosis_json(const CompareResult& r, const ReportExtras& x) {
  std::ostringstream o;
  o << "{\n  \"format\": \"driftless-diagnosis 2\",\n  \"command\": " << q(x.command) << ",\n";
  o << "  \"log\": " << q(r.log_path) << ",\n  \"model\": " << q(r.model_source) << ",\n";
  o << "  \"verdict\": " << q(verdict_id(r.verdict)) << ",\n  \"statement\": " << q(r.statement) << ",\n";
  o << "  \"evidence_threshold\": " << n(r.threshold) << ", \"samples\": " << r.samples << ", \"samples_used\": " << r.samples_used
    << ", \"duration_s\": " << n(r.duration_s) << ", \"sample_rate_hz\": " << n(r.sample_rate_hz) << ", \"sensors\": " << r.sensors << ", \"block_s\": " << n(r.block_s)
    << ", \"resampled\": " << (r.resampled ? "true" : "false") << ",\n  \"offset_beyond_zro\": [";
  for (std::size_t i = 0; i < r.offset_beyond_zro.size(); ++i) o << (i ? ", " : "") << q(channel_name(r.offset_beyond_zro[i]));
  o << "],\n  \"notes\": ";
  strings_json(o, r.notes);
  o << ",\n";
  candidates_json(o, "selected", r.selected);
  candidates_json(o, "noise_model", r.noise_model);
  candidates_json(o, "not_supported", r.not_supported);
  channels_json(o, r, x);
  regimes_json(o, r, x);
  if (x.after) {
    o << ",\n  \"after_apply\": {\"model\": " << q(x.after_model) << ", \"applied\": ";
    strings_json(o, x.applied);
    o << ", \"skipped\": ";
    strings_json(o, x.skipped);
    o << ", \"verdict\": " << q(verdict_id(x.after->verdict)) << ", \"statement\": " << q(x.after->statement) << "}";
  }
  o << "\n}\n";
  return o.str();
}

}  // namespace driftless::diagnose
