// The one unit table: every unit suffix a key may carry ("duration_s", "sigma_dph",
// "density_dps_rthz"), the quantity it measures, its factor to that quantity's base unit, and how
// a value may spell it after the number ("600 s", "0.005 deg/s/sqrt(Hz)"). Used by every file
// format (docs/scenario.md "Units", docs/effects.md). Standard library only.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace driftless::units {

/// What a unit measures. Two units convert into each other only within one quantity.
enum class Quantity {
  kAngle,             // base rad
  kRate,              // base rad/s
  kAngularAccel,      // base rad/s^2
  kRateDensity,       // base rad/s/sqrt(Hz) (angle random walk)
  kRateRandomWalk,    // base rad/s/sqrt(s)
  kTime,              // base s
  kFrequency,         // base Hz
  kTemperature,       // base degC
  kRatio,             // base fraction
  kRatePerAccel,      // base rad/s per m/s^2 (g-sensitivity)
  kRatePerTemp,       // base rad/s per degC
  kRatioPerTemp,      // base fraction per degC
  kLength,            // base m
  kSpeed,             // base m/s
  kAccel,             // base m/s^2 (also g, mg, ug)
  kAccelDensity,      // base m/s^2/sqrt(Hz)
  kPerLength,         // base 1/m
  kTorque,            // base N m
  kTorquePerAngle,    // base N m/rad
  kTorqueTimePerAngle,  // base N m s/rad
  kInertia,           // base kg m^2
  kGyroSensitivity,   // LSB per deg/s
  kAccelSensitivity,  // LSB per g
  kTempSensitivity,   // LSB per degC
};

/// One unit: the key suffix, its quantity, value * to_base = value in the quantity's base unit,
/// and the spellings a value may carry after the number (the first is the label in messages).
struct Unit {
  std::string_view suffix;
  Quantity quantity;
  double to_base;
  std::vector<std::string_view> spellings;
};

/// Every unit, grouped by quantity.
const std::vector<Unit>& table();
/// The unit with key suffix `suffix`, or nullptr.
const Unit* find(std::string_view suffix);
/// The unit's label for messages ("deg/s" for dps).
std::string_view label(const Unit& u);
/// "dps (deg/s), dph (deg/h), radps (rad/s)": the units of one quantity, for messages.
std::string list_of(Quantity q);
/// Factor taking a value in unit `from` to unit `to` (same quantity): 1 exactly when equal.
double factor(const Unit& from, const Unit& to);

}  // namespace driftless::units
