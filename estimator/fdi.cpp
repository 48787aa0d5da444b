// Fault detection and isolation on the DriftLess residual. Method: docs/fdi.md.
#include "estimator/fdi.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace driftless::est {
namespace {

void require(bool ok, const char* field, const char* what) {
  if (!ok) throw std::invalid_argument(std::string("FdiParams.") + field + ": " + what);
}

// column k of R with the sign of the sensor's place in eq. (2): +R1 e_k or -R2 e_k
Eigen::Vector3d signature(int sensor, int axis, const Eigen::Matrix3d& R1, const Eigen::Matrix3d& R2) {
  return sensor == 1 ? Eigen::Vector3d(R1.col(axis)) : Eigen::Vector3d(-R2.col(axis));
}

// the sensor axis that box axis j maps to (largest entry of row j of R_body_from_sensor)
int sensor_axis_for_box_axis(const Eigen::Matrix3d& R_body_from_sensor, int j) {
  int k = 0;
  R_body_from_sensor.row(j).cwiseAbs().maxCoeff(&k);
  return k;
}

}  // namespace

const char* to_string(FaultKind k) {
  switch (k) {
    case FaultKind::kNone: return "none";
    case FaultKind::kStuck: return "stuck";
    case FaultKind::kBiasStep: return "bias_step";
    case FaultKind::kNoiseBurst: return "noise_burst";
    case FaultKind::kScaleChange: return "scale_change";
  }
  return "?";
}

void FdiParams::validate() const {
  require(std::isfinite(sample_rate_hz) && sample_rate_hz > 0, "sample_rate_hz", "must be > 0 Hz");
  require(learn_s > 0, "learn_s", "must be > 0 s");
  require(corr_window_s >= 0, "corr_window_s", "must be >= 0 s");
  require(rate_allowance >= 0, "rate_allowance", "must be >= 0 (deg/s per deg/s)");
  require(noise_floor_dps > 0, "noise_floor_dps", "must be > 0 deg/s");
  require(stuck_s > 0, "stuck_s", "must be > 0 s");
  require(mean_drift_sigma > 0, "mean_drift_sigma", "must be > 0");
  require(mean_threshold > 0, "mean_threshold", "must be > 0");
  require(estimate_allowance >= 0, "estimate_allowance", "must be >= 0");
  require(noise_ratio > 1, "noise_ratio", "must be > 1");
  require(noise_threshold > 0, "noise_threshold", "must be > 0");
  require(classify_s > 0, "classify_s", "must be > 0 s");
  require(noise_class_ratio > 1, "noise_class_ratio", "must be > 1");
  require(scale_z > 0, "scale_z", "must be > 0");
  require(scale_min_excitation_dps > 0, "scale_min_excitation_dps", "must be > 0 deg/s");
  require(noise_sign_z > 0, "noise_sign_z", "must be > 0");
  require(isolation_margin > 0, "isolation_margin", "must be > 0");
  require(max_isolation_segments >= 2, "max_isolation_segments", "must be >= 2");
  require(history_s > 0, "history_s", "must be > 0 s");
}

std::string FaultReport::describe() const {
  std::ostringstream out;
  out << to_string(kind) << " on sensor " << sensor << " axis " << "xyz"[axis] << " (alarm at "
      << t_alarm_s << " s, isolated at " << t_isolated_s << " s, magnitude " << magnitude
      << (confident ? "" : ", best guess") << (sensor_ambiguous ? ", sensor ambiguous" : "") << ")";
  return out.str();
}

FaultDetector::FaultDetector(const FdiParams& params) : p_(params) {
  p_.validate();
  stuck_samples_ = std::max(2, static_cast<int>(std::lround(p_.stuck_s * p_.sample_rate_hz)));
  classify_samples_ = std::max(5, static_cast<int>(std::lround(p_.classify_s * p_.sample_rate_hz)));
  history_len_ = static_cast<std::size_t>(std::max(10.0, p_.history_s * p_.sample_rate_hz));
  last_value_.setConstant(std::nan(""));
  run_.setZero();
}

Eigen::Vector3d FaultDetector::residual_sigma_dps() const {
  if (sigma_[0] < 0) return Eigen::Vector3d::Constant(std::nan(""));
  return sigma_sample_;
}

Eigen::Vector3d FaultDetector::residual_sigma_longrun_dps() const {
  if (sigma_[0] < 0) return Eigen::Vector3d::Constant(std::nan(""));
  return sigma_lr_;
}

// noise scales from the learning window, each segment demeaned (the filter's estimate error is
// constant within a segment): sigma of first differences / sqrt(2) for the noise tests, and the
// long-run sigma, sigma_lr^2 = g0 + 2 sum_{l=1..L} (1 - l/(L+1)) g_l (Bartlett window over the
// autocovariances g_l), for the mean test. The MPU6050's DLPF (and its fractional delay) gives a
// lag-1 correlation near 0.5 at 100 Hz: first differences then read about 0.7 sigma and the
// long-run sigma is about 1.4 sigma, so scaling the mean test by either made its CUSUM steps
// twice as large as assumed (docs/fdi.md, "false alarms on a moving base").
void FaultDetector::finish_learning() {
  const int L = std::max(1, static_cast<int>(std::lround(p_.corr_window_s * p_.sample_rate_hz)));
  std::vector<Eigen::Vector3d> x;
  std::vector<double> gamma_n(static_cast<std::size_t>(L) + 1, 0.0);
  std::vector<Eigen::Vector3d> gamma(static_cast<std::size_t>(L) + 1, Eigen::Vector3d::Zero());
  Eigen::Vector3d diff2 = Eigen::Vector3d::Zero();
  double n_diff = 0;
  for (std::size_t a = 0; a < learn_.size();) {
    std::size_t b = a;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (; b < learn_.size() && learn_[b].first == learn_[a].first; ++b) mean += learn_[b].second;
    const std::size_t n = b - a;
    if (n >= static_cast<std::size_t>(2 * L + 2)) {
      mean /= static_cast<double>(n);
      x.clear();
      for (std::size_t i = a; i < b; ++i) x.push_back(learn_[i].second - mean);
      for (int l = 0; l <= L; ++l) {
        for (std::size_t i = static_cast<std::size_t>(l); i < n; ++i) {
          gamma[l] += x[i].cwiseProduct(x[i - l]);
          gamma_n[l] += 1;
        }
      }
      for (std::size_t i = 1; i < n; ++i) diff2 += (x[i] - x[i - 1]).cwiseAbs2() / 2.0;
      n_diff += static_cast<double>(n - 1);
    }
    a = b;
  }
  if (gamma_n[0] < 2 || n_diff < 1) {  // only short segments so far: keep learning
    return;
  }
  for (int l = 0; l <= L; ++l) gamma[l] /= gamma_n[l];
  Eigen::Vector3d lr2 = gamma[0];
  for (int l = 1; l <= L; ++l) lr2 += 2.0 * (1.0 - l / (L + 1.0)) * gamma[l];
  sigma_sample_ = gamma[0].cwiseSqrt().cwiseMax(p_.noise_floor_dps);
  sigma_lr_ = lr2.cwiseMax(0.0).cwiseSqrt().cwiseMax(p_.noise_floor_dps);
  sigma_ = (diff2 / n_diff).cwiseSqrt().cwiseMax(p_.noise_floor_dps);
  learn_.clear();
  learn_.shrink_to_fit();
}

void FaultDetector::reset_alarm() {
  suspect_ = classified_ = false;
  kind_ = FaultKind::kNone;
  fault_.reset();
  post_.clear();
  g_up_.setZero();
  g_dn_.setZero();
  g_var_.setZero();
  n_up_.setZero();
  n_dn_.setZero();
  n_var_.setZero();
  run_.setZero();
}

// a stuck axis repeats the same code while a live one (noise above one LSB) does not
void FaultDetector::check_stuck(const FdiInput& in) {
  for (int i = 0; i < 6; ++i) {
    const double v = i < 3 ? in.gyro1_dps[i] : in.gyro2_dps[i - 3];
    if (!std::isfinite(v)) {
      run_[i] = 0;
      continue;
    }
    run_[i] = (v == last_value_[i]) ? run_[i] + 1 : 0;
    last_value_[i] = v;
    if (run_[i] + 1 >= stuck_samples_ && !fault_) {
      FaultReport f;
      f.kind = FaultKind::kStuck;
      f.sensor = i < 3 ? 1 : 2;
      f.axis = i % 3;
      f.t_alarm_s = f.t_isolated_s = in.t_s;
      f.t_onset_s = in.t_s - run_[i] / p_.sample_rate_hz;
      f.magnitude = v;
      f.bias_before_dps = in.bias_dps;
      fault_ = f;
      if (!first_alarm_s_) first_alarm_s_ = in.t_s;
    }
  }
}

FdiStatus FaultDetector::push(const FdiInput& in) {
  ++sample_index_;
  check_stuck(in);
  if (fault_) return FdiStatus::kIsolated;

  const bool usable = in.at_rest && in.gyro1_dps.allFinite() && in.gyro2_dps.allFinite() &&
                      in.bias_dps.allFinite();
  if (!usable) {
    prev_rest_ = false;
    prev_nu_.reset();
    if (suspect_) return FdiStatus::kSuspect;
    return sigma_[0] < 0 ? FdiStatus::kLearning : FdiStatus::kSkipped;
  }
  const Eigen::Matrix3d& R1 = in.R_body_from_sensor1;
  const Eigen::Matrix3d& R2 = in.R_body_from_sensor2;
  if (!prev_rest_ || (R1 - prev_R1_).cwiseAbs().maxCoeff() > 1e-9 ||
      (R2 - prev_R2_).cwiseAbs().maxCoeff() > 1e-9) {
    ++segment_;
    prev_nu_.reset();
  }
  prev_rest_ = true;
  prev_R1_ = R1;
  prev_R2_ = R2;

  // eq. (2): r = R1 y1 - R2 y2; innovation against the filter's estimate
  Record rec;
  rec.t_s = in.t_s;
  rec.segment = segment_;
  rec.r = R1 * in.gyro1_dps - R2 * in.gyro2_dps;
  rec.R1 = R1;
  rec.R2 = R2;
  rec.bias = in.bias_dps;
  const Eigen::Vector3d b1 = in.bias_dps.head<3>(), b2 = in.bias_dps.tail<3>();
  rec.fused = 0.5 * (R1 * (in.gyro1_dps - b1) + R2 * (in.gyro2_dps - b2));
  const Eigen::Vector3d nu = rec.r - (R1 * b1 - R2 * b2);
  history_.emplace_back(sample_index_, rec);
  if (history_.size() > history_len_) history_.pop_front();

  std::optional<Eigen::Vector3d> d;
  if (prev_nu_) d = (nu - *prev_nu_) / std::sqrt(2.0);
  prev_nu_ = nu;

  // learn the residual noise (per sample, of differences, long-run) from the first learn_s at rest
  if (sigma_[0] < 0) {
    learn_.emplace_back(segment_, nu);
    const long need = std::lround(p_.learn_s * p_.sample_rate_hz);
    if (++learn_n_ >= need && (learn_n_ - need) % 100 == 0) finish_learning();
    return FdiStatus::kLearning;
  }

  if (suspect_) {
    feed_isolation(rec);
    return fault_ ? FdiStatus::kIsolated : FdiStatus::kSuspect;
  }

  // cusum tests per box axis; the mean test allows for the filter's own estimate uncertainty
  Eigen::Matrix<double, 3, 6> H;
  H << R1, -R2;
  const Eigen::Vector3d est_var = (H * in.bias_cov_dps2 * H.transpose()).diagonal();
  const double rate_dps = rec.fused.norm();  // calibration residuals grow with the input rate
  long onset = -1;
  const double log_ratio = std::log(p_.noise_ratio);
  for (int j = 0; j < 3; ++j) {
    // in long-run sigmas: the DLPF correlates neighbouring samples, so a sum of n innovations
    // has variance n sigma_lr^2, not n sigma^2 (the mean test's false-alarm rate rests on this)
    const double z = nu[j] / sigma_lr_[j];
    const double k = p_.mean_drift_sigma +
                     (p_.estimate_allowance * std::sqrt(std::max(0.0, est_var[j])) +
                      p_.rate_allowance * rate_dps) / sigma_lr_[j];
    g_up_[j] = std::max(0.0, g_up_[j] + z - k);
    g_dn_[j] = std::max(0.0, g_dn_[j] - z - k);
    n_up_[j] = g_up_[j] > 0 ? n_up_[j] + 1 : 0;
    n_dn_[j] = g_dn_[j] > 0 ? n_dn_[j] + 1 : 0;
    if (g_up_[j] > p_.mean_threshold) onset = std::max(onset, sample_index_ - n_up_[j] + 1);
    if (g_dn_[j] > p_.mean_threshold) onset = std::max(onset, sample_index_ - n_dn_[j] + 1);
    if (d) {
      const double dz2 = (*d)[j] * (*d)[j] / (sigma_[j] * sigma_[j]);
      g_var_[j] = std::max(0.0, g_var_[j] + 0.5 * (dz2 * (1.0 - 1.0 / p_.noise_ratio) - log_ratio));
      n_var_[j] = g_var_[j] > 0 ? n_var_[j] + 1 : 0;
      if (g_var_[j] > p_.noise_threshold) onset = std::max(onset, sample_index_ - n_var_[j] + 1);
    }
  }
  if (onset >= 0) {
    alarm(in.t_s, onset);
    return fault_ ? FdiStatus::kIsolated : FdiStatus::kSuspect;
  }
  return FdiStatus::kOk;
}

void FaultDetector::alarm(double t_s, long onset_index) {
  suspect_ = true;
  classified_ = false;
  t_alarm_ = t_s;
  if (!first_alarm_s_) first_alarm_s_ = t_s;
  // freeze the reference bias just before the onset: the filter starts absorbing the fault then
  auto it = std::find_if(history_.begin(), history_.end(),
                         [&](const auto& h) { return h.first >= onset_index; });
  if (it == history_.end()) it = std::prev(history_.end());
  bias_ref_ = (it == history_.begin() ? it : std::prev(it))->second.bias;
  t_onset_ = it->second.t_s;
  post_.clear();
  for (; it != history_.end(); ++it) feed_isolation(it->second);
}

void FaultDetector::feed_isolation(const Record& rec) {
  const bool new_segment = !post_.empty() && post_.back().segment != rec.segment;
  post_.push_back(rec);
  if (fault_) return;
  if (!classified_) {
    if (static_cast<int>(post_.size()) >= classify_samples_) try_classify(rec.t_s);
    return;
  }
  if (kind_ == FaultKind::kBiasStep) {
    std::vector<long> segs;
    for (const auto& r : post_) {
      if (segs.empty() || segs.back() != r.segment) segs.push_back(r.segment);
    }
    const bool timeout = static_cast<int>(segs.size()) > p_.max_isolation_segments;
    if (new_segment || timeout || post_.size() % 50 == 0) try_isolate_mean(rec.t_s, timeout);
  } else if (kind_ == FaultKind::kNoiseBurst && post_.size() % 10 == 0) {
    try_classify(rec.t_s);
  }
}

// classify the alarm from the data since its onset: noise (difference variance up), scale
// (residual follows the box rate), otherwise a bias step (then isolated across positions)
void FaultDetector::try_classify(double t_s) {
  // median of the squared first differences over sigma^2 (a chi-square(1) median is 0.4549):
  // robust to the single jump a step or a scale onset makes
  std::array<std::vector<double>, 3> d2;
  for (std::size_t i = 1; i < post_.size(); ++i) {
    if (post_[i].segment != post_[i - 1].segment) continue;
    const Eigen::Vector3d d = (post_[i].r - post_[i - 1].r) / std::sqrt(2.0);
    for (int j = 0; j < 3; ++j) d2[j].push_back(d[j] * d[j] / (sigma_[j] * sigma_[j]));
  }
  Eigen::Vector3d ratio = Eigen::Vector3d::Ones();
  for (int j = 0; j < 3; ++j) {
    if (d2[j].empty()) continue;
    auto mid = d2[j].begin() + static_cast<long>(d2[j].size() / 2);
    std::nth_element(d2[j].begin(), mid, d2[j].end());
    ratio[j] = *mid / 0.4549;
  }
  int j_noise = 0;
  ratio.maxCoeff(&j_noise);
  const Record& last = post_.back();

  if (kind_ == FaultKind::kNoiseBurst || ratio[j_noise] > p_.noise_class_ratio) {
    kind_ = FaultKind::kNoiseBurst;
    classified_ = true;
    // which sensor: E[dr_j * dfused_j] = (var of sensor-1 part - var of sensor-2 part) / 2
    double c = 0, v = 0;
    for (std::size_t i = 1; i < post_.size(); ++i) {
      if (post_[i].segment != post_[i - 1].segment) continue;
      const double dr = post_[i].r[j_noise] - post_[i - 1].r[j_noise];
      const double df = post_[i].fused[j_noise] - post_[i - 1].fused[j_noise];
      c += dr * df;
      v += dr * dr * df * df;
    }
    const double z = v > 0 ? c / std::sqrt(v) : 0.0;
    const bool timeout = static_cast<int>(post_.size()) > 20 * classify_samples_;
    if (std::abs(z) < p_.noise_sign_z && !timeout) return;
    FaultReport f;
    f.kind = FaultKind::kNoiseBurst;
    f.sensor = z > 0 ? 1 : 2;
    f.axis = sensor_axis_for_box_axis(f.sensor == 1 ? last.R1 : last.R2, j_noise);
    f.t_alarm_s = t_alarm_;
    f.t_isolated_s = t_s;
    f.t_onset_s = t_onset_;
    f.magnitude = ratio[j_noise];
    f.confident = std::abs(z) >= p_.noise_sign_z;
    f.bias_before_dps = bias_ref_;
    fault_ = f;
    return;
  }

  // regression of the innovation (against the frozen reference bias) on the fused box rate,
  // both demeaned per segment (a bias step's signature changes between segments); the rate
  // must vary by scale_min_excitation_dps within segments for a scale change to be observable
  Eigen::Vector3d sxx = Eigen::Vector3d::Zero(), sxy = Eigen::Vector3d::Zero();
  double n_total = 0;
  for (std::size_t a = 0; a < post_.size();) {
    std::size_t b = a;
    Eigen::Vector3d su = Eigen::Vector3d::Zero(), sn = Eigen::Vector3d::Zero(),
                    suu = Eigen::Vector3d::Zero(), sun = Eigen::Vector3d::Zero();
    for (; b < post_.size() && post_[b].segment == post_[a].segment; ++b) {
      const Record& r = post_[b];
      const Eigen::Vector3d nu = r.r - (r.R1 * bias_ref_.head<3>() - r.R2 * bias_ref_.tail<3>());
      su += r.fused;
      sn += nu;
      suu += r.fused.cwiseAbs2();
      sun += r.fused.cwiseProduct(nu);
    }
    const double n = static_cast<double>(b - a);
    sxx += suu - su.cwiseAbs2() / n;
    sxy += sun - su.cwiseProduct(sn) / n;
    n_total += n;
    a = b;
  }
  Eigen::Vector3d zc = Eigen::Vector3d::Zero();
  for (int j = 0; j < 3; ++j) {
    const bool excited = sxx[j] / n_total > p_.scale_min_excitation_dps * p_.scale_min_excitation_dps;
    if (excited) zc[j] = sxy[j] / std::sqrt(sxx[j]) / sigma_lr_[j];
  }
  int j_scale = 0;
  zc.cwiseAbs().maxCoeff(&j_scale);
  classified_ = true;
  if (std::abs(zc[j_scale]) > p_.scale_z) {
    // nu_j = +e u_j for a gain (1+e) on sensor 1, -e u_j on sensor 2: the sign decides, taking
    // the faulty gain to grow (the mirror case is indistinguishable; docs/fdi.md)
    const double slope = sxy[j_scale] / sxx[j_scale];
    FaultReport f;
    f.kind = FaultKind::kScaleChange;
    f.sensor = slope > 0 ? 1 : 2;
    f.axis = sensor_axis_for_box_axis(f.sensor == 1 ? last.R1 : last.R2, j_scale);
    f.t_alarm_s = t_alarm_;
    f.t_isolated_s = t_s;
    f.t_onset_s = t_onset_;
    f.magnitude = std::abs(slope);
    f.sensor_ambiguous = true;
    kind_ = FaultKind::kScaleChange;
    f.bias_before_dps = bias_ref_;
    fault_ = f;
    return;
  }
  kind_ = FaultKind::kBiasStep;
  try_isolate_mean(t_s, false);
}

// generalised likelihood ratio over the six hypotheses "step f on sensor i axis k", with the
// per-segment mean innovations m_s = f g_h(s) + noise
void FaultDetector::try_isolate_mean(double t_s, bool timeout) {
  struct Seg {
    double n = 0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d R1, R2;
  };
  std::vector<Seg> segs;
  long cur = -1;
  for (const auto& r : post_) {
    if (r.segment != cur) {
      segs.emplace_back();
      segs.back().R1 = r.R1;
      segs.back().R2 = r.R2;
      cur = r.segment;
    }
    segs.back().n += 1;
    segs.back().sum += r.r - (r.R1 * bias_ref_.head<3>() - r.R2 * bias_ref_.tail<3>());
  }
  // segment means of correlated noise: variance sigma_lr^2 / n
  const Eigen::Vector3d w = sigma_lr_.cwiseAbs2().cwiseInverse();
  std::array<double, 6> cost{};
  std::array<double, 6> mag{};
  for (int h = 0; h < 6; ++h) {
    const int sensor = h < 3 ? 1 : 2, axis = h % 3;
    double gwg = 0, gwm = 0;
    for (const auto& s : segs) {
      const Eigen::Vector3d g = signature(sensor, axis, s.R1, s.R2);
      const Eigen::Vector3d m = s.sum / s.n;
      gwg += s.n * g.cwiseProduct(w).dot(g);
      gwm += s.n * g.cwiseProduct(w).dot(m);
    }
    const double f = gwg > 0 ? gwm / gwg : 0.0;
    double j = 0;
    for (const auto& s : segs) {
      const Eigen::Vector3d e = s.sum / s.n - f * signature(sensor, axis, s.R1, s.R2);
      j += s.n * e.cwiseProduct(w).dot(e);
    }
    cost[h] = j;
    mag[h] = f;
  }
  std::array<int, 6> order{0, 1, 2, 3, 4, 5};
  std::sort(order.begin(), order.end(), [&](int a, int b) { return cost[a] < cost[b]; });
  const bool decided = cost[order[1]] - cost[order[0]] > p_.isolation_margin;
  if (!decided && !timeout) return;
  FaultReport f;
  f.kind = FaultKind::kBiasStep;
  f.sensor = order[0] < 3 ? 1 : 2;
  f.axis = order[0] % 3;
  f.t_alarm_s = t_alarm_;
  f.t_isolated_s = t_s;
  f.t_onset_s = t_onset_;
  f.magnitude = mag[order[0]];
  f.confident = decided;
  f.bias_before_dps = bias_ref_;
  fault_ = f;
}

DegradedBias::DegradedBias(int faulty_sensor, const Vector6d& bias_dps, const Matrix6d& cov_dps2,
                           double t0_s, double bias_rw_dps2_per_s)
    : healthy_(faulty_sensor == 1 ? 2 : 1), t0_s_(t0_s), q_(bias_rw_dps2_per_s) {
  if (faulty_sensor != 1 && faulty_sensor != 2) {
    throw std::invalid_argument("DegradedBias: faulty_sensor must be 1 or 2");
  }
  if (!(bias_rw_dps2_per_s >= 0)) {
    throw std::invalid_argument("DegradedBias: bias_rw_dps2_per_s must be >= 0 (deg/s)^2/s");
  }
  const int o = healthy_ == 1 ? 0 : 3;
  bias_ = bias_dps.segment<3>(o);
  cov0_ = cov_dps2.block<3, 3>(o, o);
}

Eigen::Matrix3d DegradedBias::cov_dps2(double t_s) const {
  return cov0_ + q_ * std::max(0.0, t_s - t0_s_) * Eigen::Matrix3d::Identity();
}

Eigen::Vector3d DegradedBias::sigma_dps(double t_s) const {
  return cov_dps2(t_s).diagonal().cwiseSqrt();
}

Eigen::Vector3d DegradedBias::body_rate_dps(const FdiInput& in) const {
  return healthy_ == 1 ? Eigen::Vector3d(in.R_body_from_sensor1 * (in.gyro1_dps - bias_))
                       : Eigen::Vector3d(in.R_body_from_sensor2 * (in.gyro2_dps - bias_));
}

}  // namespace driftless::est
