#include "cli/allan_input.hpp"
#include "cli/command.hpp"

#include <algorithm>
#include <fstream>
#include <memory>
#include <thread>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "estimator/allan_stream.hpp"
#include "estimator/attitude_comparison.hpp"
#include "estimator/box_geometry.hpp"
#include "estimator/filter.hpp"
#include "estimator/log.hpp"
#include "importers/units.hpp"

namespace driftless::cli::allan {

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::size_t b = 0;
  while (b <= s.size() && !s.empty()) {
    const auto e = s.find(',', b);
    std::string f = s.substr(b, e == std::string::npos ? std::string::npos : e - b);
    f.erase(0, f.find_first_not_of(" \t"));
    f.erase(f.find_last_not_of(" \t") + 1);
    if (!f.empty()) out.push_back(f);
    if (e == std::string::npos) break;
    b = e + 1;
  }
  return out;
}

namespace {
// a mean regular step this far from the median step is jitter, not rounding
constexpr double kJitterRateTolerance = 1e-3;

// a rate measured from stamps, to 10 significant digits: the stamps' own resolution is coarser, and
// the digits beyond are the round-off of differences of large times (EuRoC's exact 5 ms steps gave
// 200.0000000001819 Hz)
double stamp_rate(double hz) { return std::stod(fmt::format("{:.10g}", hz)); }
}  // namespace

double resolve_rate(double given, double nominal, const importers::StampReport& st, std::vector<std::string>& notes,
                    const std::string& source) {
  if (given > 0.0) {
    notes.push_back(fmt::format("rate {:.6g} Hz from --rate", given));
    return given;
  }
  if (nominal > 0.0) {
    notes.push_back(fmt::format("rate {:.6g} Hz from the file", nominal));
    return nominal;
  }
  if (st.rows >= 2 && st.bursty && std::isfinite(st.mean_rate_hz())) {
    notes.push_back(fmt::format("rate {:.6g} Hz = (samples - 1) / time span (bursty stamps)", st.mean_rate_hz()));
    return stamp_rate(st.mean_rate_hz());
  }
  if (st.rows >= 2 && st.step_s > 0.0) {
    // jittering stamps (a loop timed in whole ms): the mean of the regular steps is the sampling rate,
    // the median only the most common step
    const double mean = st.regular_rate_hz(), median = 1.0 / st.step_s;
    if (std::isfinite(mean) && std::fabs(mean / median - 1.0) > kJitterRateTolerance) {
      notes.push_back(fmt::format("rate {:.6g} Hz from the mean regular stamp step (the stamps jitter: the median step "
                                  "{:.4g} ms would mean {:.6g} Hz)", mean, 1e3 * st.step_s, median));
      return stamp_rate(mean);
    }
    notes.push_back(fmt::format("rate {:.6g} Hz from the median stamp step", median));
    return stamp_rate(median);
  }
  throw std::invalid_argument(source + ": no timestamps and no rate in the file: give --rate HZ");
}

void add_stamp_notes(const importers::StampReport& st, const std::string& loc_word, bool ignore, std::vector<std::string>& notes) {
  for (auto& s : st.describe(loc_word)) notes.push_back(s);
  if (st.gaps > 0) {
    notes.push_back(ignore ? "--gaps ignore: the samples are taken as contiguous across the gaps"
                           : "gap-aware: no difference spans a gap (the record is split into segments; --gaps ignore to join)");
  }
}

namespace {

// ---- a driftless log: raw channels, and the DriftLess-corrected ones beside them ----

int corrected_slot(const std::string& n) {
  if (n.size() == 7 && n.rfind("gyro", 0) == 0 && (n[4] == '1' || n[4] == '2') && n[5] == '_' && n[6] >= 'x' && n[6] <= 'z') {
    return (n[4] - '1') * 3 + (n[6] - 'x');
  }
  return -1;
}

std::unique_ptr<est::DriftlessFilter> make_filter(const InputArgs& a, const log::Metadata& meta) {
  est::EstimatorConfig cfg;
  if (!a.config.empty()) {
    std::ifstream in(a.config);
    if (!in) throw std::runtime_error("cannot read --config " + a.config);
    cfg = est::parse_estimator_config(in, a.config);
  }
  if (!a.mode.empty()) est::set_config_value(cfg, "mode", a.mode);
  return std::make_unique<est::DriftlessFilter>(cfg, est::box_geometry_from_metadata(meta));
}

void add_corrected_notes(const est::DriftlessFilter& filter, double lock_t_s, double lock_sigma_dps,
                         std::vector<std::string>& notes) {
  if (filter.counters().updates == 0) {
    notes.push_back("--corrected: the filter made no update (no standstill found); no corrected channels");
  } else if (std::isnan(lock_t_s)) {
    notes.push_back(fmt::format("--corrected: the filter never locked on (a sigma of the correction stayed above "
                                "{:g} deg/s); no corrected channels", lock_sigma_dps));
  } else if (lock_sigma_dps > 0.0) {
    notes.push_back(fmt::format("--corrected: the corrected channels start at lock, t = {:.2f} s (every sigma of "
                                "the correction below {:g} deg/s)", lock_t_s, lock_sigma_dps));
  }
}

// the smallest and largest angle each platform column read
struct PlatformSpan {
  std::array<double, 2> lo{kNaN, kNaN}, hi{kNaN, kNaN};
  void add(const Sample& s) {
    const double a[2] = {s.plat1_deg, s.plat2_deg};
    for (int p = 0; p < 2; ++p) {
      if (!std::isfinite(a[p])) continue;
      lo[p] = std::isnan(lo[p]) ? a[p] : std::min(lo[p], a[p]);
      hi[p] = std::isnan(hi[p]) ? a[p] : std::max(hi[p], a[p]);
    }
  }
  std::array<double, 2> span_deg() const { return {hi[0] - lo[0], hi[1] - lo[1]}; }
};

Loaded load_log(const InputArgs& a) {
  // the single-sensor form is read too; --corrected runs the filter, which needs both triads
  log::ReaderOptions ro;
  ro.accept_single_sensor = !a.corrected;
  log::LogReader reader(a.log, ro);
  Loaded out;
  out.format = "log";
  const char* all_gyros = reader.sensors() == 1 ? "gyro1_x,gyro1_y,gyro1_z" : "gyro1_x,gyro1_y,gyro1_z,gyro2_x,gyro2_y,gyro2_z";
  const auto names = split_list(a.columns.empty() ? all_gyros : a.columns);
  std::vector<int> idx;
  for (const auto& n : names) {
    const int i = reader.column_index(n);
    if (i < 0) throw std::invalid_argument(fmt::format("{}: no column '{}' in the log", a.log, n));
    idx.push_back(i);
    const bool accel = n.rfind("accel", 0) == 0;
    out.channels.push_back({n, accel ? importers::Quantity::kAccel : importers::Quantity::kRate, n.back() - 'x', {}, {0}});
  }
  std::unique_ptr<est::DriftlessFilter> filter = a.corrected ? make_filter(a, reader.metadata()) : nullptr;
  std::vector<int> corr_of;
  for (const auto& n : names) {
    corr_of.push_back(filter ? corrected_slot(n) : -1);
    if (corr_of.back() >= 0) out.channels.push_back({"corrected_" + n, importers::Quantity::kRate, n.back() - 'x', {}, {0}});
  }
  importers::StampMonitor mon;
  std::vector<double> first_t;
  std::size_t skipped = 0;
  Sample s;
  bool pending_break = false;
  // the corrected channels start at lock: before it the correction is the filter's start value
  double lock_t_s = kNaN;
  PlatformSpan span;
  while (reader.next(s)) {
    span.add(s);
    if (filter) {
      filter->push(s);
      if (std::isnan(lock_t_s) && est::filter_locked(*filter, a.corrected_lock_sigma_dps)) lock_t_s = s.t_s;
    }
    if (first_t.size() < 4096) {
      first_t.push_back(s.t_s);
      if (first_t.size() == 4096) mon.learn(first_t);
    }
    bool ok = !filter || s.gyros_finite();
    for (const int i : idx) ok = ok && std::isfinite(reader.value(i));
    if (!ok) {
      ++skipped;
      pending_break = !a.gaps_ignore;
      continue;
    }
    if (pending_break) {
      for (auto& c : out.channels) {
        if (!c.x.empty()) c.segment_starts.push_back(c.x.size());
      }
      pending_break = false;
    }
    for (std::size_t c = 0; c < idx.size(); ++c) out.channels[c].x.push_back(reader.value(idx[c]));
    std::size_t extra = idx.size();
    for (std::size_t c = 0; c < idx.size() && !std::isnan(lock_t_s); ++c) {
      if (corr_of[c] < 0) continue;
      const auto& o = filter->output();
      out.channels[extra++].x.push_back(corr_of[c] < 3 ? o.y1c_dps[corr_of[c]] : o.y2c_dps[corr_of[c] - 3]);
    }
  }
  if (first_t.size() < 4096) mon.learn(first_t);
  out.platform_span_deg = span.span_deg();
  if (!reader.metadata().complete()) out.notes.push_back("the log says 'complete: false'; using the rows present");
  if (skipped > 0) out.notes.push_back(fmt::format("{} rows with a missing value were left out (a segment break each)", skipped));
  if (filter) add_corrected_notes(*filter, lock_t_s, a.corrected_lock_sigma_dps, out.notes);
  if (filter && std::isnan(lock_t_s)) out.channels.resize(idx.size());  // never locked: raw only
  out.rate_hz = resolve_rate(a.rate_hz, reader.metadata().sample_rate_hz(), mon.report(), out.notes, a.log);
  return out;
}

}  // namespace

importers::ImportOptions InputArgs::import_options() const {
  importers::ImportOptions o = import;
  o.format = importers::parse_format(csv.empty() ? format : "text");
  o.columns = split_list(columns);
  o.accel_columns = split_list(accel_columns);
  return o;
}

Loaded load(const InputArgs& a) {
  if ((a.log.empty() ? 0 : 1) + (a.in.empty() ? 0 : 1) + (a.csv.empty() ? 0 : 1) != 1) {
    throw std::invalid_argument("give exactly one of --log, --in or --csv");
  }
  if (!is_imported(a)) {
    InputArgs b = a;
    if (b.log.empty()) b.log = a.in;
    return load_log(b);
  }
  return load_imported(a);
}

bool is_imported(const InputArgs& a) {
  if (!a.log.empty()) return false;
  if (!a.csv.empty()) return true;
  const auto f = importers::parse_format(a.format);
  return f != importers::Format::kDriftlessLog &&
         (f != importers::Format::kAuto || importers::detect_format(a.in) != importers::Format::kDriftlessLog);
}

namespace {

// a unit option checked when it is parsed (a usage error, exit 2), by the importers' own unit table
CLI::Validator unit_option(importers::Unit (*parse)(const std::string&, std::string_view), const std::string& option) {
  return CLI::Validator(
      [parse, option](std::string& text) -> std::string {
        try {
          (void)parse(text, option);
        } catch (const std::exception& e) {
          std::string why = e.what();
          const std::string prefix = option + ": ";
          return why.rfind(prefix, 0) == 0 ? why.substr(prefix.size()) : why;
        }
        return {};
      },
      "UNIT");
}

}  // namespace

void add_import_options(CLI::App* cmd, InputArgs& in) {
  cmd->add_option("--format", in.format, "Input format: auto, text, euroc, npy, bag")
      ->check(CLI::IsMember({"auto", "text", "euroc", "npy", "bag", "log"}));
  cmd->add_option("--columns", in.columns, "Rate channels: names or 1-based indices, comma-separated (log default: gyro1_x..gyro2_z)");
  cmd->add_option("--accel-columns", in.accel_columns, "Accelerometer channels (x,y,z), names or 1-based indices");
  cmd->add_option("--time-column", in.import.time_column, "Time column: name, 1-based index or none (default: detected)");
  cmd->add_option("--units", in.import.units, "Rate units: deg/s, rad/s or lsb:<LSB per deg/s> (MPU6050 +-250: lsb:131)")
      ->check(unit_option(importers::parse_rate_unit, "--units"));
  cmd->add_option("--accel-units", in.import.accel_units, "Acceleration units: m/s^2, g or lsb:<LSB per g>")
      ->check(unit_option(importers::parse_accel_unit, "--accel-units"));
  cmd->add_option("--time-units", in.import.time_units, "Time units: s, ms, us, ns (default: detected)")
      ->check(unit_option(importers::parse_time_unit, "--time-units"));
  cmd->add_option("--separator", in.import.separator, "Text separator: one character, tab or space (default: detected)");
  cmd->add_flag("--no-header", in.import.no_header, "Text: the first row is data");
  cmd->add_option("--topic", in.import.topic, "Bag: the sensor_msgs/Imu topic (default: the only one)");
  cmd->add_option("--rate", in.rate_hz, "Sample rate in Hz (overrides the file's and the stamps')")->check(positive_number("Hz"));
}

}  // namespace driftless::cli::allan
