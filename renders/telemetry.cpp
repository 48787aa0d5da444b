#include "renders/telemetry.hpp"

#include <cmath>
#include <stdexcept>

namespace driftless::render {

void TelemetryParams::validate() const {
  if (!(window_s > 0.0)) throw std::invalid_argument("chart window must be > 0 s");
  if (!(settle_s >= 0.0)) throw std::invalid_argument("settle time must be >= 0 s");
}

Telemetry::Telemetry(const TelemetryParams& p, const log::Metadata& meta)
    : p_(p), residual_(meta.hinge1_axis(), meta.hinge2_axis(), p.window_s) {
  p_.validate();
  if (p_.run_estimator) {
    filter_ = std::make_unique<est::DriftlessFilter>(est::EstimatorConfig{}, est::box_geometry_from_metadata(meta));
    bias1_.emplace(1, p_.window_s);
    bias2_.emplace(2, p_.window_s);
    const double lat = meta.latitude_deg();
    attitude_.emplace(std::isfinite(lat) ? lat : 0.0);
  }
}

Telemetry::~Telemetry() = default;

void Telemetry::push(const Sample& s, double rest_s, OverlayState& st) {
  residual_.push(s, rest_s >= p_.settle_s);
  if (filter_) {
    filter_->push(s);  // its status needs no handling here: NaN rows never enter the state
    if (filter_->has_update()) {
      bias1_->push(s.t_s, filter_->bias1_dps(), s.true_bias1_dps);
      bias2_->push(s.t_s, filter_->bias2_dps(), s.true_bias2_dps);
    }
    // strapdown attitude from the bias-corrected fused rate (paper section 4), started at the
    // first reference attitude and compared with ref_q
    const bool has_ref = s.ref_q_wxyz.allFinite();
    if (has_ref && !attitude_->initialized()) {
      attitude_->reset(s.q_enu_from_body().normalized(), s.t_s);
    } else if (attitude_->initialized()) {
      attitude_->step(s.t_s, filter_->output().rate_body_dps);
      if (has_ref) {
        attitude_error_deg_ = est::attitude_error(attitude_->q_enu_from_body(),
                                                  s.q_enu_from_body().normalized())
                                  .angle_deg;
      }
    }
  }
  st.attitude_error_deg = attitude_error_deg_;
}

std::vector<const StripChart*> Telemetry::charts() const {
  if (filter_) return {&bias2_->chart(), &bias1_->chart()};
  return {&residual_.chart()};
}

}  // namespace driftless::render
