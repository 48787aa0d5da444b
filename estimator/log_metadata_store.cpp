// Log metadata: the '# key: value' store, and the one validation of the standard keys that every
// reader and the writer apply (docs/log-format.md, "Metadata keys").
#include <array>
#include <charconv>
#include <cmath>
#include <sstream>

#include "estimator/log.hpp"
#include "estimator/log_columns.hpp"

namespace driftless::log {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

bool parse_whole_number(std::string_view text, double& out) {
  text = trim(text);
  if (text.empty()) return false;
  const char* first = text.data();
  const char* last = text.data() + text.size();
  if (*first == '+') ++first;
  auto [ptr, ec] = std::from_chars(first, last, out);
  return ec == std::errc() && ptr == last;
}

bool parse_vector3(std::string_view text, Eigen::Vector3d& out) {
  std::istringstream in{std::string(text)};
  std::string extra;
  return static_cast<bool>(in >> out[0] >> out[1] >> out[2]) && !(in >> extra);
}

// what a standard key holds
enum class Kind { kFormat, kBool, kNumber, kAxis, kSensors };

struct KeyRule {
  std::string_view key;
  Kind kind;
  double lo, hi;            // kNumber: the closed range; lo_open excludes lo itself
  bool lo_open;
  std::string_view expect;  // what the message says was expected
};

// the standard keys and their valid values; other keys are provenance text, kept and not read
constexpr std::array<KeyRule, 11> kKeyRules = {{
    {"format", Kind::kFormat, 0, 0, false, "'driftless-log 1'"},
    {"complete", Kind::kBool, 0, 0, false, "'true' or 'false'"},
    {"sample_rate_hz", Kind::kNumber, 0.0, 1e6, true, "a sample rate in Hz, > 0 and <= 1e6"},
    {"latitude_deg", Kind::kNumber, -90.0, 90.0, false, "a latitude in deg within [-90, 90]"},
    {"hinge1_axis", Kind::kAxis, 0, 0, false, "three finite numbers 'x y z', not all zero"},
    {"hinge2_axis", Kind::kAxis, 0, 0, false, "three finite numbers 'x y z', not all zero"},
    {"gyro_full_scale_dps", Kind::kNumber, 0.0, 1e5, true, "a gyro full scale in deg/s, > 0 and <= 1e5"},
    {"gyro1_full_scale_dps", Kind::kNumber, 0.0, 1e5, true, "a gyro full scale in deg/s, > 0 and <= 1e5"},
    {"gyro2_full_scale_dps", Kind::kNumber, 0.0, 1e5, true, "a gyro full scale in deg/s, > 0 and <= 1e5"},
    {"sensors", Kind::kSensors, 0, 0, false, "1 (single-sensor form) or 2"},
    {"duration_s", Kind::kNumber, 0.0, 1e12, false, "a duration in s, >= 0"},
}};

bool value_ok(const KeyRule& rule, std::string_view value) {
  value = trim(value);
  switch (rule.kind) {
    case Kind::kFormat: return value == kFormatId;
    case Kind::kBool: return value == "true" || value == "false";
    case Kind::kSensors: return value == "1" || value == "2";
    case Kind::kNumber: {
      double v = kNaN;
      if (!parse_whole_number(value, v) || !std::isfinite(v)) return false;
      return (rule.lo_open ? v > rule.lo : v >= rule.lo) && v <= rule.hi;
    }
    case Kind::kAxis: {
      Eigen::Vector3d a;
      return parse_vector3(value, a) && a.allFinite() && a.norm() > 0.0;
    }
  }
  return false;
}

// the file named in a message ("log metadata" for metadata that was not read from a file)
std::string source_name(std::string_view file) { return std::string(file.empty() ? std::string_view("log metadata") : file); }

}  // namespace

namespace detail {

double& column_slot(Sample& s, std::size_t i) {
  switch (i) {
    case 0: return s.t_s;
    case 1: case 2: case 3: return s.gyro1_dps[static_cast<Eigen::Index>(i - 1)];
    case 4: case 5: case 6: return s.gyro2_dps[static_cast<Eigen::Index>(i - 4)];
    case 7: return s.plat1_deg;
    case 8: return s.plat2_deg;
    case 9: case 10: case 11: case 12: return s.ref_q_wxyz[static_cast<Eigen::Index>(i - 9)];
    case 13: case 14: case 15: return s.ref_p_enu_m[static_cast<Eigen::Index>(i - 13)];
    case 16: case 17: case 18: return s.accel1_mps2[static_cast<Eigen::Index>(i - 16)];
    case 19: case 20: case 21: return s.accel2_mps2[static_cast<Eigen::Index>(i - 19)];
    case 22: return s.temp1_c;
    case 23: return s.temp2_c;
    case 24: case 25: case 26: return s.true_bias1_dps[static_cast<Eigen::Index>(i - 24)];
    case 27: case 28: case 29: return s.true_bias2_dps[static_cast<Eigen::Index>(i - 27)];
    case 30: case 31: case 32: return s.true_rate_body_dps[static_cast<Eigen::Index>(i - 30)];
    case 33: return s.true_plat1_deg;
    case 34: return s.true_plat2_deg;
    default: break;
  }
  throw std::logic_error("log: column slot out of range");
}

}  // namespace detail

void Metadata::set(std::string key, std::string value, std::size_t line) {
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    if (entries_[i].first == key) {
      entries_[i].second = std::move(value);
      lines_[i] = line;
      return;
    }
  }
  entries_.emplace_back(std::move(key), std::move(value));
  lines_.push_back(line);
}

const std::string* Metadata::find(std::string_view key) const {
  for (const auto& [k, v] : entries_) {
    if (k == key) return &v;
  }
  return nullptr;
}

std::optional<std::string> Metadata::get(std::string_view key) const {
  if (const std::string* v = find(key)) return *v;
  return std::nullopt;
}

std::size_t Metadata::line_of(std::string_view key) const {
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    if (entries_[i].first == key) return lines_[i];
  }
  return 0;
}

double Metadata::get_number(std::string_view key, double fallback, std::string_view where) const {
  const std::string* v = find(key);
  if (v == nullptr) return fallback;
  double out = kNaN;
  if (!parse_whole_number(*v, out)) {
    throw LogError(source_name(where), line_of(key), std::string(key), "expected a number, got '" + *v + "'");
  }
  return out;
}

Eigen::Vector3d Metadata::get_vector3(std::string_view key, const Eigen::Vector3d& fallback,
                                      std::string_view where) const {
  const std::string* v = find(key);
  if (v == nullptr) return fallback;
  Eigen::Vector3d out;
  if (!parse_vector3(*v, out)) {
    throw LogError(source_name(where), line_of(key), std::string(key),
                   "expected three numbers 'x y z', got '" + *v + "'");
  }
  return out;
}

bool Metadata::complete() const {
  const std::string* v = find("complete");
  return v == nullptr || trim(*v) == "true";
}

std::string_view Metadata::gyro_full_scale_key(int sensor) const {
  const std::string_view own = sensor == 1 ? "gyro1_full_scale_dps" : "gyro2_full_scale_dps";
  if (has(own)) return own;
  return has("gyro_full_scale_dps") ? std::string_view("gyro_full_scale_dps") : std::string_view();
}

double Metadata::gyro_full_scale_dps(int sensor) const {
  const std::string_view key = gyro_full_scale_key(sensor);
  return key.empty() ? kDefaultGyroFullScaleDps : get_number(key, kDefaultGyroFullScaleDps);
}

int Metadata::sensors() const {
  const std::string* v = find("sensors");
  return v != nullptr && trim(*v) == "1" ? 1 : 2;
}

void validate_metadata(const Metadata& meta, std::string_view file) {
  for (const KeyRule& rule : kKeyRules) {
    const auto value = meta.get(rule.key);
    if (!value || value_ok(rule, *value)) continue;
    std::string msg = "expected " + std::string(rule.expect) + ", got '" + *value + "'";
    if (rule.kind == Kind::kFormat) msg += " (this reader understands 'driftless-log 1')";
    throw LogError(source_name(file), meta.line_of(rule.key), std::string(rule.key), msg + "; see docs/log-format.md");
  }
}

std::vector<std::string> column_names(std::uint32_t fields) {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < detail::kColumns.size(); ++i) {
    if (detail::column_in_layout(i, fields)) names.emplace_back(detail::kColumns[i].name);
  }
  return names;
}

std::string_view gyro_column_name(int channel) {
  // the six gyro columns follow t in the table
  return detail::kColumns[1 + static_cast<std::size_t>(channel)].name;
}

double estimated_row_bytes(std::uint32_t fields) {
  double bytes = 0.0;
  for (std::size_t i = 0; i < detail::kColumns.size(); ++i) {
    if (detail::column_in_layout(i, fields)) bytes += detail::kColumns[i].decimals + 5.0;
  }
  return bytes;
}

}  // namespace driftless::log
