#include "estimator/pipeline.hpp"

#include <array>
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
  const double lat = meta.latitude_deg();
  // the three attitude integrations of docs/estimator.md section 4, each with its unwrapped
  // error (updated every sample with a ref_q) and that error at the comparison points
  struct Track {
    AttitudeIntegrator att;
    ErrorAccumulator acc;
    std::vector<double> err_deg;
  };
  enum { kCorrected, kRaw, kFixed };
  std::array<Track, 3> tracks{Track{AttitudeIntegrator(lat), {}, {}}, Track{AttitudeIntegrator(lat), {}, {}},
                              Track{AttitudeIntegrator(lat), {}, {}}};
  std::vector<double> att_t;
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

    // attitude: the three integrations start together at the first finite ref_q once the filter
    // has locked on (every bias sigma below attitude_start_sigma_dps); the bias estimate then is
    // what a box calibrated once would keep: the `fixed` integration holds it
    const bool ref_ok = have_ref && s.ref_q_wxyz.allFinite();
    const bool started = tracks[kCorrected].att.initialized();
    if (ref_ok && !started) {
      const bool locked = opt.attitude_start_sigma_dps <= 0.0 ||
                          (filter.has_update() && filter.sigma_dps().maxCoeff() < opt.attitude_start_sigma_dps);
      if (locked) {
        filter.set_fixed_bias_dps(filter.bias_dps());  // the next sample's fixed rate uses it
        sum.fixed_bias_dps = filter.bias_dps();
        sum.attitude_start_s = s.t_s;
        for (Track& tr : tracks) tr.att.reset(s.q_enu_from_body(), s.t_s);
        next_att_t = s.t_s;
      }
    } else if (started && std::isfinite(s.t_s)) {
      tracks[kCorrected].att.step(s.t_s, out.rate_body_dps);
      tracks[kRaw].att.step(s.t_s, out.rate_body_raw_dps);
      tracks[kFixed].att.step(s.t_s, out.rate_body_fixed_dps);
    }
    if (ref_ok && tracks[kCorrected].att.initialized()) {
      for (Track& tr : tracks) tr.acc.add(tr.att.q_enu_from_body(), s.q_enu_from_body());
      if (s.t_s >= next_att_t) {
        AttitudePoint ap;
        ap.t_s = s.t_s;
        ap.corrected = attitude_error(tracks[kCorrected].att.q_enu_from_body(), s.q_enu_from_body());
        ap.raw = attitude_error(tracks[kRaw].att.q_enu_from_body(), s.q_enu_from_body());
        ap.fixed = attitude_error(tracks[kFixed].att.q_enu_from_body(), s.q_enu_from_body());
        ap.corrected_accumulated_deg = tracks[kCorrected].acc.angle_deg();
        ap.raw_accumulated_deg = tracks[kRaw].acc.angle_deg();
        ap.fixed_accumulated_deg = tracks[kFixed].acc.angle_deg();
        att_t.push_back(ap.t_s);
        // the drift is fitted to the unwrapped error: a raw gyro's error angle folds at 180 deg
        for (Track& tr : tracks) tr.err_deg.push_back(tr.acc.angle_deg());
        sum.final_corrected = ap.corrected;
        sum.final_raw = ap.raw;
        sum.final_fixed = ap.fixed;
        if (sink != nullptr) sink->on_attitude(ap);
        next_att_t += opt.attitude_interval_s;
      }
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
    sum.drift_corrected_deg_per_h = drift_deg_per_h(att_t, tracks[kCorrected].err_deg);
    sum.drift_raw_deg_per_h = drift_deg_per_h(att_t, tracks[kRaw].err_deg);
    sum.drift_fixed_deg_per_h = drift_deg_per_h(att_t, tracks[kFixed].err_deg);
  } else if (have_ref && !tracks[kCorrected].att.initialized() && sum.rows > 0) {
    sum.warnings.push_back(
        "no attitude comparison: the filter never locked on (every bias sigma below " +
        std::to_string(opt.attitude_start_sigma_dps) + " deg/s; the largest is " +
        std::to_string(filter.sigma_dps().maxCoeff()) +
        " deg/s); an attitude start sigma of 0 compares from the log's start");
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
