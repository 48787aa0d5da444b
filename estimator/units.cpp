#include "estimator/units.hpp"

#include "estimator/sample.hpp"

namespace driftless::units {

const std::vector<Unit>& table() {
  using Q = Quantity;
  constexpr double kDeg = kRadPerDeg;
  constexpr double kG = kStandardGravityMps2;
  static const std::vector<Unit> u = {
      {"deg", Q::kAngle, kDeg, {"deg", "°"}},
      {"rad", Q::kAngle, 1.0, {"rad"}},
      {"arcmin", Q::kAngle, kDeg / 60.0, {"arcmin"}},
      {"arcsec", Q::kAngle, kDeg / 3600.0, {"arcsec"}},
      {"dps", Q::kRate, kDeg, {"deg/s", "dps", "deg s^-1"}},
      {"dph", Q::kRate, kDeg / 3600.0, {"deg/h"}},
      {"radps", Q::kRate, 1.0, {"rad/s", "rad s^-1", "rps"}},
      {"dps2", Q::kAngularAccel, kDeg, {"deg/s^2", "deg/s2"}},
      {"radps2", Q::kAngularAccel, 1.0, {"rad/s^2"}},
      {"dps_rthz", Q::kRateDensity, kDeg, {"deg/s/sqrt(Hz)"}},
      {"dph_rthz", Q::kRateDensity, kDeg / 3600.0, {"deg/h/sqrt(Hz)"}},
      {"deg_rth", Q::kRateDensity, kDeg / 60.0, {"deg/sqrt(h)"}},
      {"radps_rthz", Q::kRateDensity, 1.0, {"rad/s/sqrt(Hz)"}},
      {"dps_rts", Q::kRateRandomWalk, kDeg, {"deg/s/sqrt(s)"}},
      {"dph_rth", Q::kRateRandomWalk, kDeg / 216000.0, {"deg/h/sqrt(h)"}},
      {"radps_rts", Q::kRateRandomWalk, 1.0, {"rad/s/sqrt(s)"}},
      {"s", Q::kTime, 1.0, {"s", "sec"}},
      {"ms", Q::kTime, 1e-3, {"ms"}},
      {"us", Q::kTime, 1e-6, {"us", "µs", "usec"}},
      {"ns", Q::kTime, 1e-9, {"ns", "nsec"}},
      {"min", Q::kTime, 60.0, {"min"}},
      {"h", Q::kTime, 3600.0, {"h"}},
      {"hz", Q::kFrequency, 1.0, {"Hz", "hz"}},
      {"khz", Q::kFrequency, 1e3, {"kHz"}},
      {"degc", Q::kTemperature, 1.0, {"degC"}},
      {"pct", Q::kRatio, 1e-2, {"%"}},
      {"ppm", Q::kRatio, 1e-6, {"ppm"}},
      {"frac", Q::kRatio, 1.0, {"fraction"}},
      {"dps_per_g", Q::kRatePerAccel, kDeg / kG, {"deg/s per g"}},
      {"dph_per_g", Q::kRatePerAccel, kDeg / 3600.0 / kG, {"deg/h per g"}},
      {"radps_per_mps2", Q::kRatePerAccel, 1.0, {"rad/s per m/s^2"}},
      {"dps_per_degc", Q::kRatePerTemp, kDeg, {"deg/s per degC"}},
      {"dph_per_degc", Q::kRatePerTemp, kDeg / 3600.0, {"deg/h per degC"}},
      {"radps_per_degc", Q::kRatePerTemp, 1.0, {"rad/s per degC"}},
      {"pct_per_degc", Q::kRatioPerTemp, 1e-2, {"% per degC"}},
      {"ppm_per_degc", Q::kRatioPerTemp, 1e-6, {"ppm per degC"}},
      {"m", Q::kLength, 1.0, {"m"}},
      {"mm", Q::kLength, 1e-3, {"mm"}},
      {"cm", Q::kLength, 1e-2, {"cm"}},
      {"km", Q::kLength, 1e3, {"km"}},
      {"mps", Q::kSpeed, 1.0, {"m/s"}},
      {"kmh", Q::kSpeed, 1.0 / 3.6, {"km/h"}},
      {"mps2", Q::kAccel, 1.0, {"m/s^2", "m/s2", "m s^-2"}},
      {"g", Q::kAccel, kG, {"g"}},
      {"mg", Q::kAccel, kG * 1e-3, {"mg"}},
      {"ug", Q::kAccel, kG * 1e-6, {"ug"}},
      {"mps2_rthz", Q::kAccelDensity, 1.0, {"m/s^2/sqrt(Hz)"}},
      {"mg_rthz", Q::kAccelDensity, kG * 1e-3, {"mg/sqrt(Hz)"}},
      {"ug_rthz", Q::kAccelDensity, kG * 1e-6, {"ug/sqrt(Hz)"}},
      {"per_km", Q::kPerLength, 1e-3, {"1/km"}},
      {"per_m", Q::kPerLength, 1.0, {"1/m"}},
      {"nm", Q::kTorque, 1.0, {"N m", "Nm"}},
      {"nm_per_rad", Q::kTorquePerAngle, 1.0, {"N m/rad"}},
      {"nms_per_rad", Q::kTorqueTimePerAngle, 1.0, {"N m s/rad"}},
      {"kgm2", Q::kInertia, 1.0, {"kg m^2"}},
      {"lsb_per_dps", Q::kGyroSensitivity, 1.0, {"LSB per deg/s"}},
      {"lsb_per_g", Q::kAccelSensitivity, 1.0, {"LSB per g"}},
      {"lsb_per_degc", Q::kTempSensitivity, 1.0, {"LSB per degC"}},
  };
  return u;
}

const Unit* find(std::string_view suffix) {
  for (const auto& u : table()) {
    if (u.suffix == suffix) return &u;
  }
  return nullptr;
}

std::string_view label(const Unit& u) { return u.spellings.front(); }

std::string list_of(Quantity q) {
  std::string s;
  for (const auto& u : table()) {
    if (u.quantity == q) s += (s.empty() ? "" : ", ") + std::string(u.suffix) + " (" + std::string(label(u)) + ")";
  }
  return s;
}

double factor(const Unit& from, const Unit& to) { return &from == &to ? 1.0 : from.to_base / to.to_base; }

}  // namespace driftless::units
