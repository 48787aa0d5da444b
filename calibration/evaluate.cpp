// Bias error and attitude drift of the DriftLess filter on a dynamic log (see evaluate.hpp).
#include "calibration/evaluate.hpp"

#include "estimator/geometry.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/core.h>

namespace driftless::calib {
namespace {

double angle_between_deg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return geo::rotvec_rad((a.conjugate() * b).normalized()).norm() * kDegPerRad;
}

}  // namespace

void EvalOptions::validate() const {
  if (!(skip_s >= 0.0)) throw std::invalid_argument("evaluation: skip_s must be >= 0 s");
}

EvalRow evaluate_log(const std::vector<Sample>& log, const log::Metadata& meta,
                     const est::EstimatorConfig& cfg, const std::string& label,
                     bool bias_estimated, const EvalOptions& opts) {
  opts.validate();
  if (log.size() < 2) throw std::invalid_argument("evaluation: the log holds fewer than 2 samples");
  if (!log.front().ref_q_wxyz.allFinite() || !log.front().true_bias1_dps.allFinite())
    throw std::invalid_argument("evaluation: the log needs ref_q and true_bias columns (a twin log)");
  est::DriftlessFilter filter(cfg, est::box_geometry_from_metadata(meta));
  const double lat_deg = meta.latitude_deg();
  const Eigen::Vector3d w_earth_enu =
      std::isfinite(lat_deg) ? geo::earth_rate_enu_radps(lat_deg) : Eigen::Vector3d::Zero();
  EvalRow row;
  row.label = label;
  row.bias_estimated = bias_estimated;
  Eigen::Quaterniond q = log.front().q_enu_from_body().normalized();
  Eigen::Vector3d w_hold = Eigen::Vector3d::Zero();
  double sq = 0.0, n = 0.0, max_err = 0.0;
  const double t0 = log.front().t_s;
  for (std::size_t k = 0; k < log.size(); ++k) {
    const Sample& s = log[k];
    filter.push(s);
    // the box rate this sample: M_i (y_i - b_i) of the sensors at rest (the filter's fusion),
    // or with the raw outputs; held through samples where no sensor is at rest
    Eigen::Vector3d w_dps = Eigen::Vector3d::Constant(kNaN);
    if (bias_estimated) {
      w_dps = filter.output().rate_body_dps;
    } else {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      int used = 0;
      if (std::isfinite(s.plat1_deg)) sum += filter.body_from_sensor(1, s.plat1_deg) * s.gyro1_dps, ++used;
      if (std::isfinite(s.plat2_deg)) sum += filter.body_from_sensor(2, s.plat2_deg) * s.gyro2_dps, ++used;
      if (used > 0) w_dps = sum / used;
    }
    if (w_dps.allFinite()) w_hold = w_dps;
    if (bias_estimated && s.t_s - t0 >= opts.skip_s) {
      est::Vector6d truth;
      truth << s.true_bias1_dps, s.true_bias2_dps;
      sq += (filter.bias_dps() - truth).squaredNorm();
      n += 6.0;
      row.bias_final_error_dps = (filter.bias_dps() - truth).norm();
    }
    // attitude: integrated from the end of the convergence time, starting at the reference
    if (s.t_s - t0 < opts.skip_s) {
      q = s.q_enu_from_body().normalized();
    } else if (k + 1 < log.size()) {
      const double dt = log[k + 1].t_s - s.t_s;
      // q' = q (w_body - q^-1 w_earth) / 2: box attitude in the Earth-fixed ENU frame
      q = (geo::quat_from_rotvec(-w_earth_enu * dt) * q * geo::quat_from_rotvec(w_hold * kRadPerDeg * dt))
              .normalized();
      const double err = angle_between_deg(log[k + 1].q_enu_from_body().normalized(), q);
      max_err = std::max(max_err, err);
      row.attitude_final_error_deg = err;
    }
  }
  const double duration_h = (log.back().t_s - t0 - opts.skip_s) / 3600.0;
  if (!(duration_h > 0.0)) throw std::invalid_argument("evaluation: the log is not longer than skip_s");
  row.bias_rms_error_dps = n > 0 ? std::sqrt(sq / n) : kNaN;
  row.attitude_max_error_deg = max_err;
  row.attitude_drift_deg_per_h = row.attitude_final_error_deg / duration_h;
  row.updates = filter.counters().updates;
  return row;
}

std::string eval_table(const std::vector<EvalRow>& rows) {
  std::string out =
      "| configuration | bias error RMS (deg/s) | (deg/h) | final bias error (deg/s) | attitude "
      "error final (deg) | max (deg) | drift (deg/h) |\n|---|---|---|---|---|---|---|\n";
  for (const auto& r : rows) {
    const std::string b = r.bias_estimated ? fmt::format("{:.5f}", r.bias_rms_error_dps) : "-";
    const std::string bh = r.bias_estimated ? fmt::format("{:.1f}", r.bias_rms_error_dps * 3600) : "-";
    const std::string bf = r.bias_estimated ? fmt::format("{:.5f}", r.bias_final_error_dps) : "-";
    out += fmt::format("| {} | {} | {} | {} | {:.3f} | {:.3f} | {:.2f} |\n", r.label, b, bh, bf,
                       r.attitude_final_error_deg, r.attitude_max_error_deg,
                       r.attitude_drift_deg_per_h);
  }
  return out;
}

}  // namespace driftless::calib
