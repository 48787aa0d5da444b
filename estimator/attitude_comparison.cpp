#include "estimator/attitude_comparison.hpp"

#include <cmath>

#include "estimator/geometry.hpp"

namespace driftless::est {

bool filter_locked(const DriftlessFilter& filter, double start_sigma_dps) {
  return start_sigma_dps <= 0.0 || (filter.has_update() && filter.sigma_dps().maxCoeff() < start_sigma_dps);
}

AttitudeComparison::AttitudeComparison(double latitude_deg, double start_sigma_dps, double interval_s)
    : AttitudeComparison(latitude_deg, AttitudeComparisonOptions{start_sigma_dps, interval_s}) {}

AttitudeComparison::AttitudeComparison(double latitude_deg, const AttitudeComparisonOptions& opt)
    : tracks_{Track{AttitudeIntegrator(latitude_deg), {}, {}}, Track{AttitudeIntegrator(latitude_deg), {}, {}},
              Track{AttitudeIntegrator(latitude_deg), {}, {}}},
      opt_(opt) {}

bool AttitudeComparison::push(const Sample& s, DriftlessFilter& filter, AttitudePoint& ap) {
  const bool ref_ok = s.ref_q_wxyz.allFinite();
  if (ref_ok && !started()) {
    const bool truth_ok = opt_.fixed_bias_from != FixedBiasFrom::kTruth ||
                          (s.true_bias1_dps.allFinite() && s.true_bias2_dps.allFinite());
    if (truth_ok && filter_locked(filter, opt_.start_sigma_dps)) start(s, filter);
  } else if (started() && std::isfinite(s.t_s)) {
    step(s, filter.output());
  }
  if (!ref_ok || !started()) return false;
  if (std::isnan(realign_s_) && s.t_s >= opt_.realign_at_s) {
    realign(s, ap);
    return true;
  }
  return compare(s, ap);
}

// the three integrations start together at `s`: the bias estimate then (or the truth, for a
// perfect turn-on calibration) is what a box calibrated once would keep, and `fixed` holds it
void AttitudeComparison::start(const Sample& s, DriftlessFilter& filter) {
  if (opt_.fixed_bias_from == FixedBiasFrom::kTruth) {
    fixed_bias_dps_ << s.true_bias1_dps, s.true_bias2_dps;
  } else {
    fixed_bias_dps_ = filter.bias_dps();
  }
  filter.set_fixed_bias_dps(fixed_bias_dps_);  // the next sample's fixed rate uses it
  start_s_ = aligned_s_ = s.t_s;
  for (Track& tr : tracks_) tr.att.reset(s.q_enu_from_body(), s.t_s);
  next_t_ = s.t_s;
}

void AttitudeComparison::step(const Sample& s, const SampleOutput& out) {
  tracks_[kCorrected].att.step(s.t_s, out.rate_body_dps);
  tracks_[kRaw].att.step(s.t_s, out.rate_body_raw_dps);
  tracks_[kFixed].att.step(s.t_s, out.rate_body_fixed_dps);
}

// every integration restarts on the reference: the comparison (points, unwrapped errors, drift
// fits) begins again here; the fixed bias stays what it was
void AttitudeComparison::realign(const Sample& s, AttitudePoint& ap) {
  realign_s_ = aligned_s_ = last_ref_s_ = s.t_s;
  const Eigen::Quaterniond q_ref = s.q_enu_from_body();
  for (Track& tr : tracks_) {
    tr.att.reset(q_ref, s.t_s);
    tr.acc = ErrorAccumulator{};
    tr.acc.add(q_ref, q_ref);
    tr.err_deg.assign(1, 0.0);
    tr.last_err = Eigen::Quaterniond::Identity();
  }
  t_.assign(1, s.t_s);
  ap = AttitudePoint{};
  ap.t_s = s.t_s;
  ap.corrected_accumulated_deg = ap.raw_accumulated_deg = ap.fixed_accumulated_deg = 0.0;
  ap.realigned = true;
  next_t_ = s.t_s + opt_.interval_s;
}

// compares with the reference; returns true (and fills `ap`) at a comparison point
bool AttitudeComparison::compare(const Sample& s, AttitudePoint& ap) {
  const Eigen::Quaterniond q_ref = s.q_enu_from_body();
  for (Track& tr : tracks_) {
    tr.acc.add(tr.att.q_enu_from_body(), q_ref);
    tr.last_err = tr.att.q_enu_from_body() * q_ref.conjugate();
  }
  last_ref_s_ = s.t_s;
  if (!(s.t_s >= next_t_)) return false;
  ap.t_s = s.t_s;
  ap.corrected = attitude_error(tracks_[kCorrected].att.q_enu_from_body(), q_ref);
  ap.raw = attitude_error(tracks_[kRaw].att.q_enu_from_body(), q_ref);
  ap.fixed = attitude_error(tracks_[kFixed].att.q_enu_from_body(), q_ref);
  ap.corrected_accumulated_deg = tracks_[kCorrected].acc.angle_deg();
  ap.raw_accumulated_deg = tracks_[kRaw].acc.angle_deg();
  ap.fixed_accumulated_deg = tracks_[kFixed].acc.angle_deg();
  ap.realigned = false;
  t_.push_back(ap.t_s);
  // the drift is fitted to the unwrapped error: a raw gyro's error angle folds at 180 deg
  for (Track& tr : tracks_) tr.err_deg.push_back(tr.acc.angle_deg());
  next_t_ += opt_.interval_s;
  return true;
}

AttitudeDrifts AttitudeComparison::drifts() const {
  AttitudeDrifts d;
  if (t_.size() >= 2) {
    d.corrected_deg_per_h = drift_deg_per_h(t_, tracks_[kCorrected].err_deg);
    d.raw_deg_per_h = drift_deg_per_h(t_, tracks_[kRaw].err_deg);
    d.fixed_deg_per_h = drift_deg_per_h(t_, tracks_[kFixed].err_deg);
  }
  // net: the error at the last ref_q over the span since the (re-)alignment
  const double span_h = (last_ref_s_ - aligned_s_) / 3600.0;
  const bool realign_missing = !std::isnan(opt_.realign_at_s) && std::isnan(realign_s_);
  if (span_h > 0.0 && !realign_missing) {
    const auto net = [&](int k) { return geo::rotvec_rad(tracks_[k].last_err).norm() * kDegPerRad / span_h; };
    d.net_corrected_deg_per_h = net(kCorrected);
    d.net_raw_deg_per_h = net(kRaw);
    d.net_fixed_deg_per_h = net(kFixed);
  }
  return d;
}

}  // namespace driftless::est
