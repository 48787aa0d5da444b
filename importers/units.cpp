#include "importers/units.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

#include <fast_float/fast_float.h>

#include "estimator/sample.hpp"
#include "estimator/units.hpp"

namespace driftless::importers {
namespace {

// the importers' quantities in the one unit table (estimator/units.hpp), and the project unit each
// is converted to: deg/s, m/s^2, s
units::Quantity table_quantity(Quantity q) { return q == Quantity::kRate ? units::Quantity::kRate : units::Quantity::kAccel; }
const units::Unit& project_unit(units::Quantity q) {
  static const units::Unit& dps = *units::find("dps");
  static const units::Unit& mps2 = *units::find("mps2");
  static const units::Unit& s = *units::find("s");
  return q == units::Quantity::kRate ? dps : q == units::Quantity::kAccel ? mps2 : s;
}

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

Unit to_project(const units::Unit& u) {
  return Unit{units::factor(u, project_unit(u.quantity)), std::string(units::label(u))};
}

// a unit of quantity q by its key suffix or any spelling, case-insensitive
std::optional<Unit> lookup(units::Quantity q, std::string_view s) {
  const std::string l = lower(s);
  for (const auto& u : units::table()) {
    if (u.quantity != q) continue;
    bool hit = lower(u.suffix) == l;
    for (const auto sp : u.spellings) hit = hit || lower(sp) == l;
    if (hit) return to_project(u);
  }
  return std::nullopt;
}

// "lsb:<counts per unit>": raw ADC counts
std::optional<Unit> parse_lsb(std::string_view s, double unit_scale) {
  if (s.substr(0, 4) != "lsb:") return std::nullopt;
  double lsb = 0.0;
  const auto r = fast_float::from_chars(s.data() + 4, s.data() + s.size(), lsb);
  if (r.ec != std::errc() || r.ptr != s.data() + s.size() || !(lsb > 0.0)) return std::nullopt;
  return Unit{unit_scale / lsb, std::string(s)};
}

Unit parse_unit(units::Quantity q, const std::string& s, std::string_view option, const char* expected,
                double lsb_scale) {
  if (auto u = lookup(q, s)) return *u;
  if (lsb_scale > 0.0) {
    if (auto u = parse_lsb(s, lsb_scale)) return *u;
  }
  throw ImportError(std::string(option) + ": expected " + expected + " (or another unit of " +
                    units::list_of(q) + "), got '" + s + "'");
}

// the text inside [..] or (..) of a header name, or after its last '_' ("t_ns")
std::vector<std::string> unit_tokens(std::string_view name) {
  std::vector<std::string> out;
  for (const auto& [open, close] : {std::pair{'[', ']'}, std::pair{'(', ')'}}) {
    const auto a = name.find(open), b = name.rfind(close);
    if (a != std::string_view::npos && b != std::string_view::npos && b > a) out.emplace_back(name.substr(a + 1, b - a - 1));
  }
  const auto u = name.rfind('_');
  if (u != std::string_view::npos) out.emplace_back(name.substr(u + 1));
  return out;
}

}  // namespace

Unit parse_rate_unit(const std::string& s, std::string_view option) {
  return parse_unit(units::Quantity::kRate, s, option, "deg/s, rad/s or lsb:<LSB per deg/s> (MPU6050 +-250 deg/s: lsb:131)",
                    1.0);
}

Unit parse_accel_unit(const std::string& s, std::string_view option) {
  return parse_unit(units::Quantity::kAccel, s, option, "m/s^2, g or lsb:<LSB per g> (MPU6050 +-2 g: lsb:16384)",
                    kStandardGravityMps2);
}

Unit parse_time_unit(const std::string& s, std::string_view option) {
  return parse_unit(units::Quantity::kTime, s, option, "s, ms, us or ns", 0.0);
}

std::optional<Unit> unit_in_name(std::string_view name, Quantity q) {
  for (const std::string& tok : unit_tokens(name)) {
    if (q == Quantity::kTemperature) continue;
    if (auto u = lookup(table_quantity(q), tok)) return u;
  }
  return std::nullopt;
}

std::optional<Unit> time_unit_in_name(std::string_view name) {
  for (const std::string& tok : unit_tokens(name)) {
    if (auto u = lookup(units::Quantity::kTime, tok)) return u;
  }
  return std::nullopt;
}

Unit time_unit_from_step(double dt_raw, std::string* why) {
  for (const char* suffix : {"s", "ms", "us", "ns"}) {
    const Unit u = to_project(*units::find(suffix));
    const double rate = 1.0 / (dt_raw * u.scale);
    if (rate >= 1.0 && rate <= 1e5) {
      if (why != nullptr) {
        char b[160];
        std::snprintf(b, sizeof b, "time in %s: the median step %.4g then means %.4g Hz (the first of s, ms, us, ns giving 1 Hz..100 kHz)",
                      u.name.c_str(), dt_raw, rate);
        *why = b;
      }
      return u;
    }
  }
  if (why != nullptr) {
    char b[120];
    std::snprintf(b, sizeof b, "time in s: no unit puts the median step %.4g in 1 Hz..100 kHz", dt_raw);
    *why = b;
  }
  return Unit{1.0, "s"};
}

}  // namespace driftless::importers
