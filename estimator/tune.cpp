#include "estimator/tune.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/QR>

#include "estimator/stats.hpp"

namespace driftless::est {
namespace {

long tenth_deg(double deg) { return std::isfinite(deg) ? std::lround(deg * 10.0) : 1L << 40; }

// the detector cuts every standstill into blocks of block_s (the last piece may be shorter)
EstimatorConfig block_config(EstimatorConfig cfg, const TuneLimits& limits) {
  cfg.mode = FilterMode::kGeneral;
  cfg.per_sample_updates = false;
  cfg.max_standstill_s = limits.block_s;
  cfg.min_standstill_s = 0.5 * limits.block_s;
  return cfg;
}

}  // namespace

NoiseTuner::NoiseTuner(const EstimatorConfig& cfg, const BoxGeometry& box, const TuneLimits& limits)
    : limits_(limits), configured_q_dps2_per_s_(cfg.q_dps2_per_s()), geometry_(block_config(cfg, limits), box), detector_(block_config(cfg, limits), box) {
  if (!(limits_.block_s > 0.0)) throw std::invalid_argument("tune: block_s must be > 0 s");
}

void NoiseTuner::push(const Sample& s) {
  if (!std::isfinite(s.t_s) || !s.gyros_finite()) return;
  if (std::isfinite(last_t_s_) && !(s.t_s > last_t_s_)) return;
  const double dt = std::isfinite(last_t_s_) ? s.t_s - last_t_s_ : kNaN;
  last_t_s_ = s.t_s;
  const StandstillStep st = detector_.push(s, dt, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  for (int i = 0; i < st.closed; ++i) use_piece(detector_.closed(i));
}

// a fit needs this many pairs per coefficient, or the position pair's noise is taken unfitted
constexpr std::uint64_t kPairsPerCoefficient = 4;
// a motion fit is used when noise alone would remove as much in 1 position pair of 1000
constexpr double kMotionFitSignificance = 0.999;
// and when its rate coefficients are a relative scale and misalignment a gyro can have (|c| below
// 0.2; uncalibrated MEMS parts: a few %). On a still box the fused rate x = (n1 + n2)/2 is the two
// sensors' noise, correlated with r's n1 - n2 unless sigma1 = sigma2: a fit there finds
// c = 2 (sigma1^2 - sigma2^2) / (sigma1^2 + sigma2^2), up to 2, and removes the louder sensor's noise
// (a 0.002 + 0.014 deg/s/sqrt(Hz) pair was tuned to 0.0028 instead of 0.0100)
constexpr double kMaxRateCoefficient = 0.2;
// the upper bound of K^2 when the revisits show no wander above the noise: one-sided 97.5 %
constexpr double kWanderBoundZ = 1.96;

// the block's fused body rate and specific force in box axes (zero force without accel columns:
// that coefficient is then not identified and the rank-revealing solve drops it)
NoiseTuner::Regressors NoiseTuner::regressors(const StandstillSegment& seg) const {
  const Eigen::Matrix3d M1 = geometry_.body_from_sensor(1, seg.plat1_deg);
  const Eigen::Matrix3d M2 = geometry_.body_from_sensor(2, seg.plat2_deg);
  Regressors x = Regressors::Zero();
  x.head<3>() = 0.5 * (M1 * seg.mean_gyro1_dps() + M2 * seg.mean_gyro2_dps());
  if (seg.n_accel > 0) {
    x.tail<3>() = 0.5 * (M1 * seg.sum_accel1_mps2 + M2 * seg.sum_accel2_mps2) / double(seg.n_accel);
  }
  return x;
}

// one block: a noise pair with the previous block of the same standstill, and part of the visit
void NoiseTuner::use_piece(const StandstillSegment& seg) {
  if (seg.n == 0) return;
  if (!std::isfinite(rate_hz_)) rate_hz_ = detector_.rate_hz(seg);
  const Eigen::Vector3d r = geometry_.body_from_sensor(1, seg.plat1_deg) * seg.mean_gyro1_dps() -
                            geometry_.body_from_sensor(2, seg.plat2_deg) * seg.mean_gyro2_dps();
  const Regressors x = regressors(seg);
  const std::pair<long, long> key{tenth_deg(seg.plat1_deg), tenth_deg(seg.plat2_deg)};
  const bool same_standstill = have_block_ && seg.t_rest_s == block_rest_s_ && key == visit_key_;
  if (same_standstill && x.allFinite() && block_x_.allFinite()) {
    // weighted so that each pair's noise has the same variance: 6 sigma^2 in |dr|^2
    const double w = 1.0 / (1.0 / double(seg.n) + 1.0 / double(block_n_));
    const Eigen::Vector3d dr = r - block_r_;
    const Regressors dx = x - block_x_;
    MotionFit& m = motion_[key];
    m.xx += w * dx * dx.transpose();
    m.xsx += w * dx * dx.transpose();
    if (have_pair_) m.xsx -= (pair_w_ * w / double(block_n_)) * (pair_dx_ * dx.transpose() + dx * pair_dx_.transpose());
    have_pair_ = true;
    pair_w_ = w;
    pair_dx_ = dx;
    m.xr += w * dx * dr.transpose();
    m.rr += w * dr.squaredNorm();
    ++m.pairs;
    ++noise_pairs_;
  } else {
    have_pair_ = false;
    if (!same_standstill) {
      close_visit();
      visit_key_ = key;
    }
  }
  have_block_ = seg.end == SegmentEnd::kSplit;
  block_rest_s_ = seg.t_rest_s;
  block_n_ = seg.n;
  block_r_ = r;
  block_x_ = x;
  // the visit's mean residual and regressors, and its midpoint (weighted by samples)
  const double t_mid = 0.5 * (seg.t_first_s + seg.t_last_s);
  visit_.t_mid_s = visit_.n == 0 ? t_mid : (visit_.t_mid_s * double(visit_.n) + t_mid * double(seg.n)) /
                                               double(visit_.n + seg.n);
  visit_.r_sum += r * double(seg.n);
  visit_.x_sum += x * double(seg.n);
  visit_.n += seg.n;
}

// a standstill ended: pair it with the last visit to the same positions (bias wander)
void NoiseTuner::close_visit() {
  if (visit_.n == 0) return;
  auto it = last_visit_.find(visit_key_);
  if (it != last_visit_.end()) {
    const Visit& a = it->second;
    // each visit spans its samples at the log's rate (its blocks are contiguous)
    const double spans_s = double(visit_.n + a.n) / rate_hz_;
    wander_.push_back({visit_.r_sum / double(visit_.n) - a.r_sum / double(a.n),
                       visit_.x_sum / double(visit_.n) - a.x_sum / double(a.n), visit_key_,
                       visit_.t_mid_s - a.t_mid_s, spans_s / 6.0, 1.0 / double(visit_.n) + 1.0 / double(a.n)});
  }
  last_visit_[visit_key_] = visit_;
  visit_ = Visit{};
}

// least squares of the pairs' dr on dx; the rank decides how many coefficients the noise pays for
void NoiseTuner::MotionFit::solve() {
  ss = rr;
  dof = 3.0 * double(pairs);
  if (pairs < kPairsPerCoefficient * 6) return;
  // scale the columns so that the rank threshold compares like with like (rates and forces)
  Eigen::Matrix<double, 6, 1> scale;
  for (int i = 0; i < 6; ++i) scale[i] = xx(i, i) > 0.0 ? 1.0 / std::sqrt(xx(i, i)) : 0.0;
  const Eigen::Matrix<double, 6, 6> a = scale.asDiagonal() * xx * scale.asDiagonal();
  Eigen::CompleteOrthogonalDecomposition<Eigen::Matrix<double, 6, 6>> cod;
  cod.setThreshold(1e-9);
  cod.compute(a);
  const auto rank = static_cast<std::uint64_t>(cod.rank());
  if (rank == 0 || rank >= pairs) return;
  const Eigen::Matrix<double, 6, 3> c = scale.asDiagonal() * cod.solve(scale.asDiagonal() * xr);
  const double ss_fit = std::max(rr - (xr.transpose() * c).trace(), 0.0);
  const double dof_fit = 3.0 * double(pairs - rank);
  // what the fit removed against what noise alone removes: chi-square with 3 rank dof, scaled by
  // the noise variance measured in what is left
  const double removed = (rr - ss_fit) / (ss_fit / dof_fit);
  if (!(removed > chi2_quantile(kMotionFitSignificance, 3.0 * double(rank)))) return;
  if (!(c.topRows<3>().cwiseAbs().maxCoeff() < kMaxRateCoefficient)) return;
  fitted = true;
  coef = c;
  const Eigen::Matrix<double, 6, 6> xx_inv = scale.asDiagonal() * cod.pseudoInverse() * scale.asDiagonal();
  coef_cov = xx_inv * xsx * xx_inv;
  ss = ss_fit;
  dof = dof_fit;
}

TuneResult NoiseTuner::finish() {
  for (int i = 0, n = detector_.finish(); i < n; ++i) use_piece(detector_.closed(i));
  close_visit();
  TuneResult t;
  t.block_s = limits_.block_s;
  t.sample_rate_hz = rate_hz_;
  t.noise_block_pairs = noise_pairs_;
  double ss = 0.0, dof = 0.0;
  for (auto& [key, m] : motion_) {
    m.solve();
    ss += m.ss;
    dof += m.dof;
  }
  if (noise_pairs_ < limits_.min_noise_block_pairs || !(dof > 0.0) || !std::isfinite(rate_hz_)) return t;
  const double sigma2 = ss / (2.0 * dof);  // (deg/s)^2 per sample and axis: E[SS] = 2 sigma^2 dof
  t.noise_estimated = sigma2 > 0.0;
  t.noise_density_dps_rthz = std::sqrt(sigma2 / rate_hz_);
  // K^2 = sum(|dr - coef^T dx|^2 - 6 sigma^2 w) / sum(6 (dt - window)): the difference of two
  // visits' means of a random walk has variance q (dt - (span_a + span_b) / 6) per component, dt
  // between their midpoints (dt alone read q 8-16 % low on 20 s standstills revisited every 40-80 s)
  t.wander_pairs = wander_.size();
  if (wander_.size() < limits_.min_wander_pairs) return t;
  double num = 0.0, den = 0.0, num_var = 0.0;
  for (const auto& p : wander_) {
    const auto m = motion_.find(p.key);
    Eigen::Vector3d motion = Eigen::Vector3d::Zero();
    double coef_error = 0.0;  // E|(coef - true)^T dx|^2 = 3 * 2 sigma^2 dx^T coef_cov dx
    if (m != motion_.end() && m->second.fitted) {
      motion = m->second.coef.transpose() * p.dx;
      coef_error = std::max(0.0, 6.0 * sigma2 * p.dx.dot(m->second.coef_cov * p.dx));
    }
    num += (p.dr - motion).squaredNorm() - 6.0 * sigma2 * p.inv_n - coef_error;
    den += 6.0 * (p.dt_s - p.window_s);
    // without wander |dr|^2 is v chi-square(3), v = 2 sigma^2 inv_n per axis: variance 6 v^2
    const double v = 2.0 * sigma2 * p.inv_n;
    num_var += 6.0 * v * v;
  }
  if (!(den > 0.0)) return t;
  const double bound = kWanderBoundZ * std::sqrt(num_var);
  // a wander the noise could have made (a FOG's, below a MEMS default by 1e4) is not measured:
  // its upper bound is, and the filter's sigma then follows the data, not the configured part. A
  // bound above the configured Q does not contradict it (noise inflated by a signal-chain lag gives
  // such bounds): the configured Q is kept
  t.q_upper_bound = !(num > bound);
  t.q_dps2_per_s = (t.q_upper_bound ? std::max(num, 0.0) + bound : num) / den;
  t.q_estimated = !t.q_upper_bound || t.q_dps2_per_s < configured_q_dps2_per_s_;
  return t;
}

TuneResult tune_from_log(log::LogReader& reader, const EstimatorConfig& cfg, const TuneLimits& limits) {
  NoiseTuner tuner(cfg, box_geometry_from_metadata(reader.metadata()), limits);
  Sample s;
  while (reader.next(s)) tuner.push(s);
  return tuner.finish();
}

void apply_tune(const TuneResult& t, EstimatorConfig& cfg) {
  if (t.noise_estimated) {
    cfg.noise_density_dps_rthz = t.noise_density_dps_rthz;
    cfg.r_override_dps2 = 0.0;
    cfg.noise_from_log = true;
  }
  if (t.q_estimated) cfg.q_override_dps2_per_s = t.q_dps2_per_s;
}

}  // namespace driftless::est
