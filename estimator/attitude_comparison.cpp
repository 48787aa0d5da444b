#include "estimator/attitude_comparison.hpp"

#include <cmath>

namespace driftless::est {

bool filter_locked(const DriftlessFilter& filter, double start_sigma_dps) {
  return start_sigma_dps <= 0.0 || (filter.has_update() && filter.sigma_dps().maxCoeff() < start_sigma_dps);
}

AttitudeComparison::AttitudeComparison(double latitude_deg, double start_sigma_dps, double interval_s)
    : tracks_{Track{AttitudeIntegrator(latitude_deg), {}, {}}, Track{AttitudeIntegrator(latitude_deg), {}, {}},
              Track{AttitudeIntegrator(latitude_deg), {}, {}}},
      start_sigma_dps_(start_sigma_dps),
      interval_s_(interval_s) {}

bool AttitudeComparison::push(const Sample& s, DriftlessFilter& filter, AttitudePoint& ap) {
  const bool ref_ok = s.ref_q_wxyz.allFinite();
  if (ref_ok && !started()) {
    if (filter_locked(filter, start_sigma_dps_)) start(s, filter);
  } else if (started() && std::isfinite(s.t_s)) {
    step(s, filter.output());
  }
  return ref_ok && started() && compare(s, ap);
}

// the three integrations start together at `s`: the bias estimate then is what a box
// calibrated once would keep, and the `fixed` integration holds it
void AttitudeComparison::start(const Sample& s, DriftlessFilter& filter) {
  filter.set_fixed_bias_dps(filter.bias_dps());  // the next sample's fixed rate uses it
  fixed_bias_dps_ = filter.bias_dps();
  start_s_ = s.t_s;
  for (Track& tr : tracks_) tr.att.reset(s.q_enu_from_body(), s.t_s);
  next_t_ = s.t_s;
}

void AttitudeComparison::step(const Sample& s, const SampleOutput& out) {
  tracks_[kCorrected].att.step(s.t_s, out.rate_body_dps);
  tracks_[kRaw].att.step(s.t_s, out.rate_body_raw_dps);
  tracks_[kFixed].att.step(s.t_s, out.rate_body_fixed_dps);
}

// compares with the reference; returns true (and fills `ap`) at a comparison point
bool AttitudeComparison::compare(const Sample& s, AttitudePoint& ap) {
  for (Track& tr : tracks_) tr.acc.add(tr.att.q_enu_from_body(), s.q_enu_from_body());
  if (!(s.t_s >= next_t_)) return false;
  ap.t_s = s.t_s;
  ap.corrected = attitude_error(tracks_[kCorrected].att.q_enu_from_body(), s.q_enu_from_body());
  ap.raw = attitude_error(tracks_[kRaw].att.q_enu_from_body(), s.q_enu_from_body());
  ap.fixed = attitude_error(tracks_[kFixed].att.q_enu_from_body(), s.q_enu_from_body());
  ap.corrected_accumulated_deg = tracks_[kCorrected].acc.angle_deg();
  ap.raw_accumulated_deg = tracks_[kRaw].acc.angle_deg();
  ap.fixed_accumulated_deg = tracks_[kFixed].acc.angle_deg();
  t_.push_back(ap.t_s);
  // the drift is fitted to the unwrapped error: a raw gyro's error angle folds at 180 deg
  for (Track& tr : tracks_) tr.err_deg.push_back(tr.acc.angle_deg());
  next_t_ += interval_s_;
  return true;
}

AttitudeDrifts AttitudeComparison::drifts() const {
  AttitudeDrifts d;
  if (t_.size() < 2) return d;
  d.corrected_deg_per_h = drift_deg_per_h(t_, tracks_[kCorrected].err_deg);
  d.raw_deg_per_h = drift_deg_per_h(t_, tracks_[kRaw].err_deg);
  d.fixed_deg_per_h = drift_deg_per_h(t_, tracks_[kFixed].err_deg);
  return d;
}

}  // namespace driftless::est
