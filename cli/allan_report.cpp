// `driftless allan` outputs: the tables, allan_fit.json and the console summary (docs/allan.md).
#include <cmath>
#include <stdexcept>

#include <fmt/core.h>

#include "cli/allan_result.hpp"
#include "estimator/numbers.hpp"
#include "report/json.hpp"
#include "report/plot_table.hpp"
#include "report/text_file.hpp"

namespace driftless::cli::allan {
namespace {

std::string num(double v) { return report::json_number(v); }
std::string str(const std::string& s) { return report::json_string(s); }

std::string str_list(const std::vector<std::string>& v) {
  std::string out = "[";
  for (std::size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + str(v[i]);
  return out + "]";
}

// the units of each fitted parameter for a quantity (rate: deg/s family; accel: m/s^2 family)
struct ParamUnits {
  const char *q, *n, *b, *k, *r;
};
ParamUnits units_of(importers::Quantity q) {
  if (q == importers::Quantity::kAccel) return {"m/s", "m/s^2/sqrt(Hz)", "m/s^2", "m/s^3/sqrt(Hz)", "m/s^3"};
  return {"deg", "deg/s/sqrt(Hz)", "deg/s", "deg/s/sqrt(s)", "deg/s^2"};
}

std::string param_json(const est::NoiseParameter& p, const char* unit) {
  return fmt::format("{{\"value\": {}, \"sigma\": {}, \"upper_95\": {}, \"unit\": {}, \"tau_s\": {}, \"region_s\": [{}, {}], "
                     "\"valid\": {}, \"note\": {}}}",
                     num(p.value), num(p.sigma), num(p.upper_95), str(unit), num(p.tau_s), num(p.tau_lo_s), num(p.tau_hi_s),
                     p.valid ? "true" : "false", str(p.note));
}

std::string validation_json(const Validation& v) {
  std::string band = "[";
  for (std::size_t i = 0; i < v.tau_s.size(); ++i) {
    band += fmt::format("{}[{}, {}, {}]", i ? ", " : "", num(v.tau_s[i]), num(v.lo95[i]), num(v.hi95[i]));
  }
  return fmt::format("{{\"records\": {}, \"fails_at_tau_s\": {}, \"verdict\": {}, \"notes\": {}, \"band_95\": {}]}}", v.records,
                     v.fails_at_tau_s > 0.0 ? num(v.fails_at_tau_s) : "null", str(v.verdict), str_list(v.notes), band);
}

std::string channel_json(const ChannelResult& c) {
  const auto& f = c.fit;
  const auto u = units_of(c.quantity);
  std::string s = fmt::format(
      "{{\"quantity\": {}, \"unit\": {}, \"preferred_bias_model\": {}, \"chi2_red\": {}, \"tau_fit_s\": [{}, {}], "
      "\"points_fitted\": {}, \"white_lowpass_tau_s\": {},\n",
      str(c.quantity == importers::Quantity::kAccel ? "acceleration" : "rate"), str(importers::unit_of(c.quantity)),
      str(f.preferred == est::BiasModel::kFlicker ? "flicker" : "gauss_markov"), num(f.chi2_red), num(f.tau_fit_lo_s),
      num(f.tau_fit_hi_s), f.points_fitted, num(f.white_lowpass_tau_s));
  s += "      \"Q\": " + param_json(f.Q, u.q) + ",\n      \"N\": " + param_json(f.N, u.n) + ",\n";
  s += "      \"B\": " + param_json(f.B, u.b) + ",\n      \"B_min\": " + param_json(f.B_min, u.b) + ",\n";
  s += "      \"gm_sigma\": " + param_json(f.gm_sigma, u.b) + ",\n      \"gm_tau\": " + param_json(f.gm_tau, "s") + ",\n";
  s += "      \"K\": " + param_json(f.K, u.k) + ",\n      \"R\": " + param_json(f.R, u.r) + ",\n";
  s += "      \"warnings\": " + str_list(f.warnings);
  if (c.validation) s += ",\n      \"validation\": " + validation_json(*c.validation);
  return s + "}";
}

void write_wide(const std::filesystem::path& path, const Result& r, std::size_t dev) {
  std::vector<report::AllanTableColumn> cols;
  for (const auto& ch : r.channels) {
    report::AllanTableColumn col;
    col.name = ch.name;
    for (const auto& p : ch.curves[dev].points) {
      col.tau_s.push_back(p.tau_s), col.adev.push_back(p.adev), col.lo.push_back(p.adev_lo), col.hi.push_back(p.adev_hi);
    }
    cols.push_back(std::move(col));
  }
  report::write_allan_table(path, cols);
}

std::string cell(const est::NoiseParameter& p) {
  if (p.valid) return fmt::format("{:.3e} +- {:.1e}", p.value, p.sigma);
  return std::isfinite(p.upper_95) ? fmt::format("< {:.2e}", p.upper_95) : std::string("-");
}

}  // namespace

Datasheet parse_datasheet(const std::string& s) {
  Datasheet d;
  for (const auto& kv : split_list(s)) {
    const auto eq = kv.find('=');
    double v = 0.0;
    std::size_t used = 0;
    try {
      v = std::stod(kv.substr(eq + 1), &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (eq == std::string::npos || used != kv.size() - eq - 1 || !(v > 0.0)) {
      throw std::invalid_argument("--datasheet: expected N=<deg/s/rtHz>,B=<deg/s>,K=<deg/s/rts> with positive numbers, got '" + kv + "'");
    }
    const std::string k = kv.substr(0, eq);
    if (k == "N") d.N = v;
    else if (k == "B") d.B = v;
    else if (k == "K") d.K = v;
    else throw std::invalid_argument("--datasheet: unknown key '" + k + "' (N, B or K)");
  }
  return d;
}

void write_tables(const std::filesystem::path& dir, const Result& r) {
  for (std::size_t d = 0; d < r.deviations.size(); ++d) {
    const bool adev = r.deviations[d] == est::Deviation::kAllan;
    write_wide(dir / (adev ? std::string("allan.csv") : std::string(est::to_string(r.deviations[d])) + ".csv"), r, d);
  }
  report::TextFile o(dir / "allan_points.csv");
  o.print("channel,deviation,tau_s,m,value,lo,hi,edf,noise,noise_inherited,phase_scale_m,terms\n");
  for (const auto& ch : r.channels) {
    for (const auto& c : ch.curves) {
      for (const auto& p : c.points) {
        o.print("{},{},{},{},{},{},{},{},{},{},{},{}\n", ch.name, est::to_string(c.deviation), exact_number(p.tau_s), p.m,
                exact_number(p.adev), exact_number(p.adev_lo), exact_number(p.adev_hi), exact_number(p.edf), est::to_string(p.noise), p.noise_inherited ? 1 : 0, p.phase_scale_m, p.terms);
      }
    }
  }
  o.commit();
}

void write_fit_json(const std::filesystem::path& dir, const Result& r) {
  std::vector<std::string> devs;
  for (const auto d : r.deviations) devs.push_back(est::to_string(d));
  const auto& st = r.stamps;
  std::string s = fmt::format(
      "{{\n  \"source\": {},\n  \"format\": {},\n  \"sample_rate_hz\": {},\n  \"samples\": {},\n  \"deviations\": {},\n"
      "  \"stamps\": {{\"rows\": {}, \"step_s\": {}, \"bursty\": {}, \"gaps\": {}, \"missing\": {}, \"largest_step_s\": {}, "
      "\"backwards\": {}, \"repeated\": {}}},\n  \"notes\": {},\n  \"warnings\": {},\n  \"channels\": {{\n",
      str(r.source), str(r.format), num(r.rate_hz), r.samples, str_list(devs), st.rows, num(st.step_s), st.bursty ? "true" : "false",
      st.gaps, st.missing, num(st.largest_step_s), st.backwards, st.repeated, str_list(r.notes), str_list(r.warnings));
  for (std::size_t c = 0; c < r.channels.size(); ++c) {
    s += "    " + str(r.channels[c].name) + ": " + channel_json(r.channels[c]) + (c + 1 < r.channels.size() ? ",\n" : "\n");
  }
  s += "  }\n}\n";
  io::write_file(dir / "allan_fit.json", s);
}

void print_summary(const Result& r) {
  fmt::print("{}: {} samples at {:.6g} Hz ({}), {} channel(s)\n", r.source, r.samples, r.rate_hz, r.format, r.channels.size());
  for (const auto& n : r.notes) fmt::print("  note: {}\n", n);
  // the units stand in each row: a record may mix rate (deg/s) and acceleration (m/s^2) channels
  fmt::print("  {:<22} {:>20} {:>24} {:>20} {:>20}  {}\n", "channel", "N", "B_min (datasheet) @tau", "B (IEEE 952)", "K", "units (N, B, K)");
  for (const auto& ch : r.channels) {
    const auto& f = ch.fit;
    const auto u = units_of(ch.quantity);
    const std::string bmin = std::isfinite(f.B_min.value)
                                 ? fmt::format("{}{:.3e} @{:.3g} s", f.B_min.valid ? "" : "< ", f.B_min.valid ? f.B_min.value : f.B_min.upper_95, f.B_min.tau_s)
                                 : std::string("-");
    fmt::print("  {:<22} {:>20} {:>24} {:>20} {:>20}  {}, {}, {}\n", ch.name, cell(f.N), bmin, cell(f.B), cell(f.K), u.n, u.b, u.k);
  }
  for (const auto& ch : r.channels) {
    for (const auto& w : ch.fit.warnings) fmt::print("  {}: {}\n", ch.name, w);
    if (ch.validation) fmt::print("  {}: round trip: {}\n", ch.name, ch.validation->verdict);
  }
}

}  // namespace driftless::cli::allan
