// driftless allan: Allan deviation and noise fits (N, B, K) of gyro channels, from a measurement
// log (raw, and DriftLess-corrected side by side) or from a plain single-IMU CSV file.
// Formats: docs/estimator.md.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <fast_float/fast_float.h>
#include <fmt/core.h>
#include <fmt/os.h>

#include "cli/command.hpp"
#include "estimator/allan.hpp"
#include "estimator/filter.hpp"
#include "estimator/log.hpp"
#include "report/gnuplot.hpp"
#include "report/json.hpp"
#include "report/plot_table.hpp"

namespace driftless::cli {
namespace {

namespace fs = std::filesystem;

struct AllanArgs {
  std::string log, csv, out, columns, units = "deg/s", config, mode, time_column;
  double rate_hz = 0.0;
  bool corrected = false, all_tau = false, non_overlapping = false, imu_yaml = false, plot = false;
};

struct Channel {
  std::string name;
  std::vector<double> x;  // deg/s
};

std::vector<std::string> split(std::string_view s, char sep) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const auto p = s.find(sep, start);
    std::string f(s.substr(start, p == std::string_view::npos ? std::string_view::npos : p - start));
    while (!f.empty() && (f.back() == ' ' || f.back() == '\r' || f.back() == '\t')) f.pop_back();
    while (!f.empty() && (f.front() == ' ' || f.front() == '\t')) f.erase(f.begin());
    out.push_back(f);
    if (p == std::string_view::npos) break;
    start = p + 1;
  }
  return out;
}

bool parse_double(const std::string& s, double& v) {
  if (s.empty()) return false;
  const char* b = s.data();
  const char* e = b + s.size();
  if (*b == '+') ++b;
  const auto r = fast_float::from_chars(b, e, v);
  return r.ec == std::errc() && r.ptr == e;
}

// deg/s per input unit
double unit_scale(const std::string& units) {
  if (units == "deg/s" || units == "dps") return 1.0;
  if (units == "rad/s") return kDegPerRad;
  if (units.rfind("lsb:", 0) == 0) {
    double lsb = 0.0;
    if (parse_double(units.substr(4), lsb) && lsb > 0.0) return 1.0 / lsb;
  }
  throw std::invalid_argument("--units: expected deg/s, rad/s or lsb:<LSB per deg/s> (e.g. lsb:131), got '" +
                              units + "'");
}

// a plain single-IMU CSV: optional preamble (a 'Fs,<Hz>' line is read as the rate), a header row
// holding the requested columns, then numeric rows. Timestamps, if any, give the mean rate only
// (bursty logging makes single gaps meaningless); the samples are treated as uniform.
std::vector<Channel> read_plain_csv(const AllanArgs& a, double& rate_hz, std::vector<std::string>& notes) {
  std::ifstream in(a.csv);
  if (!in) throw std::runtime_error("cannot read --csv " + a.csv);
  if (a.columns.empty()) throw std::invalid_argument("--csv needs --columns (e.g. --columns gx,gy,gz)");
  const auto wanted = split(a.columns, ',');
  const double scale = unit_scale(a.units);
  std::vector<Channel> ch(wanted.size());
  for (std::size_t i = 0; i < wanted.size(); ++i) ch[i].name = wanted[i];
  std::vector<int> idx(wanted.size(), -1);
  int time_idx = -1;
  double preamble_rate = 0.0;
  bool have_header = false;
  std::string line;
  std::size_t line_no = 0, ncols = 0;
  double t_first = kNaN, t_last = kNaN;
  std::size_t skipped = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line == "\r" || line[0] == '#') continue;
    const auto f = split(line, ',');
    if (!have_header) {
      if (f.size() >= 2 && (f[0] == "Fs" || f[0] == "fs")) {
        if (!parse_double(f[1], preamble_rate) || !(preamble_rate > 0.0)) {
          throw std::invalid_argument(fmt::format("{}:{}: rate line '{}': expected Fs,<Hz>", a.csv, line_no, line));
        }
        continue;
      }
      bool all = true;
      for (std::size_t i = 0; i < wanted.size(); ++i) {
        const auto it = std::find(f.begin(), f.end(), wanted[i]);
        idx[i] = it == f.end() ? -1 : static_cast<int>(it - f.begin());
        all = all && idx[i] >= 0;
      }
      if (all) {
        have_header = true;
        ncols = f.size();
        for (const char* tn : {"sec", "t", "time", "timestamp", "time_s"}) {
          const std::string name = a.time_column.empty() ? tn : a.time_column;
          const auto it = std::find(f.begin(), f.end(), name);
          if (it != f.end()) {
            time_idx = static_cast<int>(it - f.begin());
            break;
          }
        }
      }
      continue;  // preamble lines (settings) are skipped
    }
    if (f.size() != ncols) {
      throw std::invalid_argument(
          fmt::format("{}:{}: expected {} fields as in the header, got {}", a.csv, line_no, ncols, f.size()));
    }
    double v[16];
    bool ok = true;
    for (std::size_t i = 0; i < wanted.size() && i < 16; ++i) ok = ok && parse_double(f[idx[i]], v[i]);
    if (!ok) {
      // a row with an empty or junk gyro value is dropped and counted (like NaN rows in a log)
      ++skipped;
      continue;
    }
    for (std::size_t i = 0; i < wanted.size(); ++i) ch[i].x.push_back(v[i] * scale);
    if (time_idx >= 0) {
      double t = 0.0;
      if (parse_double(f[time_idx], t)) {
        if (!std::isfinite(t_first)) t_first = t;
        t_last = t;
      }
    }
  }
  if (!have_header) {
    throw std::invalid_argument(fmt::format("{}: no header row holds all of --columns {} (found {} lines)", a.csv,
                                            a.columns, line_no));
  }
  const std::size_t n = ch.empty() ? 0 : ch[0].x.size();
  if (n < 3) throw std::invalid_argument(fmt::format("{}: only {} numeric rows; need at least 3", a.csv, n));
  if (skipped > 0) notes.push_back(fmt::format("{} rows with an empty or non-numeric value were dropped", skipped));
  if (a.rate_hz > 0.0) {
    rate_hz = a.rate_hz;
    notes.push_back(fmt::format("rate {:.4f} Hz from --rate", rate_hz));
  } else if (preamble_rate > 0.0) {
    rate_hz = preamble_rate;
    notes.push_back(fmt::format("rate {:.4f} Hz from the file's Fs line", rate_hz));
  } else if (time_idx >= 0 && t_last > t_first) {
    rate_hz = double(n - 1) / (t_last - t_first);
    notes.push_back(fmt::format("rate {:.4f} Hz = samples / time span (timestamps may be bursty; samples "
                                "treated as uniform)",
                                rate_hz));
  } else {
    throw std::invalid_argument(a.csv + ": no timestamps and no 'Fs,<Hz>' line: give --rate HZ");
  }
  return ch;
}

// channels of a measurement log, raw and optionally DriftLess-corrected
std::vector<Channel> read_log(const AllanArgs& a, double& rate_hz, std::vector<std::string>& notes) {
  log::LogReader reader(a.log);
  const auto& meta = reader.metadata();
  const auto names = split(a.columns.empty() ? "gyro1_x,gyro1_y,gyro1_z,gyro2_x,gyro2_y,gyro2_z" : a.columns, ',');
  std::vector<int> idx;
  for (const auto& n : names) {
    const int i = reader.column_index(n);
    if (i < 0) throw std::invalid_argument(fmt::format("{}: no column '{}' in the log", a.log, n));
    idx.push_back(i);
  }
  std::vector<Channel> ch;
  for (const auto& n : names) ch.push_back({n, {}});
  // corrected: the filter runs alongside; gyro<i>_<axis> channels get a corrected twin
  std::unique_ptr<est::DriftlessFilter> filter;
  std::vector<int> corr_of;  // channel -> 0..5 in [y1c; y2c], or -1
  if (a.corrected) {
    est::EstimatorConfig cfg;
    if (!a.config.empty()) {
      std::ifstream in(a.config);
      if (!in) throw std::runtime_error("cannot read --config " + a.config);
      cfg = est::parse_estimator_config(in, a.config);
    }
    if (!a.mode.empty()) est::set_config_value(cfg, "mode", a.mode);
    filter = std::make_unique<est::DriftlessFilter>(cfg, est::box_geometry_from_metadata(meta));
    for (const auto& n : names) {
      int k = -1;
      if (n.size() == 7 && n.rfind("gyro", 0) == 0 && (n[4] == '1' || n[4] == '2') && n[5] == '_' &&
          n[6] >= 'x' && n[6] <= 'z') {
        k = (n[4] - '1') * 3 + (n[6] - 'x');
      }
      corr_of.push_back(k);
      if (k >= 0) ch.push_back({"corrected_" + n, {}});
    }
  }
  Sample s;
  std::size_t skipped = 0;
  while (reader.next(s)) {
    if (filter) filter->push(s);
    bool ok = true;
    for (const int i : idx) ok = ok && std::isfinite(reader.value(i));
    if (!ok || (filter && !s.gyros_finite())) {
      ++skipped;
      continue;
    }
    for (std::size_t c = 0; c < idx.size(); ++c) ch[c].x.push_back(reader.value(idx[c]));
    if (filter) {
      std::size_t extra = idx.size();
      for (std::size_t c = 0; c < idx.size(); ++c) {
        if (corr_of[c] < 0) continue;
        const auto& o = filter->output();
        const double v = corr_of[c] < 3 ? o.y1c_dps[corr_of[c]] : o.y2c_dps[corr_of[c] - 3];
        ch[extra++].x.push_back(v);
      }
    }
  }
  if (!meta.complete()) notes.push_back("the log says 'complete: false'; using the rows present");
  if (skipped > 0) notes.push_back(fmt::format("{} rows with a missing value were dropped", skipped));
  rate_hz = a.rate_hz > 0.0 ? a.rate_hz : meta.sample_rate_hz();
  if (!std::isfinite(rate_hz)) {
    throw std::invalid_argument(a.log + ": no sample_rate_hz in the metadata: give --rate HZ");
  }
  if (filter && filter->counters().updates == 0) {
    notes.push_back("--corrected: the filter made no update (no standstill found); corrected = raw");
  }
  return ch;
}

int run_allan(const AllanArgs& a) {
  if (a.log.empty() == a.csv.empty()) throw std::invalid_argument("give exactly one of --log or --csv");
  std::vector<std::string> notes;
  double rate_hz = kNaN;
  auto channels = a.csv.empty() ? read_log(a, rate_hz, notes) : read_plain_csv(a, rate_hz, notes);
  fs::create_directories(a.out);
  const fs::path dir(a.out);

  est::AllanOptions opt;
  opt.sample_rate_hz = rate_hz;
  opt.overlapping = !a.non_overlapping;
  opt.spacing = a.all_tau ? est::TauSpacing::kAll : est::TauSpacing::kOctave;
  std::vector<report::AllanTableColumn> table;
  std::vector<est::NoiseFit> fits;
  Progress progress("allan");
  for (std::size_t c = 0; c < channels.size(); ++c) {
    progress.update(double(c) / double(channels.size()), channels[c].name);
    const auto curve = est::allan_deviation(channels[c].x, opt);
    fits.push_back(est::fit_noise_parameters(curve));
    report::AllanTableColumn col;
    col.name = channels[c].name;
    for (const auto& p : curve.points) {
      col.tau_s.push_back(p.tau_s);
      col.adev.push_back(p.adev);
      col.lo.push_back(p.adev_lo);
      col.hi.push_back(p.adev_hi);
    }
    table.push_back(std::move(col));
  }
  progress.done();
  report::write_allan_table(dir / "allan.csv", table);

  // fits: N in deg/s/sqrt(Hz) (= deg/sqrt(s)), B in deg/s, K in deg/s/sqrt(s)
  {
    auto o = fmt::output_file((dir / "allan_fit.json").string());
    o.print("{{\n  \"source\": \"{}\",\n  \"sample_rate_hz\": {},\n  \"samples\": {},\n  \"overlapping\": {},\n",
            a.csv.empty() ? a.log : a.csv, report::json_number(rate_hz), channels.empty() ? 0 : channels[0].x.size(),
            opt.overlapping ? "true" : "false");
    o.print("  \"units\": {{\"N\": \"deg/s/sqrt(Hz)\", \"B\": \"deg/s\", \"K\": \"deg/s/sqrt(s)\", "
            "\"tau\": \"s\"}},\n  \"channels\": {{\n");
    for (std::size_t c = 0; c < channels.size(); ++c) {
      const auto& f = fits[c];
      auto par = [&](const est::NoiseParameter& p) {
        return fmt::format("{{\"value\": {}, \"sigma\": {}, \"tau_s\": {}, \"valid\": {}, \"note\": \"{}\"}}",
                           report::json_number(p.value), report::json_number(p.sigma), report::json_number(p.tau_s), p.valid ? "true" : "false",
                           p.note);
      };
      o.print("    \"{}\": {{\"N\": {}, \"B\": {}, \"K\": {}}}{}\n", channels[c].name, par(f.N), par(f.B), par(f.K),
              c + 1 < channels.size() ? "," : "");
    }
    o.print("  }},\n  \"notes\": [");
    for (std::size_t i = 0; i < notes.size(); ++i) o.print("{}\"{}\"", i ? ", " : "", notes[i]);
    o.print("]\n}}\n");
  }

  fmt::print("{}: {} samples at {:.4f} Hz ({} Allan deviation)\n", a.csv.empty() ? a.log : a.csv,
             channels.empty() ? 0 : channels[0].x.size(), rate_hz, opt.overlapping ? "overlapping" : "non-overlapping");
  for (const auto& n : notes) fmt::print("  note: {}\n", n);
  fmt::print("  {:<20} {:>22} {:>26} {:>22}\n", "channel", "N [deg/s/rtHz]", "B [deg/s] (tau)", "K [deg/s/rts]");
  for (std::size_t c = 0; c < channels.size(); ++c) {
    const auto& f = fits[c];
    auto cell = [](const est::NoiseParameter& p) {
      return p.valid ? fmt::format("{:.3e} +- {:.1e}", p.value, p.sigma) : std::string("-");
    };
    fmt::print("  {:<20} {:>22} {:>26} {:>22}\n", channels[c].name, cell(f.N),
               f.B.valid ? fmt::format("{:.3e} ({:.0f} s)", f.B.value, f.B.tau_s) : "-", cell(f.K));
  }

  if (a.imu_yaml) {
    // Kalibr's imu.yaml wants SI units: rad/s/sqrt(Hz) and rad/s^2/sqrt(Hz); the worst axis is used
    double nd = 0.0, rw = 0.0;
    for (const auto& f : fits) {
      if (f.N.valid) nd = std::max(nd, f.N.value * kRadPerDeg);
      if (f.K.valid) rw = std::max(rw, f.K.value * kRadPerDeg);
    }
    std::ofstream y(dir / "imu.yaml");
    y << "# Kalibr IMU noise model from driftless allan (gyroscope only; the worst channel of "
      << channels.size() << ")\n";
    y << "rostopic: /imu0\n";
    y << fmt::format("update_rate: {:.4f}  # Hz\n", rate_hz);
    y << fmt::format("gyroscope_noise_density: {:.6e}  # rad/s/sqrt(Hz)\n", nd);
    if (rw > 0.0) y << fmt::format("gyroscope_random_walk: {:.6e}  # rad/s^2/sqrt(Hz)\n", rw);
    else y << "# gyroscope_random_walk: not observed (no +1/2 slope in the data)\n";
  }

  if (a.plot) {
    std::string body = fmt::format(
        "  set logscale xy; set xlabel 'tau [s]'; set ylabel 'Allan deviation [deg/s]'\n"
        "  set title 'Allan deviation{}'\n  plot ",
        a.corrected ? ": raw (solid) and DriftLess-corrected (dashed)" : "");
    for (std::size_t c = 0; c < table.size(); ++c) {
      const bool corr = table[c].name.rfind("corrected_", 0) == 0;
      body += fmt::format(
          "'allan.csv' using 1:{0}:{1}:{2} with yerrorlines dt {3} title '{4}'{5}", 2 + 3 * c, 3 + 3 * c,
          4 + 3 * c, corr ? 2 : 1, table[c].name, c + 1 < table.size() ? ", " : "\n");
    }
    if (const auto st = report::render(dir, report::Figure("allan", body)); !st.ok)
      fmt::print(stderr, "driftless allan: warning: {}\n", st.message);
  }
  return 0;
}

const bool registered = register_command(40, [](CLI::App& app) {
  auto* cmd = app.add_subcommand("allan",
                                 "Allan deviation (deg/s vs tau in s) with NIST SP 1065 confidence intervals "
                                 "and fits of N, B, K; from a measurement log or a plain IMU CSV");
  auto a = std::make_shared<AllanArgs>();
  auto* log_opt = cmd->add_option("--log", a->log, "Measurement log (driftless-log 1)")->check(CLI::ExistingFile);
  auto* csv_opt =
      cmd->add_option("--csv", a->csv, "Plain single-IMU CSV (a header row naming --columns; 'Fs,<Hz>' preamble ok)")
          ->check(CLI::ExistingFile);
  log_opt->excludes(csv_opt);
  cmd->add_option("--columns", a->columns,
                  "Comma-separated channels (log default: gyro1_x..gyro2_z; required with --csv)");
  cmd->add_option("--units", a->units, "--csv gyro units: deg/s, rad/s or lsb:<LSB per deg/s> (MPU6050 +-250: lsb:131)");
  cmd->add_option("--rate", a->rate_hz, "Sample rate in Hz (overrides the file's)")->check(CLI::PositiveNumber);
  cmd->add_option("--time-column", a->time_column, "--csv timestamp column in s (default: sec, t, time, timestamp)");
  cmd->add_option("--out", a->out, "Output folder: allan.csv, allan_fit.json [, imu.yaml, allan.png/svg]")->required();
  cmd->add_flag("--corrected", a->corrected, "Log only: also the DriftLess-corrected gyro channels, side by side");
  cmd->add_option("--config", a->config, "Estimator configuration for --corrected (docs/estimator.md)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--mode", a->mode, "Estimator mode for --corrected: paper or general")
      ->check(CLI::IsMember({"paper", "general"}));
  cmd->add_flag("--all-tau", a->all_tau, "Every cluster size m (slow: O(N^2)) instead of octaves");
  cmd->add_flag("--non-overlapping", a->non_overlapping, "The paper's non-overlapping cluster definition");
  cmd->add_flag("--imu-yaml", a->imu_yaml, "Also write a Kalibr-style imu.yaml (rad/s/sqrt(Hz), rad/s^2/sqrt(Hz))");
  cmd->add_flag("--plot", a->plot, "Also write allan.png/svg with its gnuplot script");
  return [a] { return run_allan(*a); };
});

}  // namespace
}  // namespace driftless::cli
