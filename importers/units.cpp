#include "importers/units.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>

#include <fast_float/fast_float.h>

namespace driftless::importers {
namespace {

constexpr double kDegPerRad = 57.295779513082320876798;
constexpr double kStandardGravityMps2 = 9.80665;

struct NamedUnit {
  const char* name;
  double scale;
};

// one table per quantity: accepted spellings and their factor to the project unit
constexpr std::array<NamedUnit, 6> kRateUnits = {{
    {"deg/s", 1.0}, {"dps", 1.0}, {"deg s^-1", 1.0}, {"rad/s", kDegPerRad}, {"rad s^-1", kDegPerRad}, {"rps", kDegPerRad}}};
constexpr std::array<NamedUnit, 5> kAccelUnits = {{
    {"m/s^2", 1.0}, {"m/s2", 1.0}, {"m s^-2", 1.0}, {"g", kStandardGravityMps2}, {"mg", 1e-3 * kStandardGravityMps2}}};
constexpr std::array<NamedUnit, 8> kTimeUnits = {{
    {"s", 1.0}, {"sec", 1.0}, {"ms", 1e-3}, {"us", 1e-6}, {"µs", 1e-6}, {"ns", 1e-9}, {"nsec", 1e-9}, {"usec", 1e-6}}};

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

template <std::size_t N>
std::optional<Unit> lookup(const std::array<NamedUnit, N>& table, std::string_view s) {
  const std::string l = lower(s);
  for (const auto& u : table) {
    if (l == u.name) return Unit{u.scale, u.name};
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

template <std::size_t N>
Unit parse_unit(const std::array<NamedUnit, N>& table, const std::string& s, std::string_view option,
                const char* expected, double lsb_scale) {
  if (auto u = lookup(table, s)) return *u;
  if (lsb_scale > 0.0) {
    if (auto u = parse_lsb(s, lsb_scale)) return *u;
  }
  throw ImportError(std::string(option) + ": expected " + expected + ", got '" + s + "'");
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
  return parse_unit(kRateUnits, s, option, "deg/s, rad/s or lsb:<LSB per deg/s> (MPU6050 +-250 deg/s: lsb:131)", 1.0);
}

Unit parse_accel_unit(const std::string& s, std::string_view option) {
  return parse_unit(kAccelUnits, s, option, "m/s^2, g or lsb:<LSB per g> (MPU6050 +-2 g: lsb:16384)",
                    kStandardGravityMps2);
}

Unit parse_time_unit(const std::string& s, std::string_view option) {
  return parse_unit(kTimeUnits, s, option, "s, ms, us or ns", 0.0);
}

std::optional<Unit> unit_in_name(std::string_view name, Quantity q) {
  for (const std::string& tok : unit_tokens(name)) {
    if (q == Quantity::kRate) {
      if (auto u = lookup(kRateUnits, tok)) return u;
    } else if (q == Quantity::kAccel) {
      if (auto u = lookup(kAccelUnits, tok)) return u;
    }
  }
  return std::nullopt;
}

std::optional<Unit> time_unit_in_name(std::string_view name) {
  for (const std::string& tok : unit_tokens(name)) {
    if (auto u = lookup(kTimeUnits, tok)) return u;
  }
  return std::nullopt;
}

Unit time_unit_from_step(double dt_raw, std::string* why) {
  for (const auto& u : {NamedUnit{"s", 1.0}, NamedUnit{"ms", 1e-3}, NamedUnit{"us", 1e-6}, NamedUnit{"ns", 1e-9}}) {
    const double rate = 1.0 / (dt_raw * u.scale);
    if (rate >= 1.0 && rate <= 1e5) {
      if (why != nullptr) {
        char b[160];
        std::snprintf(b, sizeof b, "time in %s: the median step %.4g then means %.4g Hz (the first of s, ms, us, ns giving 1 Hz..100 kHz)",
                      u.name, dt_raw, rate);
        *why = b;
      }
      return Unit{u.scale, u.name};
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
