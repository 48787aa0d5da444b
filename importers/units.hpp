// The importers' units: the one unit table (estimator/units.hpp) read for rates, accelerations
// and time, by key suffix or spelling, case-insensitive, with the factor to the project's unit
// (deg/s, m/s^2, s); plus the raw-count form lsb:<LSB per unit>. docs/import.md, units.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "importers/imu_reader.hpp"

namespace driftless::importers {

/// A unit with its factor to the project unit of its quantity and its display name.
struct Unit {
  double scale = 1.0;  // multiply a value in this unit to get deg/s, m/s^2, s or degC
  std::string name;    // e.g. "rad/s", "lsb:131"
};

/// Rate units: deg/s (dps), rad/s, lsb:<LSB per deg/s>. Throws ImportError naming the option.
Unit parse_rate_unit(const std::string& s, std::string_view option);
/// Acceleration units: m/s^2, g, lsb:<LSB per g>.
Unit parse_accel_unit(const std::string& s, std::string_view option);
/// Time units: s, ms, us, ns.
Unit parse_time_unit(const std::string& s, std::string_view option);

/// A unit written in a header name, e.g. "w_RS_S_x [rad s^-1]", "gyro_x(deg/s)", "t[ns]".
std::optional<Unit> unit_in_name(std::string_view name, Quantity q);
/// The time unit written in a header name ("[ns]", "_us", "(ms)", ...).
std::optional<Unit> time_unit_in_name(std::string_view name);

/// The time unit that makes a median step `dt_raw` a rate between 1 Hz and 100 kHz, trying s, ms,
/// us, ns in that order; `why` explains the choice.
Unit time_unit_from_step(double dt_raw, std::string* why);

}  // namespace driftless::importers
