#include "estimator/tune.hpp"

#include <algorithm>
#include <cmath>

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
    : limits_(limits), geometry_(block_config(cfg, limits), box), detector_(block_config(cfg, limits), box) {
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

// one block: a noise pair with the previous block of the same standstill, and part of the visit
void NoiseTuner::use_piece(const StandstillSegment& seg) {
  if (seg.n == 0) return;
  if (!std::isfinite(rate_hz_)) rate_hz_ = detector_.rate_hz(seg);
  const Eigen::Vector3d r = geometry_.body_from_sensor(1, seg.plat1_deg) * seg.mean_gyro1_dps() -
                            geometry_.body_from_sensor(2, seg.plat2_deg) * seg.mean_gyro2_dps();
  const std::pair<long, long> key{tenth_deg(seg.plat1_deg), tenth_deg(seg.plat2_deg)};
  const bool same_standstill = have_block_ && seg.t_rest_s == block_rest_s_ && key == visit_key_;
  if (same_standstill) {
    // E|r_a - r_b|^2 = 6 sigma^2 (1/n_a + 1/n_b): two sensors, three axes each
    noise_sq_ += (r - block_r_).squaredNorm();
    noise_w_ += 6.0 * (1.0 / double(seg.n) + 1.0 / double(block_n_));
    ++noise_pairs_;
  } else {
    close_visit();
    visit_key_ = key;
  }
  have_block_ = seg.end == SegmentEnd::kSplit;
  block_rest_s_ = seg.t_rest_s;
  block_n_ = seg.n;
  block_r_ = r;
  // the visit's mean residual and its midpoint (weighted by samples)
  const double t_mid = 0.5 * (seg.t_first_s + seg.t_last_s);
  visit_.t_mid_s = visit_.n == 0 ? t_mid : (visit_.t_mid_s * double(visit_.n) + t_mid * double(seg.n)) /
                                               double(visit_.n + seg.n);
  visit_.r_sum += r * double(seg.n);
  visit_.n += seg.n;
}

// a standstill ended: pair it with the last visit to the same positions (bias wander)
void NoiseTuner::close_visit() {
  if (visit_.n == 0) return;
  auto it = last_visit_.find(visit_key_);
  if (it != last_visit_.end()) {
    const Visit& a = it->second;
    const Eigen::Vector3d d = visit_.r_sum / double(visit_.n) - a.r_sum / double(a.n);
    wander_.push_back({d.squaredNorm(), visit_.t_mid_s - a.t_mid_s, 1.0 / double(visit_.n) + 1.0 / double(a.n)});
  }
  last_visit_[visit_key_] = visit_;
  visit_ = Visit{};
}

TuneResult NoiseTuner::finish() {
  for (int i = 0, n = detector_.finish(); i < n; ++i) use_piece(detector_.closed(i));
  close_visit();
  TuneResult t;
  t.block_s = limits_.block_s;
  t.sample_rate_hz = rate_hz_;
  t.noise_block_pairs = noise_pairs_;
  if (noise_pairs_ < limits_.min_noise_block_pairs || !(noise_w_ > 0.0) || !std::isfinite(rate_hz_)) return t;
  const double sigma2 = noise_sq_ / noise_w_;  // (deg/s)^2 per sample and axis
  t.noise_estimated = sigma2 > 0.0;
  t.noise_density_dps_rthz = std::sqrt(sigma2 / rate_hz_);
  // K^2 = sum(|dr|^2 - 6 sigma^2 w) / sum(6 dt)
  t.wander_pairs = wander_.size();
  if (wander_.size() < limits_.min_wander_pairs) return t;
  double num = 0.0, den = 0.0;
  for (const auto& p : wander_) {
    num += p.sq - 6.0 * sigma2 * p.inv_n;
    den += 6.0 * p.dt_s;
  }
  if (den > 0.0 && num > 0.0) {
    t.q_estimated = true;
    t.q_dps2_per_s = num / den;
  }
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
  }
  if (t.q_estimated) cfg.q_override_dps2_per_s = t.q_dps2_per_s;
}

}  // namespace driftless::est
