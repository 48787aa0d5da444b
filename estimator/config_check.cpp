// The estimator configuration's checks and the quantities it derives (estimator/config.hpp): apart
// from the filter, so that what reads a configuration (estimator/config.cpp, its fuzz harness) needs
// none of the filter's code.
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/LU>

#include "estimator/config.hpp"

namespace driftless::est {
namespace {

constexpr double kBiasInstabilityFactor = 0.6642824702679600;  // sqrt(2 ln 2 / pi)

}  // namespace

void Calibration::validate() const {
  for (int i = 0; i < 2; ++i) {
    if (!G_dps_per_g[static_cast<std::size_t>(i)].allFinite())
      throw std::invalid_argument("calibration: sensor " + std::to_string(i + 1) + " has a non-finite g-sensitivity entry");
    const auto& k = temp_coef_dps_per_degc[static_cast<std::size_t>(i)];
    const auto& ks = temp_coef_sigma_dps_per_degc[static_cast<std::size_t>(i)];
    if (has_temp_coef && (!k.allFinite() || !ks.allFinite() || (ks.array() < 0.0).any()))
      throw std::invalid_argument("calibration: sensor " + std::to_string(i + 1) +
                                  " has a non-finite temperature coefficient or a negative sigma (deg/s per degC)");
  }
  for (int i = 0; i < 2; ++i) {
    const auto iu = static_cast<std::size_t>(i);
    const std::string who = "calibration: sensor " + std::to_string(i + 1);
    if (has_g_sigma && (!G_sigma_dps_per_g[iu].allFinite() || (G_sigma_dps_per_g[iu].array() < 0.0).any()))
      throw std::invalid_argument(who + " has a non-finite or negative g-sensitivity sigma (deg/s per g)");
    if (!has_scale_misalign) continue;
    if (!E_frac[iu].allFinite() || !E_sigma_frac[iu].allFinite() || (E_sigma_frac[iu].array() < 0.0).any())
      throw std::invalid_argument(who + " has a non-finite scale/misalignment entry or a negative sigma (fraction)");
    // (I + E) must be invertible and near I: an E this large is not a scale error but another axis order
    if (!(E_frac[iu].cwiseAbs().maxCoeff() < 0.5))
      throw std::invalid_argument(who + " has a scale/misalignment element of 0.5 (50 %) or more: not a small error");
  }
  // an end stop is off by hundredths of a degree; +-10 deg is the twin's limit too (model.box)
  if (has_end_stops && (!end_stop_deg.allFinite() || !end_stop_sigma_deg.allFinite() ||
                        (end_stop_sigma_deg.array() < 0.0).any() || (end_stop_deg.array().abs() > 10.0).any()))
    throw std::invalid_argument("calibration: an end-stop angle error beyond +-10 deg, not finite, or a negative sigma (deg)");
  if (has_end_stops && !empty())
    throw std::invalid_argument("calibration: end-stop angle errors with calibrated matrices, which hold the stop angles already");
  auto check = [&](const std::vector<CalibratedPosition>& list, int sensor) {
    for (const auto& p : list) {
      if (!std::isfinite(p.plat_deg) || !p.M_body_from_sensor.allFinite()) {
        throw std::invalid_argument("calibration: sensor " + std::to_string(sensor) +
                                    " has a non-finite angle or matrix entry");
      }
      if (std::fabs(p.M_body_from_sensor.determinant()) < 1e-6) {
        throw std::invalid_argument("calibration: sensor " + std::to_string(sensor) + " matrix at " +
                                    std::to_string(p.plat_deg) + " deg is singular");
      }
    }
  };
  check(sensor1, 1);
  check(sensor2, 2);
  if (!(match_tolerance_deg > 0.0)) {
    throw std::invalid_argument("calibration: match_tolerance_deg must be > 0 deg");
  }
}

void EstimatorConfig::validate() const {
  auto positive = [](double v, const char* name, const char* unit) {
    if (!(v > 0.0) || !std::isfinite(v)) {
      throw std::invalid_argument(std::string("estimator config: ") + name + " must be > 0 " + unit +
                                  ", got " + std::to_string(v));
    }
  };
  auto non_negative = [](double v, const char* name, const char* unit) {
    if (!(v >= 0.0) || !std::isfinite(v)) {
      throw std::invalid_argument(std::string("estimator config: ") + name + " must be >= 0 " + unit +
                                  ", got " + std::to_string(v));
    }
  };
  non_negative(settle_s, "settle_s", "s");
  non_negative(min_standstill_s, "min_standstill_s", "s");
  non_negative(end_margin_s, "end_margin_s", "s");
  non_negative(max_standstill_s, "max_standstill_s", "s (0 = never split)");
  positive(angle_tolerance_deg, "angle_tolerance_deg", "deg");
  positive(gyro_motion_threshold_dps, "gyro_motion_threshold_dps", "deg/s");
  positive(standstill_period_s, "standstill_period_s", "s");
  if (!std::isfinite(initial_plat1_deg) || !std::isfinite(initial_plat2_deg)) {
    throw std::invalid_argument("estimator config: initial_plat1_deg/initial_plat2_deg must be numbers (deg)");
  }
  positive(noise_density_dps_rthz, "noise_density_dps_rthz", "deg/s/sqrt(Hz)");
  non_negative(bias_instability_dps, "bias_instability_dps", "deg/s");
  positive(bias_instability_tau_s, "bias_instability_tau_s", "s");
  non_negative(q_override_dps2_per_s, "q_override_dps2_per_s", "(deg/s)^2/s (0 = from spec)");
  non_negative(r_override_dps2, "r_override_dps2", "(deg/s)^2 (0 = from noise density)");
  non_negative(gsens_sigma_dps_per_g, "gsens_sigma_dps_per_g", "deg/s per g");
  non_negative(ref_gravity_accel_sigma_g, "ref_gravity_accel_sigma_g", "g");
  non_negative(ref_gravity_speed_mps, "ref_gravity_speed_mps", "m/s");
  non_negative(scale_misalign_sigma_frac, "scale_misalign_sigma_frac", "fraction");
  positive(box_rest_rate_sigma_dps, "box_rest_rate_sigma_dps", "deg/s");
  positive(box_dwell_rate_dps, "box_dwell_rate_dps", "deg/s");
  non_negative(box_dwell_min_s, "box_dwell_min_s", "s");
  non_negative(box_dwell_margin_s, "box_dwell_margin_s", "s");
  non_negative(flip_angle_sigma_deg, "flip_angle_sigma_deg", "deg");
  positive(flip_max_s, "flip_max_s", "s");
  if (mode == FilterMode::kPaper && (self_calibration || box_at_rest)) {
    throw std::invalid_argument("estimator config: self_calibration and box_at_rest need mode: general");
  }
  non_negative(temp_coef_sigma_dps_per_degc, "temp_coef_sigma_dps_per_degc", "deg/s per degC (0 = no temperature states)");
  if (!std::isfinite(initial_bias_dps)) throw std::invalid_argument("estimator config: initial_bias_dps must be a number");
  positive(initial_sigma_dps, "initial_sigma_dps", "deg/s");
  positive(variance_floor_dps2, "variance_floor_dps2", "(deg/s)^2");
  if (gate_relock_after < 0) {
    throw std::invalid_argument("estimator config: gate_relock_after must be >= 0 (0 = never re-lock)");
  }
  if (!(nis_gate_probability > 0.0 && nis_gate_probability <= 1.0)) {
    throw std::invalid_argument("estimator config: nis_gate_probability must be in (0, 1] (1 = no gate)");
  }
  if (mode == FilterMode::kPaper && per_sample_updates) {
    throw std::invalid_argument(
        "estimator config: per_sample_updates needs mode: general (paper mode stacks standstills)");
  }
  if (mode == FilterMode::kPaper && max_standstill_s > 0.0) {
    throw std::invalid_argument(
        "estimator config: max_standstill_s needs mode: general (eq. (5) expects one update per position)");
  }
  calibration.validate();
}

double EstimatorConfig::q_dps2_per_s() const {
  if (q_override_dps2_per_s > 0.0) return q_override_dps2_per_s;
  // a random walk with sigma_K(tau_B) = 0.664 B: K^2 tau_B / 3 = (0.664 B)^2
  const double k = kBiasInstabilityFactor * bias_instability_dps * std::sqrt(3.0 / bias_instability_tau_s);
  return k * k;
}

double EstimatorConfig::sample_variance_dps2(double sample_rate_hz) const {
  if (r_override_dps2 > 0.0) return r_override_dps2;
  return noise_density_dps_rthz * noise_density_dps_rthz * sample_rate_hz;
}

EstimatorConfig paper_config() {
  EstimatorConfig c;
  c.mode = FilterMode::kPaper;
  c.covariance_update = CovarianceUpdate::kPrinted;
  c.temp_coef_sigma_dps_per_degc = 0.0;  // the paper's model: bias + noise, eq. (3)
  return c;
}

}  // namespace driftless::est
