#include "cli/estimate_health_accel.hpp"

#include <cmath>
#include <string_view>

#include <fmt/format.h>

#include "estimator/accel_check.hpp"
#include "estimator/units.hpp"

namespace driftless::cli {
namespace {

// the acceleration unit of the one unit table whose factor to m/s^2 is `factor` ("g", "mg", ...)
std::string unit_of_factor(double factor) {
  const units::Unit* mps2 = units::find("mps2");
  for (const units::Unit& u : units::table()) {
    if (u.quantity == units::Quantity::kAccel && std::fabs(units::factor(u, *mps2) / factor - 1.0) < 1e-9) {
      return std::string(units::label(u));
    }
  }
  return "?";
}

// what the wrong columns spoiled, by the finding's severity (failed: the self-calibration used them)
std::string accel_consequence(const est::HealthFinding& f) {
  return f.severity == est::HealthVerdict::kFailed
             ? "the self-calibration's g-sensitivity states were driven by them, so its biases and G are not the "
               "sensors'"
             : "the g-sensitivity correction and the box's up direction used them";
}

std::string accel_text(const est::HealthFinding& f) {
  const int sensor = f.components.empty() ? 1 : f.components.front();
  const std::string cols = fmt::format("accel{}_x/y/z", sensor);
  const double g = kStandardGravityMps2;
  if (f.cause == est::HealthCause::kAccelEmpty) {
    return fmt::format("{} read |f| = {:.3g} at the standstills (median of {} samples), where gravity alone is "
                       "{:g} m/s^2: the columns are empty (all zero, or a logger that did not fill them); {}. Fill "
                       "them, or drop them (with ref_q in the log the self-calibration then takes gravity from it)",
                       cols, f.value, f.count, g, accel_consequence(f));
  }
  if (std::isfinite(f.suggested)) {
    const std::string unit = unit_of_factor(f.suggested);
    return fmt::format("{} read |f| = {:.4g} at the standstills (median of {} samples), where the log format wants "
                       "m/s^2 (gravity {:g}): the columns are in {} (multiply them by {:.6g} to get m/s^2); {}",
                       cols, f.value, f.count, g, unit, f.suggested, accel_consequence(f));
  }
  return fmt::format("{} read |f| = {:.4g} at the standstills (median of {} samples): neither gravity in m/s^2 "
                     "({:g}) nor in g, mg or ug; a wrong scale, or a box far from 1 g while the platforms rest? "
                     "Check the accel columns (the self-calibration's g-sensitivity used them)",
                     cols, f.value, f.count, g);
}

// "sensor 1 G[z][x] 0.0001 +- 0.0577" for the first few uncertain elements
std::string element_list(const est::HealthFinding& f) {
  constexpr std::size_t kShown = 6;
  constexpr const char* kAxes = "xyz";
  std::string o;
  for (std::size_t i = 0; i < f.components.size() && i < kShown; ++i) {
    const int c = f.components[i];
    const int sensor = c / 100, g = (c % 100) < 10, rc = c % 10;
    o += fmt::format("{}sensor {} {}[{}][{}] {:.4f} +- {:.4f}", i ? ", " : "", sensor, g ? "G" : "E", kAxes[rc / 3],
                     kAxes[rc % 3], f.positions_deg[i][0], f.positions_deg[i][1]);
  }
  if (f.components.size() > kShown) o += fmt::format(" and {} more", f.components.size() - kShown);
  return o;
}

}  // namespace

std::string describe_accel(const est::HealthFinding& f) {
  if (f.cause != est::HealthCause::kCalibUncertain) return accel_text(f);
  return fmt::format(
      "the calibration's g-sensitivity G / scale-misalignment E hold {} of {:g} elements whose sigma is not small "
      "against the value (above a third of it, and above {:g} deg/s per g for G, {:g} for E), as a "
      "self-calibration leaves the elements its log did not observe: {}. Without the self-calibration they are "
      "applied as exact corrections, which for those elements is no better than none; use it with --selfcal (G "
      "and E then start at the file's values with the file's sigma, and learn)",
      f.count, f.value, est::kCalibGSigmaFloorDpsPerG, est::kCalibESigmaFloor, element_list(f));
}

}  // namespace driftless::cli
