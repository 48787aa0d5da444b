#include "estimator/log_metadata.hpp"

#include <cmath>
#include <functional>
#include <vector>

#include "estimator/numbers.hpp"

namespace driftless::log {
namespace {

// one row per key: the text of the field, or nullopt when not given
struct Row {
  const char* key;
  std::function<std::optional<std::string>(const LogInfo&)> text;
};

std::optional<std::string> num(double v) {
  if (std::isnan(v)) return std::nullopt;
  return exact_number(v);
}
std::optional<std::string> str(const std::string& s) {
  if (s.empty()) return std::nullopt;
  return s;
}
std::optional<std::string> vec(const std::optional<Eigen::Vector3d>& v) {
  if (!v) return std::nullopt;
  return vector3_text(*v);
}

const std::vector<Row>& rows() {
  using I = LogInfo;
  static const std::vector<Row> r = {
      {"sample_rate_hz", [](const I& i) { return num(i.sample_rate_hz); }},
      {"latitude_deg", [](const I& i) { return num(i.latitude_deg); }},
      {"hinge1_axis", [](const I& i) { return vec(i.hinge1_axis); }},
      {"hinge2_axis", [](const I& i) { return vec(i.hinge2_axis); }},
      {"source", [](const I& i) { return str(i.source); }},
      {"scenario", [](const I& i) { return str(i.scenario); }},
      {"seed",
       [](const I& i) -> std::optional<std::string> {
         if (!i.seed) return std::nullopt;
         return std::to_string(*i.seed);
       }},
      {"duration_s", [](const I& i) { return num(i.duration_s); }},
      {"motion", [](const I& i) { return str(i.motion); }},
      {"carrier", [](const I& i) { return str(i.carrier); }},
      {"platform_readback", [](const I& i) { return str(i.platform_readback); }},
      {"flip_angle_deg", [](const I& i) { return num(i.flip_angle_deg); }},
      {"standstill_s", [](const I& i) { return num(i.standstill_s); }},
      {"flip_control", [](const I& i) { return str(i.flip_control); }},
      {"end_stop_deg", [](const I& i) { return num(i.end_stop_deg); }},
      {"sensor1_preset", [](const I& i) { return str(i.sensor1_preset); }},
      {"sensor2_preset", [](const I& i) { return str(i.sensor2_preset); }},
  };
  return r;
}

}  // namespace

void write_log_info(Metadata& meta, const LogInfo& info) {
  for (const auto& row : rows()) {
    if (auto t = row.text(info)) meta.set(row.key, std::move(*t));
  }
}

std::string vector3_text(const Eigen::Vector3d& v) {
  return exact_number(v.x()) + " " + exact_number(v.y()) + " " + exact_number(v.z());
}

void set_number(Metadata& meta, const std::string& key, double value) { meta.set(key, exact_number(value)); }

void set_vector3(Metadata& meta, const std::string& key, const Eigen::Vector3d& v) { meta.set(key, vector3_text(v)); }

}  // namespace driftless::log
