#include "importers/text_layout.hpp"

#include "estimator/log.hpp"
#include "estimator/mpu6050.hpp"
#include "estimator/sample.hpp"
#include "importers/stamp_ns.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>

#include <fast_float/fast_float.h>

namespace driftless::importers {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kG = 9.80665;
// the noisiest MEMS gyros' white noise (deg/s/sqrt(Hz)): 40x an MPU6050's 0.005, 4x an industrial unit's 0.05
constexpr double kMaxGyroNoiseDensityDpsRtHz = 0.2;
// the quietest MEMS gyros' (deg/s/sqrt(Hz)): navigation-grade MEMS reach 0.0015 (0.09 deg/sqrt(h)); below it
// fibre-optic gyros
constexpr double kMinMemsNoiseDensityDpsRtHz = 1e-3;
// deg/s: the largest full scale of common MEMS gyros (the log format's default, docs/log-format.md)
constexpr double kMaxGyroFullScaleDps = log::kDefaultGyroFullScaleDps;

struct Line {
  std::string_view text;
  std::size_t number;  // 1-based
};

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::vector<Line> lines_of(std::string_view head) {
  std::vector<Line> out;
  std::size_t start = 0, number = 1;
  while (start < head.size()) {
    const std::size_t nl = head.find('\n', start);
    const std::size_t end = nl == std::string_view::npos ? head.size() : nl;
    out.push_back({head.substr(start, end - start), number++});
    start = end + 1;
  }
  return out;
}

bool is_comment(std::string_view t) { return !t.empty() && (t.front() == '#' || t.front() == '%'); }

bool numeric_row(std::string_view line, char sep, std::vector<std::string_view>& f) {
  split_fields(line, sep, f);
  if (f.empty()) return false;
  double v = 0.0;
  for (const auto& x : f) {
    if (!parse_field(x, v)) return false;
  }
  return true;
}

char separator_of(const std::string& s, const std::string& file) {
  if (s.empty()) return 0;
  if (s == "tab" || s == "\\t") return '\t';
  if (s == "space" || s == "whitespace" || s == " ") return ' ';
  if (s.size() == 1) return s[0];
  throw ImportError(file + ": --separator: expected one character, 'tab' or 'space', got '" + s + "'");
}

// the separator giving the same field count (>= 2) on the most numeric lines near the end of the head
char detect_separator(const std::vector<Line>& lines, std::vector<std::string>& notes) {
  std::vector<std::string_view> f;
  char best = ',';
  std::size_t best_score = 0;
  for (const char sep : {',', '\t', ';', '|', ' '}) {
    std::size_t score = 0, fields = 0;
    for (std::size_t i = lines.size() > 40 ? lines.size() - 40 : 0; i < lines.size(); ++i) {
      const auto t = trim(lines[i].text);
      if (t.empty() || is_comment(t) || !numeric_row(t, sep, f) || f.size() < 2) continue;
      if (fields == 0) fields = f.size();
      score += f.size() == fields ? 1 : 0;
    }
    if (score > best_score) best = sep, best_score = score;
  }
  if (best_score == 0) return ',';
  notes.push_back(std::string("separator ") + (best == '\t' ? "tab" : best == ' ' ? "blanks" : std::string("'") + best + "'") +
                  " (the one that splits the data rows into equal numeric fields)");
  return best;
}

// the first line from which on 5 rows (or all the head holds) are numeric with equal field counts
std::size_t data_start(const std::vector<Line>& lines, char sep, std::size_t& fields) {
  std::vector<std::string_view> f;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const auto t = trim(lines[i].text);
    if (t.empty() || is_comment(t) || !numeric_row(t, sep, f)) continue;
    const std::size_t n = f.size();
    std::size_t ok = 0, seen = 0;
    for (std::size_t j = i; j < lines.size() && seen < 5; ++j) {
      const auto u = trim(lines[j].text);
      if (u.empty() || is_comment(u)) continue;
      ++seen;
      ok += numeric_row(u, sep, f) && f.size() == n ? 1 : 0;
    }
    if (ok == seen) {
      fields = n;
      return i;
    }
  }
  return lines.size();
}

// the rate a preamble line states: "Fs,100", "rate: 100", "# sample_rate_hz: 100"
double preamble_rate(std::string_view t) {
  if (is_comment(t)) t = trim(t.substr(1));
  std::string key;
  std::size_t i = 0;
  while (i < t.size() && (std::isalnum(static_cast<unsigned char>(t[i])) || t[i] == '_')) key += static_cast<char>(std::tolower(t[i++]));
  if (key != "fs" && key != "rate" && key != "sample_rate" && key != "sample_rate_hz" && key != "update_rate") return 0.0;
  while (i < t.size() && (t[i] == ',' || t[i] == ':' || t[i] == '=' || t[i] == ' ' || t[i] == '\t' || t[i] == ';')) ++i;
  double v = 0.0;
  const auto r = fast_float::from_chars(t.data() + i, t.data() + t.size(), v);
  return r.ec == std::errc() && v > 0.0 ? v : 0.0;
}

// lower case, the unit in brackets removed, separators as '_': "w_RS_S_x [rad s^-1]" -> "w_rs_s_x"
std::string normalise(std::string_view name) {
  std::string out;
  for (char c : name) {
    if (c == '[' || c == '(') break;
    if (c == '#' || c == '%' || c == '"') continue;
    out += (c == '.' || c == ' ' || c == '-') ? '_' : static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  while (!out.empty() && out.back() == '_') out.pop_back();
  return out;
}

constexpr std::array<const char*, 16> kGyroBases = {"g", "gyro", "gyr", "w", "omega", "angular_velocity",
                                                    "field_angular_velocity", "w_rs_s", "rate", "gyroscope",
                                                    "gyro1", "ang_vel", "wb", "gyro_", "omega_", "w_"};
constexpr std::array<const char*, 13> kAccelBases = {"a", "acc", "accel", "alpha", "linear_acceleration",
                                                     "field_linear_acceleration", "a_rs_s", "accelerometer",
                                                     "accel1", "lin_acc", "acc_", "a_", "accel_"};
constexpr std::array<const char*, 18> kTimeNames = {"t", "time", "sec", "secs", "seconds", "timestamp", "time_s",
                                                    "stamp", "t_s", "field_header_stamp", "time_ns", "timestamp_ns",
                                                    "time_us", "t_ns", "t_ms", "t_us", "millis", "micros"};
constexpr std::array<const char*, 5> kTempNames = {"temp", "temperature", "temp_c", "temp1", "die_temp"};

template <std::size_t N>
bool in(const std::array<const char*, N>& set, const std::string& s) {
  return std::any_of(set.begin(), set.end(), [&](const char* x) { return s == x; });
}

// quantity and axis a header name stands for (-1 axis: not an axis name)
bool classify(const std::string& norm, Quantity& q, int& axis) {
  if (norm.empty()) return false;
  const char last = norm.back();
  if (last < 'x' || last > 'z') return false;
  std::string base = norm.substr(0, norm.size() - 1);
  while (!base.empty() && base.back() == '_') base.pop_back();
  axis = last - 'x';
  if (in(kGyroBases, base)) return q = Quantity::kRate, true;
  if (in(kAccelBases, base)) return q = Quantity::kAccel, true;
  return false;
}

// a column by header name or 1-based index
int find_column(const std::string& spec, const std::vector<std::string>& header, std::size_t fields,
                const std::string& file, const char* option) {
  double idx = 0.0;
  if (parse_field(spec, idx) && !std::isnan(idx)) {
    if (idx >= 1.0 && idx <= static_cast<double>(fields) && idx == std::floor(idx)) return static_cast<int>(idx) - 1;
    throw ImportError(file + ": " + option + " " + spec + ": expected a 1-based column index up to " +
                      std::to_string(fields));
  }
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (header[i] == spec || normalise(header[i]) == normalise(spec)) return static_cast<int>(i);
  }
  std::string names;
  for (const auto& h : header) names += (names.empty() ? "" : ", ") + h;
  throw ImportError(file + ": " + option + " '" + spec + "': no such column" +
                    (header.empty() ? std::string(" (the file has no header: give 1-based indices)")
                                    : " (the header has: " + names + ")"));
}

struct Stats {
  double mean_norm = 0.0;  // |mean| of a triad over the sample rows
  bool integers = true;
  double max_abs = 0.0;
};

Stats triad_stats(const std::vector<std::vector<double>>& rows, const std::array<int, 3>& idx) {
  Stats s;
  std::array<double, 3> mean{};
  std::size_t n = 0;
  for (const auto& r : rows) {
    for (int k = 0; k < 3; ++k) {
      const double v = r[static_cast<std::size_t>(idx[k])];
      if (std::isnan(v)) continue;
      mean[k] += v;
      s.integers = s.integers && v == std::floor(v);
      s.max_abs = std::max(s.max_abs, std::fabs(v));
    }
    ++n;
  }
  if (n == 0) return s;
  for (double& m : mean) m /= static_cast<double>(n);
  s.mean_norm = std::sqrt(mean[0] * mean[0] + mean[1] * mean[1] + mean[2] * mean[2]);
  return s;
}

}  // namespace

void split_fields(std::string_view line, char sep, std::vector<std::string_view>& out) {
  out.clear();
  line = trim(line);
  if (line.empty()) return;
  if (sep == ' ') {
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      const std::size_t b = i;
      while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
      if (i > b) out.push_back(line.substr(b, i - b));
    }
    return;
  }
  std::size_t b = 0;
  for (;;) {
    const std::size_t e = line.find(sep, b);
    out.push_back(trim(line.substr(b, e == std::string_view::npos ? std::string_view::npos : e - b)));
    if (e == std::string_view::npos) break;
    b = e + 1;
  }
}

bool parse_field(std::string_view f, double& out) {
  f = trim(f);
  if (f.empty() || f == "nan" || f == "NaN" || f == "NAN") {
    out = kNaN;
    return true;
  }
  const char* b = f.data();
  const char* e = b + f.size();
  if (*b == '+') ++b;
  const auto r = fast_float::from_chars(b, e, out);
  if (r.ec == std::errc() && r.ptr == e) return true;
  // a date and time, "2024-05-01 12:00:00.125": s since 1970 (the time column's stamps are read exactly)
  std::int64_t ns = 0;
  if (!parse_datetime_ns(b, e, ns)) return false;
  out = static_cast<double>(ns) * 1e-9;
  return true;
}

// ---- the layout: separator, rows, header, columns, units, time ----

namespace {

// the header names (the last non-blank line before the data, '#' stripped, same field count)
std::vector<std::string> header_before(const std::vector<Line>& lines, std::size_t start, char sep, std::size_t fields,
                                       std::vector<std::string>& notes) {
  std::vector<std::string_view> f;
  for (std::size_t i = start; i-- > 0;) {
    auto t = trim(lines[i].text);
    if (t.empty()) continue;
    if (is_comment(t)) t = trim(t.substr(1));
    split_fields(t, sep, f);
    if (f.size() != fields || numeric_row(t, sep, f)) return {};
    split_fields(t, sep, f);
    notes.push_back("header at line " + std::to_string(lines[i].number));
    std::vector<std::string> names;
    for (auto n : f) {
      // "Time (s)" as spreadsheets, R and phyphox quote it
      if (n.size() >= 2 && n.front() == '"' && n.back() == '"') n = trim(n.substr(1, n.size() - 2));
      names.emplace_back(n);
    }
    return names;
  }
  return {};
}

// up to 200 data rows as numbers (for the unit and layout checks)
std::vector<std::vector<double>> sample_rows(const std::vector<Line>& lines, std::size_t start, char sep, std::size_t fields) {
  std::vector<std::vector<double>> rows;
  std::vector<std::string_view> f;
  for (std::size_t i = start; i < lines.size() && rows.size() < 200; ++i) {
    const auto t = trim(lines[i].text);
    if (t.empty() || is_comment(t) || !numeric_row(t, sep, f) || f.size() != fields) continue;
    std::vector<double> r(fields);
    for (std::size_t k = 0; k < fields; ++k) parse_field(f[k], r[k]);
    rows.push_back(std::move(r));
  }
  return rows;
}

std::string column_name(const TextLayout& L, int idx) {
  return idx < static_cast<int>(L.header.size()) ? L.header[static_cast<std::size_t>(idx)] : "col" + std::to_string(idx + 1);
}

void add_pick(TextLayout& L, int idx, Quantity q, int axis) {
  ColumnPick p;
  p.index = idx;
  p.channel = {column_name(L, idx), q, axis};
  L.picks.push_back(p);
}

void pick_time(TextLayout& L, const ImportOptions& opt, const std::string& file, bool positional) {
  if (opt.time_column == "none") return;
  if (!opt.time_column.empty()) {
    L.time_index = find_column(opt.time_column, L.header, L.fields, file, "--time-column");
    return;
  }
  for (std::size_t i = 0; i < L.header.size(); ++i) {
    const std::string n = normalise(L.header[i]);
    if (in(kTimeNames, n) || n.rfind("time", 0) == 0 || n.rfind("timestamp", 0) == 0) {
      L.time_index = static_cast<int>(i);
      return;
    }
  }
  if (positional && (L.fields == 4 || L.fields == 7)) {
    L.time_index = 0;
    L.assumptions.push_back("no header: column 1 taken as the time");
  }
}

// a time column of dates and times is read as UTC seconds: said, with the first row's text
void say_datetime_time(TextLayout& L, std::string_view first_row) {
  if (L.time_index < 0) return;
  std::vector<std::string_view> f;
  split_fields(first_row, L.separator, f);
  if (static_cast<std::size_t>(L.time_index) >= f.size()) return;
  const auto v = f[static_cast<std::size_t>(L.time_index)];
  std::int64_t ns = 0;
  if (!parse_datetime_ns(v.data(), v.data() + v.size(), ns)) return;
  L.assumptions.push_back("time column '" + column_name(L, L.time_index) + "' holds dates and times ('" + std::string(v) +
                          "'): read as UTC, to the ns (no zone given: UTC)");
}

// a column the options name: one channel only (--columns gyro_x,gyro_x,gyro_z would read one axis
// twice and no other, and --temp-column acc_x would take an accelerometer axis for a temperature)
void add_named_pick(TextLayout& L, const std::string& name, const char* option, Quantity q, int axis,
                    const std::string& file) {
  const int idx = find_column(name, L.header, L.fields, file, option);
  const bool taken = idx == L.time_index || std::any_of(L.picks.begin(), L.picks.end(),
                                                        [idx](const ColumnPick& p) { return p.index == idx; });
  if (taken) {
    throw ImportError(file + ": " + option + " " + name + ": column " + std::to_string(idx + 1) + " ('" +
                      column_name(L, idx) + "') is already read as " + (idx == L.time_index ? "the time" : "another channel") +
                      "; name each column once");
  }
  add_pick(L, idx, q, axis);
}

// rate (and accel) columns from the options, the header names, or the column count
bool pick_channels(TextLayout& L, const ImportOptions& opt, const std::string& file) {
  const auto fields = L.fields;
  if (!opt.columns.empty()) {
    for (std::size_t k = 0; k < opt.columns.size(); ++k) {
      add_named_pick(L, opt.columns[k], "--columns", Quantity::kRate, opt.columns.size() == 3 ? static_cast<int>(k) : -1,
                     file);
    }
  } else if (opt.all_columns) {
    for (std::size_t i = 0; i < fields; ++i) {
      if (static_cast<int>(i) != L.time_index) add_pick(L, static_cast<int>(i), Quantity::kRate, -1);
    }
  } else {
    for (std::size_t i = 0; i < L.header.size(); ++i) {
      Quantity q;
      int axis = -1;
      if (classify(normalise(L.header[i]), q, axis) && q == Quantity::kRate) add_pick(L, static_cast<int>(i), q, axis);
    }
  }
  if (!opt.accel_columns.empty()) {
    for (std::size_t k = 0; k < opt.accel_columns.size(); ++k) {
      add_named_pick(L, opt.accel_columns[k], "--accel-columns", Quantity::kAccel,
                     opt.accel_columns.size() == 3 ? static_cast<int>(k) : -1, file);
    }
  } else if (opt.columns.empty() && !opt.all_columns) {
    for (std::size_t i = 0; i < L.header.size(); ++i) {
      Quantity q;
      int axis = -1;
      if (classify(normalise(L.header[i]), q, axis) && q == Quantity::kAccel) add_pick(L, static_cast<int>(i), q, axis);
    }
  }
  if (!opt.temp_column.empty()) {
    add_named_pick(L, opt.temp_column, "--temp-column", Quantity::kTemperature, -1, file);
  } else {
    for (std::size_t i = 0; i < L.header.size(); ++i) {
      if (in(kTempNames, normalise(L.header[i]))) add_pick(L, static_cast<int>(i), Quantity::kTemperature, -1);
    }
  }
  return std::any_of(L.picks.begin(), L.picks.end(), [](const ColumnPick& p) { return p.channel.quantity == Quantity::kRate; });
}

// no header and no --columns: the usual orders by column count, gyro before accel
bool pick_positional(TextLayout& L) {
  const int first = L.time_index >= 0 ? 1 : 0;
  const std::size_t n = L.fields - static_cast<std::size_t>(first);
  if (n != 3 && n != 6) return false;
  for (int k = 0; k < 3; ++k) add_pick(L, first + k, Quantity::kRate, k);
  if (n == 6) {
    for (int k = 0; k < 3; ++k) add_pick(L, first + 3 + k, Quantity::kAccel, k);
  }
  std::string note = "no header: columns ";
  note += first ? "2-4" : "1-3";
  note += " taken as gyro x, y, z";
  if (n == 6) {
    note += ", ";
    note += first ? "5-7" : "4-6";
    note += " as accel x, y, z";
  }
  note += " (give --columns to change)";
  L.assumptions.push_back(std::move(note));
  return true;
}

std::array<int, 3> triad(const TextLayout& L, Quantity q) {
  std::array<int, 3> idx{-1, -1, -1};
  for (const auto& p : L.picks) {
    if (p.channel.quantity == q && p.channel.axis >= 0) idx[static_cast<std::size_t>(p.channel.axis)] = p.index;
  }
  return idx;
}

bool complete(const std::array<int, 3>& t) { return t[0] >= 0 && t[1] >= 0 && t[2] >= 0; }

// a positional guess that put the accelerometer first (|mean| near g): swap the triads
void check_positional_swap(TextLayout& L, const std::vector<std::vector<double>>& rows) {
  const auto g = triad(L, Quantity::kRate), a = triad(L, Quantity::kAccel);
  if (!complete(g) || !complete(a) || rows.empty()) return;
  const Stats sg = triad_stats(rows, g), sa = triad_stats(rows, a);
  const bool g_like_gravity = std::fabs(sg.mean_norm - kG) < 1.5 || std::fabs(sg.mean_norm - 1.0) < 0.15;
  if (g_like_gravity && sa.mean_norm < 0.3 * sg.mean_norm) {
    for (auto& p : L.picks) {
      if (p.channel.quantity == Quantity::kRate) p.channel.quantity = Quantity::kAccel;
      else if (p.channel.quantity == Quantity::kAccel) p.channel.quantity = Quantity::kRate;
    }
    L.assumptions.push_back("the first triad reads |mean| = " + std::to_string(sg.mean_norm) +
                            " (gravity): accelerometer first, then gyro");
  }
}

// the unit of the rate channels: option, header, EuRoC, raw counts, SI file, else deg/s. `from_name`:
// the unit was written in a header name.
Unit rate_unit(const TextLayout& L, const ImportOptions& opt, const std::vector<std::vector<double>>& rows, bool euroc,
               bool accel_in_si, bool& from_name) {
  from_name = false;
  if (!opt.units.empty()) return parse_rate_unit(opt.units, "--units");
  for (const auto& p : L.picks) {
    if (p.channel.quantity != Quantity::kRate) continue;
    if (auto u = unit_in_name(p.channel.name, Quantity::kRate)) return from_name = true, *u;
  }
  if (euroc) return {kDegPerRad, "rad/s"};
  const auto g = triad(L, Quantity::kRate);
  if (complete(g)) {
    const Stats s = triad_stats(rows, g);
    if (s.integers && s.max_abs > 20.0) return {1.0 / mpu6050::gyro_lsb_per_dps(0), "lsb:131"};
  }
  if (accel_in_si) return {kDegPerRad, "rad/s"};
  return {1.0, "deg/s"};
}

Unit accel_unit(const TextLayout& L, const ImportOptions& opt, const std::vector<std::vector<double>>& rows, bool euroc) {
  if (!opt.accel_units.empty()) return parse_accel_unit(opt.accel_units, "--accel-units");
  for (const auto& p : L.picks) {
    if (p.channel.quantity != Quantity::kAccel) continue;
    if (auto u = unit_in_name(p.channel.name, Quantity::kAccel)) return *u;
  }
  if (euroc) return {1.0, "m/s^2"};
  const auto a = triad(L, Quantity::kAccel);
  if (complete(a)) {
    const Stats s = triad_stats(rows, a);
    if (s.integers && s.max_abs > 100.0) return {kG / mpu6050::accel_lsb_per_g(0), "lsb:16384"};
    if (std::fabs(s.mean_norm - 1.0) < 0.15) return {kG, "g"};
  }
  return {1.0, "m/s^2"};
}

std::string how_unit(const std::string& unit, bool given, const std::string& what) {
  if (given) return what + " in " + unit + " (as given)";
  if (unit == "lsb:131") return what + " are whole numbers up to hundreds: raw counts at 131 LSB per deg/s (MPU6050 +-250 deg/s; give --units to change)";
  if (unit == "lsb:16384") return what + " are whole numbers: raw counts at 16384 LSB per g (MPU6050 +-2 g; give --accel-units to change)";
  return what + " in " + unit + " (detected; give the option to change)";
}

void scale_picks(TextLayout& L, const Unit& rate, const Unit& accel) {
  for (auto& p : L.picks) {
    p.scale = p.channel.quantity == Quantity::kRate ? rate.scale : p.channel.quantity == Quantity::kAccel ? accel.scale : 1.0;
  }
}

// the sample rate the first rows show (Hz): the file's own, else the median stamp step; 0 when unknown
double head_rate_hz(const TextLayout& L, const std::vector<std::vector<double>>& rows) {
  if (L.nominal_rate_hz > 0.0) return L.nominal_rate_hz;
  if (L.time_index < 0) return 0.0;
  std::vector<double> steps;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const double d = rows[i][static_cast<std::size_t>(L.time_index)] - rows[i - 1][static_cast<std::size_t>(L.time_index)];
    if (d > 0.0) steps.push_back(d * L.time_scale);
  }
  if (steps.empty()) return 0.0;
  std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2), steps.end());
  return 1.0 / steps[steps.size() / 2];
}

// the white noise (deg/s/sqrt(Hz)) of a triad as read, from the median first difference of the first rows
// (robust to motion): median |difference| = 0.6745 sqrt(2) sigma of a sample; N = sigma / sqrt(fs). NaN when
// the rows cannot tell; `rate_hz` the rate used (the file's or the stamps'; 1 kHz, the fastest common rate and
// so the smallest density, when unknown).
double white_density(const TextLayout& L, const std::vector<std::vector<double>>& rows, double& rate_hz) {
  const auto g = triad(L, Quantity::kRate);
  rate_hz = head_rate_hz(L, rows);
  if (!complete(g) || rows.size() < 3) return kNaN;
  std::vector<double> diffs;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    for (const int k : g) {
      const double d = rows[i][static_cast<std::size_t>(k)] - rows[i - 1][static_cast<std::size_t>(k)];
      if (std::isfinite(d)) diffs.push_back(std::fabs(d));
    }
  }
  if (diffs.empty()) return kNaN;
  std::nth_element(diffs.begin(), diffs.begin() + static_cast<std::ptrdiff_t>(diffs.size() / 2), diffs.end());
  return diffs[diffs.size() / 2] / (0.6745 * std::sqrt(2.0)) / std::sqrt(rate_hz > 0.0 ? rate_hz : 1000.0);
}

// a deg/s guess whose white noise lies below every MEMS gyro's: a fibre-optic gyro, or a MEMS file in rad/s
std::string deg_s_too_quiet(const TextLayout& L, const std::vector<std::vector<double>>& rows) {
  double rate = 0.0;
  const double n = white_density(L, rows, rate);
  if (!(n > 0.0) || n >= kMinMemsNoiseDensityDpsRtHz || rate <= 0.0) return {};
  char b[240];
  std::snprintf(b, sizeof b,
                "; as deg/s the white noise is %.3g deg/s/sqrt(Hz), below every MEMS gyro's (%.2g and up): a "
                "fibre-optic gyro, or a MEMS file in rad/s (then %.3g): give --units",
                n, kMinMemsNoiseDensityDpsRtHz, n * kDegPerRad);
  return b;
}

// An SI file's rates are a guess from its accelerometer (m/s^2); a file in deg/s with an accelerometer in m/s^2
// read as rad/s gives a white noise 57x too large. The guess stands unless the rates read as rad/s are beyond
// every MEMS gyro: a white-noise density above kMaxGyroNoiseDensityDpsRtHz (from the median first difference of
// the first rows, robust to motion) or a reading beyond the full scale of common MEMS gyros. Empty: the guess
// stands; else the reason to read deg/s instead.
std::string rad_s_implausible(const TextLayout& L, const std::vector<std::vector<double>>& rows) {
  const auto g = triad(L, Quantity::kRate);
  if (!complete(g)) return {};
  double max_abs = 0.0;
  for (const auto& r : rows) {
    for (const int k : g) {
      if (std::isfinite(r[static_cast<std::size_t>(k)])) max_abs = std::max(max_abs, std::fabs(r[static_cast<std::size_t>(k)]));
    }
  }
  char b[320];
  if (max_abs * kDegPerRad > kMaxGyroFullScaleDps) {
    std::snprintf(b, sizeof b, "as rad/s a reading would be %.0f deg/s, beyond the +-%.0f deg/s of any MEMS gyro",
                  max_abs * kDegPerRad, kMaxGyroFullScaleDps);
    return b;
  }
  double rate = 0.0;
  const double density_dps = white_density(L, rows, rate) * kDegPerRad;
  if (!(density_dps > kMaxGyroNoiseDensityDpsRtHz)) return {};
  std::snprintf(b, sizeof b,
                "as rad/s its white noise would be %.3g deg/s/sqrt(Hz)%s, over the %.2g of the noisiest MEMS gyros "
                "(an MPU6050 has 0.005); as deg/s it is %.3g",
                density_dps, rate > 0.0 ? "" : " (at an assumed 1 kHz)", kMaxGyroNoiseDensityDpsRtHz, density_dps / kDegPerRad);
  return b;
}

void pick_units(TextLayout& L, const ImportOptions& opt, const std::vector<std::vector<double>>& rows, bool euroc) {
  const bool has_accel = complete(triad(L, Quantity::kAccel));
  const Unit au = accel_unit(L, opt, rows, euroc);
  const bool accel_si = has_accel && au.name == "m/s^2" && std::fabs(triad_stats(rows, triad(L, Quantity::kAccel)).mean_norm - kG) < 1.5;
  bool from_name = false;
  Unit ru = rate_unit(L, opt, rows, euroc, accel_si, from_name);
  const bool guessed = opt.units.empty() && !from_name && !euroc;
  std::string how = from_name ? "rates in " + ru.name + " (from the header)" : how_unit(ru.name, !opt.units.empty(), "rates");
  if (guessed && ru.name == "rad/s") {
    const std::string why = rad_s_implausible(L, rows);
    if (why.empty()) {
      how = "rates in rad/s: the accelerometer reads g in m/s^2, an SI file (give --units to change)";
    } else {
      ru = {1.0, "deg/s"};
      how = "rates in deg/s, although the accelerometer reads g in m/s^2 (an SI file would have rad/s): " + why +
            " (give --units rad/s to change)";
    }
  } else if (guessed && ru.name == "deg/s") {
    how = "rates in deg/s: no unit given or written in the header (give --units rad/s if not)" + deg_s_too_quiet(L, rows);
  }
  L.assumptions.push_back(how);
  if (has_accel) L.assumptions.push_back(how_unit(au.name, !opt.accel_units.empty(), "accelerations"));
  scale_picks(L, ru, au);
}

void pick_time_unit(TextLayout& L, const ImportOptions& opt, const std::vector<std::vector<double>>& rows, bool euroc) {
  if (L.time_index < 0) return;
  const std::string name = column_name(L, L.time_index);
  if (!opt.time_units.empty()) {
    L.time_scale = parse_time_unit(opt.time_units, "--time-units").scale;
    return;
  }
  if (auto u = time_unit_in_name(name)) {
    L.time_scale = u->scale;
    L.assumptions.push_back("time column '" + name + "' in " + u->name + " (from its name)");
    return;
  }
  // Arduino sketches log millis() or micros(), the board's clock in whole ms or us
  if (const std::string n = normalise(name); n == "millis" || n == "micros") {
    L.time_scale = n == "millis" ? 1e-3 : 1e-6;
    L.assumptions.push_back("time column '" + name + "' in " + (n == "millis" ? "ms" : "us") + " (Arduino's " + n + "())");
    return;
  }
  if (euroc) {
    L.time_scale = 1e-9;
    L.assumptions.push_back("time in ns (EuRoC / TUM-VI)");
    return;
  }
  std::vector<double> steps;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const double d = rows[i][static_cast<std::size_t>(L.time_index)] - rows[i - 1][static_cast<std::size_t>(L.time_index)];
    if (d > 0.0) steps.push_back(d);
  }
  if (steps.empty()) return;
  std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2), steps.end());
  std::string why;
  L.time_scale = time_unit_from_step(steps[steps.size() / 2], &why).scale;
  L.assumptions.push_back("column '" + name + "': " + why + " (give --time-units to change)");
}

}  // namespace

// the header's columns that are neither the time nor a picked channel: said, not silently dropped.
// A second gyro triad among them is a dual-gyro box's recording, which the two-sensor log form
// (not convert's single-IMU output) holds
void say_unused_columns(TextLayout& L) {
  std::vector<bool> used(L.header.size(), false);
  if (L.time_index >= 0 && std::size_t(L.time_index) < used.size()) used[std::size_t(L.time_index)] = true;
  for (const auto& p : L.picks) {
    if (p.index >= 0 && std::size_t(p.index) < used.size()) used[std::size_t(p.index)] = true;
  }
  std::string names;
  int gyro_like = 0;
  for (std::size_t i = 0; i < L.header.size(); ++i) {
    if (used[i] || L.header[i].empty()) continue;
    names += (names.empty() ? "" : ", ") + L.header[i];
    std::string lower(L.header[i]);
    for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (lower.find("gyr") != std::string::npos || lower.find("rate") != std::string::npos) ++gyro_like;
  }
  if (names.empty()) return;
  std::string a = "columns not used: " + names;
  if (gyro_like >= 3) {
    a += " (a second gyro triad? convert writes one IMU; for a dual-gyro box write the log form itself: columns t, "
         "gyro1_x..gyro2_z (deg/s), plat1_deg, plat2_deg (deg) and a '# format: driftless-log 1' line, "
         "docs/log-format.md)";
  }
  L.assumptions.push_back(a);
}

TextLayout detect_text_layout(std::string_view head, const std::string& file, const ImportOptions& opt, bool euroc) {
  TextLayout L;
  const auto lines = lines_of(head);
  const char given = separator_of(opt.separator, file);
  L.separator = given != 0 ? given : euroc ? ',' : detect_separator(lines, L.assumptions);
  const std::size_t start = data_start(lines, L.separator, L.fields);
  if (start == lines.size()) {
    throw ImportError(file + ": no rows of numbers in the first " + std::to_string(lines.size()) +
                      " lines (expected delimited numbers, one sample per line; see docs/import.md)");
  }
  L.data_line = lines[start].number;
  for (std::size_t i = 0; i < start; ++i) {
    const double r = preamble_rate(trim(lines[i].text));
    if (r > 0.0) {
      L.nominal_rate_hz = r;
      char b[96];
      std::snprintf(b, sizeof b, "rate %g Hz stated in line %zu", r, lines[i].number);
      L.assumptions.push_back(b);
    }
  }
  if (!opt.no_header) L.header = header_before(lines, start, L.separator, L.fields, L.assumptions);
  const auto rows = sample_rows(lines, start, L.separator, L.fields);
  const bool positional = L.header.empty() && opt.columns.empty() && !opt.all_columns;
  pick_time(L, opt, file, positional);
  say_datetime_time(L, lines[start].text);
  if (!pick_channels(L, opt, file)) {
    if (!positional || !pick_positional(L)) {
      std::string names;
      for (const auto& h : L.header) names += (names.empty() ? "" : ", ") + h;
      throw ImportError(file + ": no gyro columns found: give --columns (names or 1-based indices)" +
                        (names.empty() ? std::string(" (no header; ") + std::to_string(L.fields) + " fields per row)"
                                       : " (the header has: " + names + ")"));
    }
    check_positional_swap(L, rows);
  }
  pick_time_unit(L, opt, rows, euroc);  // first: the rate checks the unit of the rates
  pick_units(L, opt, rows, euroc);
  if (L.time_index < 0) L.assumptions.push_back("no time column: the rate must come from the file or --rate");
  say_unused_columns(L);
  return L;
}

}  // namespace driftless::importers
