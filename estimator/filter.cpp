#include "estimator/filter.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include "estimator/geometry.hpp"
#include "estimator/stats.hpp"

namespace driftless::est {
namespace {

constexpr double kBiasInstabilityFactor = 0.6642824702679600;  // sqrt(2 ln 2 / pi)

bool finite(double v) { return std::isfinite(v); }

}  // namespace

// ---------------------------------------------------------------------------------------------
// configuration

void Calibration::validate() const {
  for (int i = 0; i < 2; ++i) {
    if (!G_dps_per_g[static_cast<std::size_t>(i)].allFinite())
      throw std::invalid_argument("calibration: sensor " + std::to_string(i + 1) + " has a non-finite g-sensitivity entry");
  }
  auto check = [&](const std::vector<CalibratedPosition>& list, int sensor) {
    for (const auto& p : list) {
      if (!finite(p.plat_deg) || !p.M_body_from_sensor.allFinite()) {
        throw std::invalid_argument("calibration: sensor " + std::to_string(sensor) +
                                    " has a non-finite angle or matrix entry");
      }
      if (std::fabs(p.M_body_from_sensor.determinant()) < 1e-6) {
        throw std::invalid_argument("calibration: sensor " + std::to_string(sensor) + " matrix at " +
                                    std::to_string(p.plat_deg) + " deg is singular");
      }
    }
  };
  check(sensor1, 1);
  check(sensor2, 2);
  if (!(match_tolerance_deg > 0.0)) {
    throw std::invalid_argument("calibration: match_tolerance_deg must be > 0 deg");
  }
}

void EstimatorConfig::validate() const {
  auto positive = [](double v, const char* name, const char* unit) {
    if (!(v > 0.0) || !std::isfinite(v)) {
      throw std::invalid_argument(std::string("estimator config: ") + name + " must be > 0 " + unit +
                                  ", got " + std::to_string(v));
    }
  };
  auto non_negative = [](double v, const char* name, const char* unit) {
    if (!(v >= 0.0) || !std::isfinite(v)) {
      throw std::invalid_argument(std::string("estimator config: ") + name + " must be >= 0 " + unit +
                                  ", got " + std::to_string(v));
    }
  };
  non_negative(settle_s, "settle_s", "s");
  non_negative(min_standstill_s, "min_standstill_s", "s");
  non_negative(end_margin_s, "end_margin_s", "s");
  non_negative(max_standstill_s, "max_standstill_s", "s (0 = never split)");
  positive(angle_tolerance_deg, "angle_tolerance_deg", "deg");
  positive(gyro_motion_threshold_dps, "gyro_motion_threshold_dps", "deg/s");
  positive(standstill_period_s, "standstill_period_s", "s");
  positive(flip_angle_deg, "flip_angle_deg", "deg");
  if (!finite(initial_plat1_deg) || !finite(initial_plat2_deg)) {
    throw std::invalid_argument("estimator config: initial_plat1_deg/initial_plat2_deg must be numbers (deg)");
  }
  positive(noise_density_dps_rthz, "noise_density_dps_rthz", "deg/s/sqrt(Hz)");
  non_negative(bias_instability_dps, "bias_instability_dps", "deg/s");
  positive(bias_instability_tau_s, "bias_instability_tau_s", "s");
  non_negative(q_override_dps2_per_s, "q_override_dps2_per_s", "(deg/s)^2/s (0 = from spec)");
  non_negative(r_override_dps2, "r_override_dps2", "(deg/s)^2 (0 = from noise density)");
  if (!finite(initial_bias_dps)) throw std::invalid_argument("estimator config: initial_bias_dps must be a number");
  positive(initial_sigma_dps, "initial_sigma_dps", "deg/s");
  positive(variance_floor_dps2, "variance_floor_dps2", "(deg/s)^2");
  if (gate_relock_after < 0) {
    throw std::invalid_argument("estimator config: gate_relock_after must be >= 0 (0 = never re-lock)");
  }
  if (!(nis_gate_probability > 0.0 && nis_gate_probability <= 1.0)) {
    throw std::invalid_argument("estimator config: nis_gate_probability must be in (0, 1] (1 = no gate)");
  }
  if (mode == FilterMode::kPaper && per_sample_updates) {
    throw std::invalid_argument(
        "estimator config: per_sample_updates needs mode: general (paper mode stacks standstills)");
  }
  if (mode == FilterMode::kPaper && max_standstill_s > 0.0) {
    throw std::invalid_argument(
        "estimator config: max_standstill_s needs mode: general (eq. (5) expects one update per position)");
  }
  calibration.validate();
}

double EstimatorConfig::q_dps2_per_s() const {
  if (q_override_dps2_per_s > 0.0) return q_override_dps2_per_s;
  // a random walk with sigma_K(tau_B) = 0.664 B: K^2 tau_B / 3 = (0.664 B)^2
  const double k = kBiasInstabilityFactor * bias_instability_dps * std::sqrt(3.0 / bias_instability_tau_s);
  return k * k;
}

double EstimatorConfig::sample_variance_dps2(double sample_rate_hz) const {
  if (r_override_dps2 > 0.0) return r_override_dps2;
  return noise_density_dps_rthz * noise_density_dps_rthz * sample_rate_hz;
}

EstimatorConfig paper_config() {
  EstimatorConfig c;
  c.mode = FilterMode::kPaper;
  c.covariance_update = CovarianceUpdate::kPrinted;
  return c;
}

const char* to_string(PushStatus s) {
  switch (s) {
    case PushStatus::kInvalid: return "invalid";
    case PushStatus::kTimeNotIncreasing: return "time_not_increasing";
    case PushStatus::kMoving: return "moving";
    case PushStatus::kSettling: return "settling";
    case PushStatus::kAccumulating: return "accumulating";
    case PushStatus::kUpdated: return "updated";
    case PushStatus::kRejected: return "rejected";
  }
  return "?";
}

// ---------------------------------------------------------------------------------------------
// the filter

DriftlessFilter::DriftlessFilter(const EstimatorConfig& cfg, const log::Metadata& meta) : cfg_(cfg) {
  cfg_.validate();
  set_metadata(meta);
  q_rate_dps2_per_s_ = cfg_.q_dps2_per_s();
  x_.setConstant(cfg_.initial_bias_dps);
  P_ = Matrix6d::Identity() * (cfg_.initial_sigma_dps * cfg_.initial_sigma_dps);
  gate3_ = cfg_.nis_gate_probability < 1.0 ? chi2_quantile(cfg_.nis_gate_probability, 3.0)
                                           : std::numeric_limits<double>::infinity();
  gate6_ = cfg_.nis_gate_probability < 1.0 ? chi2_quantile(cfg_.nis_gate_probability, 6.0)
                                           : std::numeric_limits<double>::infinity();
  gyro_.p1 = cfg_.initial_plat1_deg;
  gyro_.p2 = cfg_.initial_plat2_deg;
}

void DriftlessFilter::set_metadata(const log::Metadata& meta) {
  // metadata values were validated by the reader; a bad one here is a caller error
  hinge1_ = meta.hinge1_axis();
  hinge2_ = meta.hinge2_axis();
  if (!(hinge1_.norm() > 0.0) || !(hinge2_.norm() > 0.0)) {
    throw std::invalid_argument("estimator: hinge1_axis / hinge2_axis must be non-zero vectors");
  }
  hinge1_.normalize();
  hinge2_.normalize();
  meta_rate_hz_ = meta.sample_rate_hz();
  cache_deg_ = {kNaN, kNaN};
  // the end-margin ring, sized once (unknown rate: assume up to 1 kHz)
  const double rate = finite(meta_rate_hz_) && meta_rate_hz_ > 0.0 ? meta_rate_hz_ : 1000.0;
  ring_capacity_ = static_cast<std::size_t>(std::ceil(cfg_.end_margin_s * rate - 1e-9));
  ring_.assign(ring_capacity_ + 1, Pending{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 0.0});
  ring_head_ = ring_count_ = 0;
}

void DriftlessFilter::on_source_switch(const log::Metadata* meta) {
  if (meta != nullptr) set_metadata(*meta);
  seg_ = Segment{};
  prev_res_.valid = false;
  last_t_s_ = kNaN;
  prev_p1_ = prev_p2_ = prev_t_plat_s_ = kNaN;
  sched_start_s_ = kNaN;
  gyro_.moving = false;
  gyro_.have_base = false;
  // P and x stay; the time base of the prediction restarts with the next sample
  t_filter_s_ = kNaN;
  ++counters_.source_switches;
}

Eigen::Matrix3d DriftlessFilter::body_from_sensor(int sensor, double plat_deg) const {
  const std::size_t i = sensor == 1 ? 0 : 1;
  if (cache_deg_[i] == plat_deg) return cache_M_[i];
  const auto& list = sensor == 1 ? cfg_.calibration.sensor1 : cfg_.calibration.sensor2;
  Eigen::Matrix3d M = geo::rot_about_axis_deg(sensor == 1 ? hinge1_ : hinge2_, plat_deg);
  double best = cfg_.calibration.match_tolerance_deg;
  for (const auto& p : list) {
    const double d = std::fabs(p.plat_deg - plat_deg);
    if (d <= best) {
      best = d;
      M = p.M_body_from_sensor;
    }
  }
  cache_deg_[i] = plat_deg;
  cache_M_[i] = M;
  return M;
}

// eq. (5)'s position sequence (geo::kFlipCycle): (+,+), (+,-), (-,-), (-,+)
int DriftlessFilter::pattern_of(double p1, double p2) const { return geo::flip_cycle_index(p1, p2); }

double DriftlessFilter::pattern_angle(int pattern, int sensor) const {
  const geo::FlipSigns s = geo::flip_cycle_at(pattern);
  return cfg_.flip_angle_deg * (sensor == 1 ? s.plat1 : s.plat2);
}

void DriftlessFilter::predict_to(double t_s) {
  // A = I: the bias random walk only grows P (eq. (3)); Q = K^2 dt per axis
  if (finite(t_filter_s_) && t_s > t_filter_s_) {
    P_.diagonal().array() += q_rate_dps2_per_s_ * (t_s - t_filter_s_);
  }
  t_filter_s_ = t_s;
}

template <int D>
bool DriftlessFilter::update(const Eigen::Matrix<double, D, 1>& r, const Eigen::Matrix<double, D, 6>& H,
                             const Eigen::Matrix<double, D, D>& R, UpdateRecord& rec) {
  // P here is P_k + Q_k (predict_to ran); the recursion of section 2, S^-1 through a Cholesky solve
  const Eigen::Matrix<double, D, D> S = R + H * P_ * H.transpose();
  Eigen::LLT<Eigen::Matrix<double, D, D>> llt(S);
  const Eigen::Matrix<double, D, 1> innov = r - H * x_;
  rec.dim = D;
  rec.innovation_dps.setZero();
  rec.innovation_dps.head(D) = innov;
  rec.nis_gate = D == 3 ? gate3_ : gate6_;
  if (llt.info() != Eigen::Success) {
    rec.nis = kNaN;
    return false;
  }
  rec.nis = innov.dot(llt.solve(innov));
  if (!(rec.nis <= rec.nis_gate)) {
    // an outlier is rejected once or twice; a run of rejections means the state lost lock
    // (a bias step, another sensor after a source switch): widen P by the innovation, re-lock
    ++consecutive_rejections_;
    if (cfg_.gate_relock_after <= 0 || consecutive_rejections_ < cfg_.gate_relock_after ||
        !std::isfinite(rec.nis)) {
      return false;
    }
    P_.diagonal().array() += innov.squaredNorm();
    ++counters_.relocks;
    return update<D>(r, H, R, rec);
  }
  consecutive_rejections_ = 0;
  // W = (P + Q) H^T S^-1
  const Eigen::Matrix<double, 6, D> W = llt.solve(H * P_).transpose();
  x_ += W * innov;
  const Matrix6d IKH = Matrix6d::Identity() - W * H;
  if (cfg_.covariance_update == CovarianceUpdate::kJoseph) {
    P_ = IKH * P_ * IKH.transpose() + W * R * W.transpose();
  } else {
    P_ = IKH * P_;  // as printed
  }
  P_ = (0.5 * (P_ + P_.transpose())).eval();  // eval: no aliasing with the transpose
  for (int i = 0; i < 6; ++i) P_(i, i) = std::max(P_(i, i), cfg_.variance_floor_dps2);
  return true;
}

void DriftlessFilter::emit_update(const UpdateRecord& in, bool accepted) {
  last_update_ = in;
  last_update_.index = counters_.updates;
  last_update_.accepted = accepted;
  last_update_.bias_dps = x_;
  last_update_.sigma_dps = sigma_dps();
  ++counters_.updates;
  if (!accepted) ++counters_.rejected;
}

void DriftlessFilter::start_segment(double t_s, double p1, double p2, std::int64_t tag) {
  seg_ = Segment{};
  ring_head_ = ring_count_ = 0;
  seg_.active = true;
  seg_.t_rest_s = t_s;
  seg_.p1 = p1;
  seg_.p2 = p2;
  seg_.tag = tag;
}

// closes the standstill in progress; the end margin (samples just before the motion) is dropped
int DriftlessFilter::end_standstill() {
  ring_head_ = ring_count_ = 0;
  return close_segment();
}

// turns the committed samples into an update; returns +1 accepted, -1 rejected, 0 none
int DriftlessFilter::close_segment() {
  if (!seg_.active) return 0;
  Segment s = seg_;
  seg_.active = false;
  if (cfg_.per_sample_updates) return 0;  // its samples were used one by one
  if (s.n == 0) {
    ++counters_.standstills_too_short;
    prev_res_.valid = false;
    if (cfg_.mode == FilterMode::kPaper && paper_k_ >= 0) ++paper_k_;
    return 0;
  }
  const double span = s.n >= 2 ? (s.t_last_s - s.t_first_s) : 0.0;
  const double rate_hz = finite(meta_rate_hz_) && meta_rate_hz_ > 0.0
                             ? meta_rate_hz_
                             : (s.n >= 2 && span > 0.0 ? double(s.n - 1) / span : kNaN);
  const double duration = finite(rate_hz) ? double(s.n) / rate_hz : 0.0;
  if (!finite(rate_hz) || duration + 1e-9 < cfg_.min_standstill_s) {
    ++counters_.standstills_too_short;
    prev_res_.valid = false;
    if (cfg_.mode == FilterMode::kPaper && paper_k_ >= 0) ++paper_k_;
    return 0;
  }

  // positions used for H: measured (general) or eq. (5)'s sequence (paper)
  double p1 = s.p1, p2 = s.p2;
  int pattern = 0;
  if (cfg_.mode == FilterMode::kPaper) {
    if (paper_k_ < 0) paper_k_ = finite(p1) && finite(p2) ? pattern_of(p1, p2) : 0;
    pattern = static_cast<int>(paper_k_ % 4);
    if (finite(p1) && finite(p2) && pattern_of(p1, p2) != pattern) ++counters_.schedule_mismatches;
    p1 = pattern_angle(pattern, 1);
    p2 = pattern_angle(pattern, 2);
    ++paper_k_;
  }
  const Eigen::Matrix3d M1 = body_from_sensor(1, p1);
  const Eigen::Matrix3d M2 = body_from_sensor(2, p2);
  const Eigen::Vector3d y1 = s.sum1 / double(s.n), y2 = s.sum2 / double(s.n);
  Residual3 cur;
  cur.valid = true;
  cur.pattern = pattern;
  cur.r = M1 * y1 - M2 * y2;  // eq. (2): r = R1 y1 - R2 y2
  cur.H.block<3, 3>(0, kBias1.start) = M1;
  cur.H.block<3, 3>(0, kBias2.start) = -M2;
  // eq. (2)'s noise R1 n1 - R2 n2, averaged over n samples; the bias random walk adds q T / 12
  // (its mean over the standstill scatters about its value at the midpoint)
  const double var = cfg_.sample_variance_dps2(rate_hz) / double(s.n) + q_rate_dps2_per_s_ * span / 12.0;
  cur.R = var * (M1 * M1.transpose() + M2 * M2.transpose());

  UpdateRecord rec;
  rec.t_s = s.t_last_s;
  rec.t_start_s = s.t_first_s;
  rec.samples = s.n;
  rec.plat1_deg = p1;
  rec.plat2_deg = p2;
  // the average measures the bias at the standstill's midpoint: update there, then carry P on
  const double t_mid = 0.5 * (s.t_first_s + s.t_last_s);
  predict_to(std::max(t_mid, finite(t_filter_s_) ? t_filter_s_ : t_mid));
  int result = 0;
  if (cfg_.mode == FilterMode::kGeneral) {
    const bool ok = update<3>(cur.r, cur.H, cur.R, rec);
    emit_update(rec, ok);
    result = ok ? 1 : -1;
  } else if (prev_res_.valid && ((prev_res_.pattern + 1) % 4) == pattern) {
    // eq. (5): k = pattern of the earlier standstill; rows [H_prev; H_cur], R block-diagonal as
    // the paper assumes (delta-correlated v_k) although r_prev was already used at k - 1
    Eigen::Matrix<double, 6, 1> r6;
    r6 << prev_res_.r, cur.r;
    Eigen::Matrix<double, 6, 6> H6;
    H6 << prev_res_.H, cur.H;
    Eigen::Matrix<double, 6, 6> R6 = Eigen::Matrix<double, 6, 6>::Zero();
    R6.block<3, 3>(0, 0) = prev_res_.R;
    R6.block<3, 3>(3, 3) = cur.R;
    const bool ok = update<6>(r6, H6, R6, rec);
    emit_update(rec, ok);
    result = ok ? 1 : -1;
  }
  prev_res_ = cur;
  predict_to(s.t_last_s);
  if (result != 0) last_update_.sigma_dps = sigma_dps();
  return result;
}

// at-rest test for the platform columns; p1/p2 get the angles (deg) used for H
bool DriftlessFilter::classify(const Sample& s, double& p1, double& p2, bool& p1_rest, bool& p2_rest) {
  p1 = s.plat1_deg;
  p2 = s.plat2_deg;
  const double tol = cfg_.angle_tolerance_deg;
  p1_rest = finite(p1) && finite(prev_p1_) && std::fabs(p1 - prev_p1_) <= tol;
  p2_rest = finite(p2) && finite(prev_p2_) && std::fabs(p2 - prev_p2_) <= tol;
  // the very first sample with both angles known counts as at rest only from the next one on
  prev_p1_ = p1;
  prev_p2_ = p2;
  prev_t_plat_s_ = s.t_s;
  return p1_rest && p2_rest;
}

// gyro-only flip detection: |y1| - |y2| is independent of the box rate (rotations keep norms),
// so a jump in it is a platform moving; the hinge-rate integral y_i . a_i says which and how far
bool DriftlessFilter::track_gyro_positions(const Sample& s, double dt_s) {
  const Eigen::Vector3d y1 = s.gyro1_dps - x_.segment<3>(kBias1.start);
  const Eigen::Vector3d y2 = s.gyro2_dps - x_.segment<3>(kBias2.start);
  const double d = y1.norm() - y2.norm();
  const double h1 = y1.dot(hinge1_), h2 = y2.dot(hinge2_);
  auto& g = gyro_;
  if (!g.have_base) {
    g.have_base = true;
    g.d_base = d;
    g.h1_base = h1;
    g.h2_base = h2;
    g.prev_d = d;
    return true;
  }
  const double thr = cfg_.gyro_motion_threshold_dps;
  if (!g.moving) {
    if (std::fabs(d - g.d_base) > thr) {
      g.moving = true;
      g.turn1_deg = g.turn2_deg = 0.0;
      g.quiet = 0;
    } else {
      // slow rest levels (time constant ~1 s)
      const double a = std::min(1.0, finite(dt_s) ? dt_s / 1.0 : 0.01);
      g.d_base += a * (d - g.d_base);
      g.h1_base += a * (h1 - g.h1_base);
      g.h2_base += a * (h2 - g.h2_base);
    }
  }
  if (g.moving) {
    if (finite(dt_s)) {
      g.turn1_deg += (h1 - g.h1_base) * dt_s;
      g.turn2_deg += (h2 - g.h2_base) * dt_s;
    }
    // the flip is over when the statistic stays steady for ~0.25 s
    g.quiet = std::fabs(d - g.prev_d) < 0.2 * thr ? g.quiet + 1 : 0;
    const double rate = finite(meta_rate_hz_) && meta_rate_hz_ > 0.0 ? meta_rate_hz_ : 100.0;
    if (g.quiet >= std::max(3, static_cast<int>(0.25 * rate))) {
      g.moving = false;
      auto apply = [&](double& p, double turn) {
        if (std::fabs(turn) < 0.5 * cfg_.flip_angle_deg) return;
        p += turn;
        // snap to the nearest end position
        if (std::fabs(p - cfg_.flip_angle_deg) < std::fabs(p + cfg_.flip_angle_deg)) p = cfg_.flip_angle_deg;
        else p = -cfg_.flip_angle_deg;
      };
      apply(g.p1, g.turn1_deg);
      apply(g.p2, g.turn2_deg);
      g.d_base = d;
      g.h1_base = h1;
      g.h2_base = h2;
    }
  }
  g.prev_d = d;
  return !g.moving;
}

// a resting sample enters the ring; the one falling out of the end margin is committed
void DriftlessFilter::accumulate(const Sample& s, PushStatus& status, int& result) {
  status = PushStatus::kAccumulating;
  if (ring_capacity_ == 0) {
    commit(s.gyro1_dps, s.gyro2_dps, s.t_s, result);
    return;
  }
  const std::size_t slots = ring_.size();
  if (ring_count_ == ring_capacity_) {
    const Pending old = ring_[ring_head_];
    ring_head_ = (ring_head_ + 1) % slots;
    --ring_count_;
    commit(old.y1, old.y2, old.t_s, result);
  }
  ring_[(ring_head_ + ring_count_) % slots] = Pending{s.gyro1_dps, s.gyro2_dps, s.t_s};
  ++ring_count_;
}

void DriftlessFilter::commit(const Eigen::Vector3d& y1, const Eigen::Vector3d& y2, double t_s, int& result) {
  if (seg_.n == 0) seg_.t_first_s = t_s;
  seg_.t_last_s = t_s;
  ++seg_.n;
  seg_.sum1 += y1;
  seg_.sum2 += y2;
  if (cfg_.per_sample_updates) {
    // one 3-dim update per sample: r = M1 y1 - M2 y2, R from one sample's noise
    const Eigen::Matrix3d M1 = body_from_sensor(1, seg_.p1), M2 = body_from_sensor(2, seg_.p2);
    Eigen::Matrix<double, 3, 6> H;
    H << M1, -M2;
    const double rate_hz = finite(meta_rate_hz_) && meta_rate_hz_ > 0.0 ? meta_rate_hz_ : 100.0;
    const Eigen::Vector3d r = M1 * y1 - M2 * y2;
    const Eigen::Matrix3d R = cfg_.sample_variance_dps2(rate_hz) * (M1 * M1.transpose() + M2 * M2.transpose());
    UpdateRecord rec;
    rec.t_s = rec.t_start_s = t_s;
    rec.samples = 1;
    rec.plat1_deg = seg_.p1;
    rec.plat2_deg = seg_.p2;
    predict_to(t_s);
    const bool ok = update<3>(r, H, R, rec);
    emit_update(rec, ok);
    result = ok ? 1 : -1;
  } else if (cfg_.max_standstill_s > 0.0 && t_s - seg_.t_first_s >= cfg_.max_standstill_s) {
    // split a long standstill: update now, keep accumulating the same position (no settle);
    // the ring of pending samples carries over
    const Segment keep = seg_;
    result = close_segment();
    seg_ = Segment{};
    seg_.active = true;
    seg_.t_rest_s = keep.t_rest_s;
    seg_.p1 = keep.p1;
    seg_.p2 = keep.p2;
    seg_.tag = keep.tag;
  }
}

void DriftlessFilter::fuse_rate(const Sample& s, double p1, double p2, bool p1_rest, bool p2_rest) {
  out_.y1c_dps = s.gyro1_dps - x_.segment<3>(kBias1.start);
  out_.y2c_dps = s.gyro2_dps - x_.segment<3>(kBias2.start);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero(), raw = Eigen::Vector3d::Zero(),
                  fixed = Eigen::Vector3d::Zero();
  int n = 0;
  // a sensor on a moving platform also reads its hinge rate; only resting ones enter the fusion
  if (p1_rest && finite(p1)) {
    const Eigen::Matrix3d M1 = body_from_sensor(1, p1);
    sum += M1 * out_.y1c_dps;
    raw += M1 * s.gyro1_dps;
    fixed += M1 * (s.gyro1_dps - fixed_bias_.segment<3>(kBias1.start));
    ++n;
  }
  if (p2_rest && finite(p2)) {
    const Eigen::Matrix3d M2 = body_from_sensor(2, p2);
    sum += M2 * out_.y2c_dps;
    raw += M2 * s.gyro2_dps;
    fixed += M2 * (s.gyro2_dps - fixed_bias_.segment<3>(kBias2.start));
    ++n;
  }
  out_.sensors_fused = n;
  if (n > 0) {
    out_.rate_body_dps = sum / double(n);
    out_.rate_body_raw_dps = raw / double(n);
    out_.rate_body_fixed_dps = fixed / double(n);
  }
}

PushStatus DriftlessFilter::push(const Sample& s) {
  // calibrated g-sensitivity: y <- y - G f / g with the sample's own specific force
  if (cfg_.calibration.has_g_sensitivity()) {
    Sample c = s;
    if (s.accel1_mps2.allFinite()) c.gyro1_dps -= cfg_.calibration.G_dps_per_g[0] * (s.accel1_mps2 / kStandardGravityMps2);
    if (s.accel2_mps2.allFinite()) c.gyro2_dps -= cfg_.calibration.G_dps_per_g[1] * (s.accel2_mps2 / kStandardGravityMps2);
    return push_corrected(c);
  }
  return push_corrected(s);
}

PushStatus DriftlessFilter::push_corrected(const Sample& s) {
  ++counters_.samples;
  out_ = SampleOutput{};
  out_.t_s = s.t_s;
  if (!finite(s.t_s) || !s.gyros_finite()) {
    ++counters_.invalid;
    out_.status = PushStatus::kInvalid;
    return out_.status;
  }
  if (finite(last_t_s_) && !(s.t_s > last_t_s_)) {
    ++counters_.time_not_increasing;
    out_.status = PushStatus::kTimeNotIncreasing;
    return out_.status;
  }
  const double dt = finite(last_t_s_) ? s.t_s - last_t_s_ : kNaN;
  last_t_s_ = s.t_s;
  if (!finite(t_filter_s_)) t_filter_s_ = s.t_s;

  // 1. where are the platforms, and are they at rest?
  double p1 = kNaN, p2 = kNaN;
  bool r1 = false, r2 = false, at_rest = false;
  std::int64_t tag = 0;
  switch (cfg_.standstill) {
    case StandstillSource::kPlatformColumns:
      at_rest = classify(s, p1, p2, r1, r2);
      break;
    case StandstillSource::kGyroSignal:
      at_rest = track_gyro_positions(s, dt);
      p1 = gyro_.p1;
      p2 = gyro_.p2;
      r1 = r2 = at_rest;
      break;
    case StandstillSource::kSchedule: {
      if (!finite(sched_start_s_)) sched_start_s_ = s.t_s;
      tag = static_cast<std::int64_t>(std::floor((s.t_s - sched_start_s_) / cfg_.standstill_period_s));
      const int first = pattern_of(cfg_.initial_plat1_deg, cfg_.initial_plat2_deg);
      p1 = pattern_angle(first + static_cast<int>(tag % 4), 1);
      p2 = pattern_angle(first + static_cast<int>(tag % 4), 2);
      r1 = r2 = at_rest = true;
      break;
    }
  }

  // 2. standstill bookkeeping: a change of position or motion closes the segment
  int result = 0;
  const double tol = cfg_.angle_tolerance_deg;
  if (!at_rest) {
    result = end_standstill();
    out_.status = PushStatus::kMoving;
  } else {
    const bool same = seg_.active && seg_.tag == tag && std::fabs(p1 - seg_.p1) <= tol &&
                      std::fabs(p2 - seg_.p2) <= tol;
    if (!same) {
      result = end_standstill();
      start_segment(s.t_s, p1, p2, tag);
    }
    if (s.t_s - seg_.t_rest_s < cfg_.settle_s) {
      out_.status = PushStatus::kSettling;
    } else {
      accumulate(s, out_.status, result);
    }
  }
  if (result != 0) out_.status = result > 0 ? PushStatus::kUpdated : PushStatus::kRejected;

  // 3. outputs with the estimate now in force
  fuse_rate(s, p1, p2, r1, r2);
  return out_.status;
}

template bool DriftlessFilter::update<3>(const Eigen::Matrix<double, 3, 1>&, const Eigen::Matrix<double, 3, 6>&,
                                         const Eigen::Matrix<double, 3, 3>&, UpdateRecord&);
template bool DriftlessFilter::update<6>(const Eigen::Matrix<double, 6, 1>&, const Eigen::Matrix<double, 6, 6>&,
                                         const Eigen::Matrix<double, 6, 6>&, UpdateRecord&);

}  // namespace driftless::est
