// The estimator's `key: value` configuration format (docs/estimator.md): a flat YAML subset
// read with the standard library only, so the filter's own folder needs no YAML parser.
#include <cmath>
#include <cerrno>
#include <cstdlib>
#include <functional>
#include <istream>
#include <map>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "estimator/filter.hpp"

namespace driftless::est {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

double to_number(const std::string& key, const std::string& v) {
  const char* begin = v.c_str();
  char* end = nullptr;
  errno = 0;
  const double x = std::strtod(begin, &end);
  if (end == begin || trim(std::string(end)) != "" || errno == ERANGE) {
    throw std::invalid_argument("key '" + key + "': expected a number, got '" + v + "'");
  }
  return x;
}

bool to_bool(const std::string& key, const std::string& v) {
  if (v == "true" || v == "yes" || v == "1") return true;
  if (v == "false" || v == "no" || v == "0") return false;
  throw std::invalid_argument("key '" + key + "': expected true or false, got '" + v + "'");
}

template <typename E>
E to_enum(const std::string& key, const std::string& v, const std::map<std::string, E>& names) {
  const auto it = names.find(v);
  if (it != names.end()) return it->second;
  std::string list;
  for (const auto& [n, e] : names) list += (list.empty() ? "" : " | ") + n;
  throw std::invalid_argument("key '" + key + "': expected " + list + ", got '" + v + "'");
}

const std::map<std::string, FilterMode> kModes = {{"paper", FilterMode::kPaper},
                                                  {"general", FilterMode::kGeneral}};
const std::map<std::string, CovarianceUpdate> kCovUpdates = {{"printed", CovarianceUpdate::kPrinted},
                                                             {"joseph", CovarianceUpdate::kJoseph}};
const std::map<std::string, StandstillSource> kSources = {
    {"platform", StandstillSource::kPlatformColumns},
    {"gyro", StandstillSource::kGyroSignal},
    {"schedule", StandstillSource::kSchedule}};

template <typename E>
std::string name_of(E e, const std::map<std::string, E>& names) {
  for (const auto& [n, v] : names) {
    if (v == e) return n;
  }
  return "?";
}

// every numeric field, by its key
const std::map<std::string, double EstimatorConfig::*>& numeric_fields() {
  static const std::map<std::string, double EstimatorConfig::*> f = {
      {"settle_s", &EstimatorConfig::settle_s},
      {"min_standstill_s", &EstimatorConfig::min_standstill_s},
      {"max_standstill_s", &EstimatorConfig::max_standstill_s},
      {"angle_tolerance_deg", &EstimatorConfig::angle_tolerance_deg},
      {"gyro_motion_threshold_dps", &EstimatorConfig::gyro_motion_threshold_dps},
      {"standstill_period_s", &EstimatorConfig::standstill_period_s},
      {"initial_plat1_deg", &EstimatorConfig::initial_plat1_deg},
      {"initial_plat2_deg", &EstimatorConfig::initial_plat2_deg},
      {"noise_density_dps_rthz", &EstimatorConfig::noise_density_dps_rthz},
      {"bias_instability_dps", &EstimatorConfig::bias_instability_dps},
      {"bias_instability_tau_s", &EstimatorConfig::bias_instability_tau_s},
      {"q_override_dps2_per_s", &EstimatorConfig::q_override_dps2_per_s},
      {"r_override_dps2", &EstimatorConfig::r_override_dps2},
      {"initial_bias_dps", &EstimatorConfig::initial_bias_dps},
      {"initial_sigma_dps", &EstimatorConfig::initial_sigma_dps},
      {"variance_floor_dps2", &EstimatorConfig::variance_floor_dps2},
      {"nis_gate_probability", &EstimatorConfig::nis_gate_probability},
  };
  return f;
}

}  // namespace

void set_config_value(EstimatorConfig& cfg, const std::string& key, const std::string& value) {
  const auto& nums = numeric_fields();
  if (const auto it = nums.find(key); it != nums.end()) {
    cfg.*(it->second) = to_number(key, value);
  } else if (key == "mode") {
    cfg.mode = to_enum(key, value, kModes);
    // paper mode brings the printed recursion unless the file says otherwise later
    if (cfg.mode == FilterMode::kPaper) cfg.covariance_update = CovarianceUpdate::kPrinted;
  } else if (key == "covariance_update") {
    cfg.covariance_update = to_enum(key, value, kCovUpdates);
  } else if (key == "standstill") {
    cfg.standstill = to_enum(key, value, kSources);
  } else if (key == "per_sample_updates") {
    cfg.per_sample_updates = to_bool(key, value);
  } else if (key == "gate_relock_after") {
    const double v = to_number(key, value);
    if (v != std::floor(v) || v < 0.0 || v > 1e6) {
      throw std::invalid_argument("estimator config: gate_relock_after: expected a whole number >= 0, got '" +
                                  value + "'");
    }
    cfg.gate_relock_after = static_cast<int>(v);
  } else if (key == "calibration_match_tolerance_deg") {
    cfg.calibration.match_tolerance_deg = to_number(key, value);
  } else {
    std::string known = "mode, covariance_update, standstill, per_sample_updates, gate_relock_after, calibration_match_tolerance_deg";
    for (const auto& [k, p] : nums) known += ", " + k;
    throw std::invalid_argument("unknown key '" + key + "' (known: " + known + ")");
  }
}

EstimatorConfig parse_estimator_config(std::istream& in, const std::string& name, EstimatorConfig base) {
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    line = trim(line);
    if (line.empty() || line == "---") continue;
    const auto colon = line.find(':');
    if (colon == std::string::npos) {
      throw std::invalid_argument(name + ":" + std::to_string(line_no) + ": expected 'key: value', got '" +
                                  line + "'");
    }
    const std::string key = trim(line.substr(0, colon));
    std::string value = trim(line.substr(colon + 1));
    if (value.size() >= 2 && (value.front() == '"' || value.front() == '\'') && value.back() == value.front()) {
      value = value.substr(1, value.size() - 2);
    }
    try {
      set_config_value(base, key, value);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(name + ":" + std::to_string(line_no) + ": " + e.what());
    }
  }
  try {
    base.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(name + ": " + e.what());
  }
  return base;
}

void write_estimator_config(std::ostream& out, const EstimatorConfig& cfg) {
  std::ostringstream s;
  s.precision(17);
  s << "mode: " << name_of(cfg.mode, kModes) << "\n";
  s << "covariance_update: " << name_of(cfg.covariance_update, kCovUpdates) << "\n";
  s << "standstill: " << name_of(cfg.standstill, kSources) << "\n";
  s << "per_sample_updates: " << (cfg.per_sample_updates ? "true" : "false") << "\n";
  s << "gate_relock_after: " << cfg.gate_relock_after << "\n";
  for (const auto& [k, p] : numeric_fields()) s << k << ": " << cfg.*p << "\n";
  s << "calibration_match_tolerance_deg: " << cfg.calibration.match_tolerance_deg << "\n";
  out << s.str();
}

}  // namespace driftless::est
