#include "estimator/pipeline.hpp"

#include <cmath>

#include <Eigen/Cholesky>

#include "estimator/stats.hpp"

namespace driftless::est {

EstimateSummary run_estimate(log::LogReader& reader, const EstimatorConfig& cfg, EstimateSink* sink,
                             const EstimateRunOptions& opt, bool (*should_stop)()) {
  EstimateSummary sum;
  const auto& meta = reader.metadata();
  DriftlessFilter filter(cfg, meta);
  sum.log_complete = meta.complete();
  if (!sum.log_complete) {
    sum.warnings.push_back("the log says 'complete: false' (" +
                           meta.get("incomplete_reason").value_or("no reason given") +
                           "); results cover the rows present");
  }
  if (!std::isfinite(meta.latitude_deg())) {
    sum.warnings.push_back("no latitude_deg in the log: the Earth rate is removed at latitude 0");
  }
  const bool have_truth = (reader.fields() & kFieldTrueBias) != 0;
  const bool have_ref = (reader.fields() & kFieldRefQ) != 0;
  sum.attitude_available = have_ref;
  AttitudeIntegrator att_corr(meta.latitude_deg()), att_raw(meta.latitude_deg());
  std::vector<double> att_t, att_err_corr, att_err_raw;
  double next_att_t = kNaN;

  // truth statistics accumulators
  const double band_p = opt.nees_band_probability;
  TruthStats& ts = sum.truth;
  ts.available = have_truth;
  ts.nees_band_lo = chi2_quantile(0.5 * (1.0 - band_p), 6.0);
  ts.nees_band_hi = chi2_quantile(1.0 - 0.5 * (1.0 - band_p), 6.0);
  std::vector<double> err2_per_update;  // mean squared component error per update
  double nees_sum = 0.0;
  std::size_t nees_in = 0, comp_in = 0, comp_n = 0;

  Sample s;
  while (reader.next(s)) {
    if (should_stop != nullptr && (sum.rows & 4095u) == 0 && should_stop()) {
      sum.warnings.push_back("stopped early at t = " + std::to_string(s.t_s) + " s (interrupted)");
      break;
    }
    ++sum.rows;
    if (!std::isfinite(sum.t_first_s)) sum.t_first_s = s.t_s;
    sum.t_last_s = s.t_s;
    const PushStatus st = filter.push(s);
    const SampleOutput& out = filter.output();
    if (sink != nullptr) sink->on_sample(s, out);

    if ((st == PushStatus::kUpdated || st == PushStatus::kRejected)) {
      if (sink != nullptr) sink->on_update(filter.last_update(), filter.covariance_dps2(), s);
      if (have_truth && st == PushStatus::kUpdated && s.true_bias1_dps.allFinite() &&
          s.true_bias2_dps.allFinite()) {
        Vector6d truth;
        truth << s.true_bias1_dps, s.true_bias2_dps;
        const Vector6d e = filter.bias_dps() - truth;
        const Matrix6d& P = filter.covariance_dps2();
        const double nees = e.dot(P.llt().solve(e));
        nees_sum += nees;
        nees_in += (nees >= ts.nees_band_lo && nees <= ts.nees_band_hi) ? 1 : 0;
        for (int i = 0; i < 6; ++i) {
          comp_in += std::fabs(e[i]) <= 3.0 * std::sqrt(P(i, i)) ? 1 : 0;
          ++comp_n;
        }
        err2_per_update.push_back(e.squaredNorm() / 6.0);
        ts.final_error_dps = e;
      }
    }

    // attitude: both integrators start at the first finite ref_q
    if (have_ref && s.ref_q_wxyz.allFinite()) {
      if (!att_corr.initialized()) {
        att_corr.reset(s.q_enu_from_body(), s.t_s);
        att_raw.reset(s.q_enu_from_body(), s.t_s);
        next_att_t = s.t_s;
      } else {
        att_corr.step(s.t_s, out.rate_body_dps);
        att_raw.step(s.t_s, out.rate_body_raw_dps);
      }
      if (s.t_s >= next_att_t) {
        AttitudePoint ap;
        ap.t_s = s.t_s;
        ap.corrected = attitude_error(att_corr.q_enu_from_body(), s.q_enu_from_body());
        ap.raw = attitude_error(att_raw.q_enu_from_body(), s.q_enu_from_body());
        att_t.push_back(ap.t_s);
        att_err_corr.push_back(ap.corrected.angle_deg);
        att_err_raw.push_back(ap.raw.angle_deg);
        sum.final_corrected = ap.corrected;
        sum.final_raw = ap.raw;
        if (sink != nullptr) sink->on_attitude(ap);
        next_att_t += opt.attitude_interval_s;
      }
    } else if (att_corr.initialized() && std::isfinite(s.t_s)) {
      att_corr.step(s.t_s, out.rate_body_dps);
      att_raw.step(s.t_s, out.rate_body_raw_dps);
    }
  }
  sum.rows_missing_gyro = reader.rows_with_missing_gyro();
  if (sum.rows_missing_gyro > 0) {
    sum.warnings.push_back(std::to_string(sum.rows_missing_gyro) +
                           " rows had a missing or NaN gyro value and were skipped");
  }
  if (reader.dropped_truncated_row()) sum.warnings.push_back("the last row was cut off and dropped");
  if (sum.rows == 0) sum.warnings.push_back("the log holds no rows");
  sum.counters = filter.counters();
  if (sum.counters.updates == 0 && sum.rows > 0) {
    sum.warnings.push_back("no filter update: no standstill of at least min_standstill_s was found");
  }
  if (sum.counters.schedule_mismatches > 0) {
    sum.warnings.push_back(std::to_string(sum.counters.schedule_mismatches) +
                           " standstills did not match eq. (5)'s position sequence (paper mode)");
  }
  sum.bias_dps = filter.bias_dps();
  sum.sigma_dps = filter.sigma_dps();
  if (att_t.size() >= 2) {
    sum.drift_corrected_deg_per_h = drift_deg_per_h(att_t, att_err_corr);
    sum.drift_raw_deg_per_h = drift_deg_per_h(att_t, att_err_raw);
  }
  if (!err2_per_update.empty()) {
    const std::size_t n = err2_per_update.size();
    double a = 0.0, b = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      a += err2_per_update[i];
      if (i >= n / 2) b += err2_per_update[i];
    }
    ts.updates = n;
    ts.bias_error_rms_dps = std::sqrt(a / double(n));
    ts.bias_error_rms_second_half_dps = std::sqrt(b / double(n - n / 2));
    ts.nees_mean = nees_sum / double(n);
    ts.nees_mean_band_lo = chi2_quantile(0.5 * (1.0 - band_p), 6.0 * double(n)) / double(n);
    ts.nees_mean_band_hi = chi2_quantile(1.0 - 0.5 * (1.0 - band_p), 6.0 * double(n)) / double(n);
    ts.nees_fraction_in_band = double(nees_in) / double(n);
    ts.within_3sigma_fraction = double(comp_in) / double(comp_n);
  }
  return sum;
}

}  // namespace driftless::est
