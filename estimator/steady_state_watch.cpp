// The steady state of a run from its first updates (steady_state_watch.hpp).
#include "estimator/steady_state_watch.hpp"

#include <cmath>

namespace driftless::est {

void SteadyStateWatch::on_update(const UpdateRecord& rec, const DriftlessFilter& filter) {
  if (n_ >= kScheduleUpdates) return;
  // the closed form is the general mode's windowed 3-row update; a re-lock or an update at the
  // log's end (a standstill cut short) would not be a sample of the schedule
  const EstimatorConfig& cfg = filter.config();
  if (cfg.mode != FilterMode::kGeneral || cfg.per_sample_updates || rec.dim != 3) return;
  if (rec.at_end || rec.relocked || !std::isfinite(rec.t_s) || !std::isfinite(rec.t_start_s) || rec.samples == 0) return;
  if (n_ == 0) t_first_s_ = rec.t_s;
  t_last_s_ = rec.t_s;
  ++n_;
  sum_window_s_ += rec.t_s - rec.t_start_s;
  sum_samples_ += double(rec.samples);
  if (n_ == kScheduleUpdates) predict(filter, rec.t_s);
}

void SteadyStateWatch::predict(const DriftlessFilter& filter, double t_s) {
  const EstimatorConfig& cfg = filter.config();
  const double n = double(n_);
  UpdateSchedule& s = pred_.schedule;
  s.q_dps2_per_s = cfg.q_dps2_per_s();
  s.interval_s = (t_last_s_ - t_first_s_) / (n - 1.0);
  s.window_s = sum_window_s_ / n;
  s.meas_var_dps2 = cfg.sample_variance_dps2(filter.geometry().sample_rate_hz) / (sum_samples_ / n);
  if (!(s.window_s <= s.interval_s)) return;  // overlapping windows: no periodic schedule
  pred_.closed = bias_steady_state(s);
  if (!std::isfinite(pred_.closed.sigma_dps)) return;
  pred_.available = true;
  pred_.known_at_t_s = t_s;
  pred_.lock_sigma_dps = lock_sigma_dps_;
  pred_.interval_for_lock_s = interval_for_sigma_s(s, kSteadyStateLockMargin * lock_sigma_dps_);
  const bool temp_known = std::isfinite(filter.temperature_ref_c()[0]) || std::isfinite(filter.temperature_ref_c()[1]);
  pred_.other_states = filter.has_gsens_states() || filter.has_scale_states() || (filter.has_temp_states() && temp_known);
}

}  // namespace driftless::est
