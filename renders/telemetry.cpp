#include "renders/telemetry.hpp"

#include <cmath>
#include <stdexcept>

namespace driftless::render {

namespace {
constexpr double kAttitudeIntervalS = 0.1;  // s of data between attitude comparisons (overlay, chart)
}  // namespace

void TelemetryParams::validate() const {
  if (!(window_s > 0.0)) throw std::invalid_argument("chart window must be > 0 s");
  if (!(settle_s >= 0.0)) throw std::invalid_argument("settle time must be >= 0 s");
}

Telemetry::Telemetry(const TelemetryParams& p, const log::Metadata& meta)
    : p_(p), residual_(meta.hinge1_axis(), meta.hinge2_axis(), p.window_s) {
  p_.validate();
  if (p_.run_estimator) {
    filter_ = std::make_unique<est::DriftlessFilter>(p_.estimator, est::box_geometry_from_metadata(meta));
    bias1_.emplace(1, p_.window_s);
    bias2_.emplace(2, p_.window_s);
    attitude_chart_.emplace(p_.window_s);
    // the comparison `driftless estimate` makes, from the same lock level, more often
    attitude_.emplace(meta.latitude_deg(), est::EstimateRunOptions{}.attitude_start_sigma_dps, kAttitudeIntervalS);
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
      if (std::isnan(locked_from_s_) && est::filter_locked(*filter_, lock_sigma_dps_)) {
        locked_from_s_ = s.t_s;
      }
    }
    // the attitude comparison of docs/estimator.md section 4: from lock on, against ref_q
    attitude_now_.available = attitude_now_.available || s.ref_q_wxyz.allFinite();
    est::AttitudePoint ap;
    if (attitude_->push(s, *filter_, ap)) {
      attitude_now_.started = true;
      attitude_now_.start_s = attitude_->start_s();
      attitude_now_.corrected_deg = ap.corrected.angle_deg;
      attitude_now_.fixed_deg = ap.fixed.angle_deg;
    }
    attitude_chart_->push(s.t_s, attitude_now_);
  }
  st.attitude = attitude_now_;
}

std::vector<const StripChart*> Telemetry::charts() const {
  if (filter_) return {&bias1_->chart(), &bias2_->chart(), &attitude_chart_->chart()};
  return {&residual_.chart()};
}

}  // namespace driftless::render
