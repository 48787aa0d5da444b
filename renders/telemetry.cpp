#include "renders/telemetry.hpp"

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
    filter_ = std::make_unique<est::DriftlessFilter>(est::EstimatorConfig{}, meta);
    bias1_.emplace(1, p_.window_s);
    bias2_.emplace(2, p_.window_s);
  }
}

Telemetry::~Telemetry() = default;

void Telemetry::push(const Sample& s, double rest_s, OverlayState& /*st*/) {
  residual_.push(s, rest_s >= p_.settle_s);
  if (filter_) {
    filter_->push(s);  // its status needs no handling here: NaN rows never enter the state
    if (filter_->has_update()) {
      bias1_->push(s.t_s, filter_->bias1_dps(), s.true_bias1_dps);
      bias2_->push(s.t_s, filter_->bias2_dps(), s.true_bias2_dps);
    }
  }
}

std::vector<const StripChart*> Telemetry::charts() const {
  if (filter_) return {&bias2_->chart(), &bias1_->chart()};
  return {&residual_.chart()};
}

}  // namespace driftless::render
