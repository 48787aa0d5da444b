// The estimator's `key: value` configuration format (docs/estimator.md): a flat YAML subset read
// with the standard library only, so the filter's own folder needs no YAML parser. One table
// (estimator/fields.hpp) drives parse, the allowed keys, units and the written config.
#include <istream>
#include <ostream>

#include "estimator/fields.hpp"
#include "estimator/config.hpp"
#include "estimator/input_error.hpp"

namespace driftless::est {
namespace {

using C = EstimatorConfig;

const fields::Names<FilterMode>& mode_names() {
  static const fields::Names<FilterMode> n = {{"paper", FilterMode::kPaper}, {"general", FilterMode::kGeneral}};
  return n;
}

// paper mode brings the printed recursion unless the file says otherwise later
fields::Row<C> mode_row() {
  return fields::custom<C>(
      "mode", "",
      [](C& c, const fields::Node& n, const fields::Reading& r) {
        c.mode = fields::read_choice(n, r, mode_names());
        if (c.mode == FilterMode::kPaper) c.covariance_update = CovarianceUpdate::kPrinted;
      },
      [](const C& c) -> std::optional<fields::Node> {
        return fields::Node::scalar(fields::choice_name(c.mode, mode_names()));
      });
}

// Variances are in (deg/s)^2 (keys ending _dps2, _dps2_per_s): not units of the unit table, where
// dps2 is an angular acceleration, so those keys are whole names without unit conversion.
const fields::Table<C>& config_table() {
  static const fields::Table<C> t = {
      mode_row(),
      fields::choice<C>("covariance_update", &C::covariance_update,
                        fields::Names<CovarianceUpdate>{{"printed", CovarianceUpdate::kPrinted},
                                                        {"joseph", CovarianceUpdate::kJoseph}}),
      fields::choice<C>("standstill", &C::standstill,
                        fields::Names<StandstillSource>{{"platform", StandstillSource::kPlatformColumns},
                                                        {"gyro", StandstillSource::kGyroSignal},
                                                        {"schedule", StandstillSource::kSchedule}}),
      fields::flag<C>("per_sample_updates", &C::per_sample_updates),
      fields::flag<C>("self_calibration", &C::self_calibration),
      fields::flag<C>("box_at_rest", &C::box_at_rest),
      fields::flag<C>("box_dwell_updates", &C::box_dwell_updates),
      fields::flag<C>("flip_updates", &C::flip_updates),
      fields::integer<C>("gate_relock_after", &C::gate_relock_after, 0, 1000000),
      fields::number<C>("angle_tolerance", "deg", &C::angle_tolerance_deg),
      fields::number<C>("bias_instability", "dps", &C::bias_instability_dps),
      fields::number<C>("bias_instability_tau", "s", &C::bias_instability_tau_s),
      fields::number<C>("box_rest_rate_sigma", "dps", &C::box_rest_rate_sigma_dps),
      fields::number<C>("box_dwell_rate", "dps", &C::box_dwell_rate_dps),
      fields::number<C>("box_dwell_min", "s", &C::box_dwell_min_s),
      fields::number<C>("box_dwell_margin", "s", &C::box_dwell_margin_s),
      fields::number<C>("end_margin", "s", &C::end_margin_s),
      fields::number<C>("flip_angle_sigma", "deg", &C::flip_angle_sigma_deg),
      fields::number<C>("flip_max", "s", &C::flip_max_s),
      fields::number<C>("gsens_sigma", "dps_per_g", &C::gsens_sigma_dps_per_g),
      fields::number<C>("ref_gravity_accel_sigma", "g", &C::ref_gravity_accel_sigma_g),
      fields::number<C>("ref_gravity_speed", "mps", &C::ref_gravity_speed_mps),
      fields::number<C>("gyro_motion_threshold", "dps", &C::gyro_motion_threshold_dps),
      fields::number<C>("initial_bias", "dps", &C::initial_bias_dps),
      fields::number<C>("initial_plat1", "deg", &C::initial_plat1_deg),
      fields::number<C>("initial_plat2", "deg", &C::initial_plat2_deg),
      fields::number<C>("initial_sigma", "dps", &C::initial_sigma_dps),
      fields::number<C>("max_standstill", "s", &C::max_standstill_s),
      fields::number<C>("min_standstill", "s", &C::min_standstill_s),
      fields::number<C>("nis_gate_probability", "", &C::nis_gate_probability),
      fields::number<C>("noise_density", "dps_rthz", &C::noise_density_dps_rthz),
      fields::number<C>("q_override_dps2_per_s", "", &C::q_override_dps2_per_s),
      fields::number<C>("r_override_dps2", "", &C::r_override_dps2),
      fields::number<C>("scale_misalign_sigma", "frac", &C::scale_misalign_sigma_frac),
      fields::number<C>("settle", "s", &C::settle_s),
      fields::number<C>("standstill_period", "s", &C::standstill_period_s),
      fields::number<C>("temp_coef_sigma", "dps_per_degc", &C::temp_coef_sigma_dps_per_degc),
      fields::number<C>("variance_floor_dps2", "", &C::variance_floor_dps2),
      fields::number<C>("calibration_match_tolerance", "deg",
                        [](auto& c) -> auto& { return c.calibration.match_tolerance_deg; }),
  };
  return t;
}

}  // namespace

void set_config_value(EstimatorConfig& cfg, const std::string& key, const std::string& value) {
  fields::read_key(config_table(), cfg, key, fields::Node::scalar(value), fields::Context{}, fields::Node{});
}

EstimatorConfig parse_estimator_config(std::istream& in, const std::string& name, EstimatorConfig base) {
  const fields::Node map = fields::read_flat(in, name);
  fields::read_block(config_table(), base, map, fields::Context{name, ""});
  with_location(name, 0, "", [&] { base.validate(); });
  return base;
}

void write_estimator_config(std::ostream& out, const EstimatorConfig& cfg) {
  fields::write_flat(out, fields::write_block(config_table(), cfg));
}

}  // namespace driftless::est
