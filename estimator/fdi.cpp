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
  require(lock_sigma_dps > 0, "lock_sigma_dps", "must be > 0 deg/s");
  require(quiet_rate_dps > 0, "quiet_rate_dps", "must be > 0 deg/s");
  require(revisit_sigma_dps >= 0, "revisit_sigma_dps", "must be >= 0 deg/s");
}

std::string UncalibratedReport::describe() const {
  std::ostringstream out;
  out << alarms << " alarm" << (alarms == 1 ? "" : "s") << " (the latest at t=" << t_alarm_s
      << " s, offsets up to " << offset_dps
      << " deg/s): the residual's offset equals its mean at the earlier visits of the same platform positions "
      << "(change at most " << change_dps << " deg/s over " << segments << " segment" << (segments == 1 ? "" : "s")
      << "; a bias step fits better by at most " << step_chi2 << " chi2 units";
  if (while_turning > 0) out << "; " << while_turning << " of them only while the box turned";
  out << "): a position-dependent error of uncalibrated sensors (g-sensitivity, misalignment, scale), not a fault";
  return out.str();
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
bool FaultDetector::finish_learning(const std::vector<std::pair<long, Eigen::Vector3d>>& pieces) {
  learned_samples_ = learned_segments_ = 0;
  const int L = std::max(1, static_cast<int>(std::lround(p_.corr_window_s * p_.sample_rate_hz)));
  std::vector<Eigen::Vector3d> x;
  std::vector<double> gamma_n(static_cast<std::size_t>(L) + 1, 0.0);
  std::vector<Eigen::Vector3d> gamma(static_cast<std::size_t>(L) + 1, Eigen::Vector3d::Zero());
  Eigen::Vector3d diff2 = Eigen::Vector3d::Zero();
  double n_diff = 0;
  for (std::size_t a = 0; a < pieces.size();) {
    std::size_t b = a;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (; b < pieces.size() && pieces[b].first == pieces[a].first; ++b) mean += pieces[b].second;
    const std::size_t n = b - a;
    if (n >= static_cast<std::size_t>(2 * L + 2)) {
      mean /= static_cast<double>(n);
      x.clear();
      for (std::size_t i = a; i < b; ++i) x.push_back(pieces[i].second - mean);
      for (int l = 0; l <= L; ++l) {
        for (std::size_t i = static_cast<std::size_t>(l); i < n; ++i) {
          gamma[l] += x[i].cwiseProduct(x[i - l]);
          gamma_n[l] += 1;
        }
      }
      for (std::size_t i = 1; i < n; ++i) diff2 += (x[i] - x[i - 1]).cwiseAbs2() / 2.0;
      n_diff += static_cast<double>(n - 1);
      learned_samples_ += static_cast<long>(n);
      ++learned_segments_;
    }
    a = b;
  }
  if (gamma_n[0] < 2 || n_diff < 1) {  // only short segments so far: keep learning
    return false;
  }
  for (int l = 0; l <= L; ++l) gamma[l] /= gamma_n[l];
  Eigen::Vector3d lr2 = gamma[0];
  for (int l = 1; l <= L; ++l) lr2 += 2.0 * (1.0 - l / (L + 1.0)) * gamma[l];
  sigma_sample_ = gamma[0].cwiseSqrt().cwiseMax(p_.noise_floor_dps);
  sigma_lr_ = lr2.cwiseMax(0.0).cwiseSqrt().cwiseMax(p_.noise_floor_dps);
  sigma_ = (diff2 / n_diff).cwiseSqrt().cwiseMax(p_.noise_floor_dps);
  return true;
}

void FaultDetector::reset_alarm() {
  fault_.reset();
  run_.setZero();
  resume_monitoring();
}

void FaultDetector::resume_monitoring() {
  suspect_ = classified_ = scale_waiting_ = false;
  kind_ = FaultKind::kNone;
  post_.clear();
  g_up_.setZero();
  g_dn_.setZero();
  g_var_.setZero();
  n_up_.setZero();
  n_dn_.setZero();
  n_var_.setZero();
}

// the position check's memory: each rest segment's quiet residual sum (r, not the innovation: it
// does not depend on the filter's estimate), the newest visits kept
void FaultDetector::remember_visit(const Record& rec) {
  if (visits_.empty() || visits_.back().segment != rec.segment) {
    visits_.push_back(Visit{rec.segment, rec.R1, rec.R2});
    if (visits_.size() > 256) visits_.pop_front();
  }
  Visit& v = visits_.back();
  v.n_all += 1;
  v.s_w += rec.fused;
  v.s_ww += rec.fused.cwiseAbs2();
  v.s_r += rec.r;
  v.s_wr += rec.fused.cwiseProduct(rec.r);
  if (!rec.quiet) return;
  visits_.back().n += 1;
  visits_.back().sum_r += rec.r;
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

// learns the residual noise (per sample, of differences, long-run) from the first learn_s of quiet
// rest samples after the filter locked: before the lock the innovation carries the filter's own
// estimate error, and on a turning box the misalignment x rate of uncalibrated sensors (F14: a
// car's first turn read as 0.3-0.6 deg/s of noise). A box that is hardly ever quiet (fewer than
// half of the first learn_s of rest samples: a pan/tilt unit that keeps turning) is learned from
// all its rest samples, as calibrated sensors allow. True once learned.
bool FaultDetector::learn(const FdiInput& in, const Record& rec, const Eigen::Vector3d& nu,
                          const Eigen::Vector3d& est_var) {
  if (std::isnan(t_locked_s_)) {
    if (!(est_var.maxCoeff() < p_.lock_sigma_dps * p_.lock_sigma_dps)) return false;
    t_locked_s_ = in.t_s;
  }
  const long need = std::lround(p_.learn_s * p_.sample_rate_hz);
  const long n_quiet = static_cast<long>(learn_quiet_.size());
  if (n_quiet < need / 2 || static_cast<long>(learn_all_.size()) < need) {
    if (learn_all_.empty()) t_learn_all_s_ = in.t_s;
    learn_all_.emplace_back(segment_, nu);
  } else {
    learn_all_.clear();
  }
  if (rec.quiet) {
    if (!learn_prev_in_ || segment_ != learn_segment_) ++learn_piece_;
    if (learn_quiet_.empty()) t_learn_quiet_s_ = in.t_s;
    learn_quiet_.emplace_back(learn_piece_, nu);
  }
  learn_prev_in_ = rec.quiet;
  learn_segment_ = segment_;
  const long n_all = static_cast<long>(learn_all_.size());
  if (rec.quiet && n_quiet + 1 >= need && (n_quiet + 1 - need) % 100 == 0 && finish_learning(learn_quiet_)) {
    learned_on_quiet_ = true;
    t_learn_start_s_ = t_learn_quiet_s_;
  } else if (n_quiet < need / 2 && n_all >= need && (n_all - need) % 100 == 0 && finish_learning(learn_all_)) {
    learned_on_quiet_ = false;
    t_learn_start_s_ = t_learn_all_s_;
  }
  if (sigma_[0] < 0) return false;
  learn_quiet_.clear();
  learn_quiet_.shrink_to_fit();
  learn_all_.clear();
  learn_all_.shrink_to_fit();
  return true;
}

FdiStatus FaultDetector::push(const FdiInput& in) {
  ++sample_index_;
  check_stuck(in);
  if (fault_) return FdiStatus::kIsolated;

  const bool usable = in.at_rest && in.gyro1_dps.allFinite() && in.gyro2_dps.allFinite() &&
                      in.bias_dps.allFinite();
  if (!usable) {
    prev_rest_ = false;
    learn_prev_in_ = false;
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
  rec.quiet = rec.fused.norm() <= p_.quiet_rate_dps;
  const Eigen::Vector3d nu = rec.r - (R1 * b1 - R2 * b2);
  history_.emplace_back(sample_index_, rec);
  if (history_.size() > history_len_) history_.pop_front();
  remember_visit(rec);

  std::optional<Eigen::Vector3d> d;
  if (prev_nu_) d = (nu - *prev_nu_) / std::sqrt(2.0);
  prev_nu_ = nu;

  // the filter's own estimate uncertainty in the residual, (H P H^T)_jj
  Eigen::Matrix<double, 3, 6> H;
  H << R1, -R2;
  const Eigen::Vector3d est_var = (H * in.bias_cov_dps2 * H.transpose()).diagonal();
  if (sigma_[0] < 0) return learn(in, rec, nu, est_var) ? FdiStatus::kOk : FdiStatus::kLearning;

  if (suspect_) {
    feed_isolation(rec);
    return fault_ ? FdiStatus::kIsolated : FdiStatus::kSuspect;
  }

  // cusum tests per box axis; the mean test allows for the filter's own estimate uncertainty
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
    // (a scale change waiting for a rate-excited earlier visit is re-tried every 50 samples)
    const int n = static_cast<int>(post_.size());
    if (n >= classify_samples_ && (n - classify_samples_) % (scale_waiting_ ? 50 : 1) == 0) try_classify(rec.t_s);
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
    // the same slope at the earlier visits of these positions: uncalibrated scale or misalignment
    const double z_change = scale_change_z(j_scale);
    if (std::isfinite(z_change) && std::abs(z_change) < p_.scale_z) {
      explain(t_s, 0.0, 0.0, 0.0, 0, true);
      resume_monitoring();
      return;
    }
    // no earlier visit of these positions saw the box turn: wait for one (a car turns now and
    // then), up to max_isolation_segments, then report the change unconfirmed
    long segments = 0;
    for (std::size_t i = 0; i < post_.size(); ++i) segments += i == 0 || post_[i].segment != post_[i - 1].segment;
    const bool unconfirmed = !std::isfinite(z_change);
    if (unconfirmed && segments <= p_.max_isolation_segments) {
      classified_ = false;
      scale_waiting_ = true;
      return;
    }
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
    f.confident = !unconfirmed;
    kind_ = FaultKind::kScaleChange;
    f.bias_before_dps = bias_ref_;
    fault_ = f;
    return;
  }
  kind_ = FaultKind::kBiasStep;
  try_isolate_mean(t_s, false);
}

// The position check (F14). A position-dependent error of uncalibrated sensors (g-sensitivity,
// misalignment, scale) gives the residual r = R1 y1 - R2 y2 an offset per platform-position pair
// that comes back the same at every visit; a bias step adds f g_h at every pair from its onset on.
// Each post-onset segment's quiet mean of r is compared with the mean of the earlier visits of its
// pair: e_s = m_post - m_pre, variance sigma_lr^2 (1/n_post + 1/n_pre) + revisit_sigma^2 per box
// axis. Costs: "no change" C0 = sum e^T V^-1 e; hypothesis h (step f on sensor i axis k) the
// weighted least-squares misfit C_h of e_s = f g_h(s).
struct FaultDetector::PositionEvidence {
  int segments = 0;          // post-onset segments with an earlier visit of their pair
  double n = 0;              // their quiet samples
  double cost_none = 0;      // C0
  std::array<double, 6> cost{}, mag{};
  double offset_dps = 0;     // largest |quiet innovation mean| (against the frozen bias)
  double offset_chi2 = 0;    // sum nu_mean^T V^-1 nu_mean over them: is the alarm in the quiet samples?
  double change_dps = 0;     // largest |e_s|
};

FaultDetector::PositionEvidence FaultDetector::position_evidence() const {
  PositionEvidence ev;
  if (post_.empty()) return ev;
  const long onset_segment = post_.front().segment;
  struct Seg {
    Eigen::Vector3d e, inv_var;
    Eigen::Matrix3d R1, R2;
  };
  std::vector<Seg> segs;
  for (std::size_t a = 0; a < post_.size();) {
    std::size_t b = a;
    double n = 0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero(), sum_nu = Eigen::Vector3d::Zero();
    for (; b < post_.size() && post_[b].segment == post_[a].segment; ++b) {
      const Record& r = post_[b];
      if (!r.quiet) continue;
      n += 1;
      sum += r.r;
      sum_nu += r.r - (r.R1 * bias_ref_.head<3>() - r.R2 * bias_ref_.tail<3>());
    }
    const Record& first = post_[a];
    a = b;
    double n_pre = 0;
    Eigen::Vector3d sum_pre = Eigen::Vector3d::Zero();
    for (const Visit& v : visits_) {
      if (v.segment >= onset_segment || (v.R1 - first.R1).cwiseAbs().maxCoeff() > 1e-9 ||
          (v.R2 - first.R2).cwiseAbs().maxCoeff() > 1e-9) continue;
      n_pre += v.n;
      sum_pre += v.sum_r;
    }
    if (n < 10 || n_pre < 10) continue;
    const Eigen::Vector3d var = sigma_lr_.cwiseAbs2() * (1.0 / n + 1.0 / n_pre) +
                                Eigen::Vector3d::Constant(p_.revisit_sigma_dps * p_.revisit_sigma_dps);
    segs.push_back(Seg{sum / n - sum_pre / n_pre, var.cwiseInverse(), first.R1, first.R2});
    ++ev.segments;
    ev.n += n;
    ev.offset_dps = std::max(ev.offset_dps, (sum_nu / n).cwiseAbs().maxCoeff());
    // the offset against the same tolerance as a change: an offset within revisit_sigma of zero
    // explains nothing (its agreement with earlier visits would hold for any small change too)
    ev.offset_chi2 += (sum_nu / n).cwiseAbs2().dot(segs.back().inv_var);
    ev.change_dps = std::max(ev.change_dps, segs.back().e.cwiseAbs().maxCoeff());
    ev.cost_none += segs.back().e.cwiseAbs2().dot(segs.back().inv_var);
  }
  for (int h = 0; h < 6; ++h) {
    double gwg = 0, gwe = 0;
    for (const Seg& sg : segs) {
      const Eigen::Vector3d g = signature(h < 3 ? 1 : 2, h % 3, sg.R1, sg.R2);
      gwg += g.cwiseAbs2().dot(sg.inv_var);
      gwe += g.cwiseProduct(sg.inv_var).dot(sg.e);
    }
    ev.mag[h] = gwg > 0 ? gwe / gwg : 0.0;
    ev.cost[h] = ev.cost_none - (gwg > 0 ? gwe * gwe / gwg : 0.0);
  }
  return ev;
}

// Decides an alarm by the position check when its segments have earlier visits: "uncalibrated"
// (no step fits better than no change, or the quiet samples carry no offset at all: monitoring
// resumes) or a bias step isolated on the changes e_s: kDecided. kChange: a change, its source not
// yet told apart (the innovation may). kNoData: nothing to compare yet (the caller waits, or at the
// timeout falls back to the innovation's best guess).
FaultDetector::PositionCheck FaultDetector::try_position_check(double t_s, bool timeout,
                                                             std::array<double, 6>* change_mag) {
  const PositionEvidence ev = position_evidence();
  *change_mag = ev.mag;
  if (ev.n < classify_samples_) return PositionCheck::kNoData;
  std::array<int, 6> order{0, 1, 2, 3, 4, 5};
  std::sort(order.begin(), order.end(), [&](int a, int b) { return ev.cost[a] < ev.cost[b]; });
  const double step_chi2 = ev.cost_none - ev.cost[order[0]];
  // the quiet samples at rest carry no offset: what alarmed came while the box turned (misalignment
  // or scale x rate); a bias step would show in them as well
  const bool while_turning = ev.offset_chi2 < p_.isolation_margin;
  if (while_turning || step_chi2 < p_.isolation_margin) {
    explain(t_s, ev.offset_dps, ev.change_dps, step_chi2, ev.segments, while_turning);
    resume_monitoring();
    return PositionCheck::kDecided;
  }
  const bool decided = ev.cost[order[1]] - ev.cost[order[0]] > p_.isolation_margin;
  if (!decided && !timeout) return PositionCheck::kChange;  // a change, its source not yet told apart
  record_bias_step(order[0], t_s, ev.mag[order[0]], decided);
  return PositionCheck::kDecided;
}

// records an alarm the positions explained (the latest one, with the largest offset, change and
// step fit over every explained alarm)
void FaultDetector::explain(double t_s, double offset_dps, double change_dps, double step_chi2, int segments,
                            bool while_turning) {
  UncalibratedReport u = uncalibrated_.value_or(UncalibratedReport{});
  u.t_alarm_s = t_alarm_;
  u.t_decided_s = std::max(t_s, t_alarm_);  // (the alarm's own samples are replayed from its onset)
  u.offset_dps = std::max(u.offset_dps, offset_dps);
  u.change_dps = std::max(u.change_dps, change_dps);
  u.step_chi2 = std::max(u.step_chi2, step_chi2);
  u.segments += segments;
  u.while_turning += while_turning ? 1 : 0;
  u.alarms = ++explained_alarms_;
  uncalibrated_ = u;
}

// The position check of a scale change on box axis j: the post-onset residual's slope on the rate,
// per segment, against the slope b_p of the earlier visits of the same position pair (uncalibrated
// scale and misalignment give every visit of a pair the same slope; a scale change alters it):
// z = sum_s (Sxy_s - b_p Sxx_s) / sqrt(sum_s sigma_lr^2 (Sxx_s + Sxx_s^2 / Sxx_p)), sums demeaned
// per segment. NaN when no segment's pair had a rate-excited earlier visit.
double FaultDetector::scale_change_z(int j) const {
  const long onset_segment = post_.front().segment;
  const double min_var = p_.scale_min_excitation_dps * p_.scale_min_excitation_dps;
  double num = 0, var = 0;
  int used = 0;
  for (std::size_t a = 0; a < post_.size();) {
    std::size_t b = a;
    double n = 0, su = 0, suu = 0, sr = 0, sur = 0;
    for (; b < post_.size() && post_[b].segment == post_[a].segment; ++b) {
      const double w = post_[b].fused[j], r = post_[b].r[j];
      n += 1;
      su += w;
      suu += w * w;
      sr += r;
      sur += w * r;
    }
    const Record& first = post_[a];
    a = b;
    double sxx_p = 0, sxy_p = 0, n_p = 0;
    for (const Visit& v : visits_) {
      if (v.segment >= onset_segment || v.n_all < 2 || (v.R1 - first.R1).cwiseAbs().maxCoeff() > 1e-9 ||
          (v.R2 - first.R2).cwiseAbs().maxCoeff() > 1e-9) continue;
      sxx_p += v.s_ww[j] - v.s_w[j] * v.s_w[j] / v.n_all;
      sxy_p += v.s_wr[j] - v.s_w[j] * v.s_r[j] / v.n_all;
      n_p += v.n_all;
    }
    const double sxx = suu - su * su / n, sxy = sur - su * sr / n;
    if (n < 2 || sxx_p <= n_p * min_var || sxx <= 0) continue;
    num += sxy - sxy_p / sxx_p * sxx;
    var += sigma_lr_[j] * sigma_lr_[j] * (sxx + sxx * sxx / sxx_p);
    ++used;
  }
  return used > 0 && var > 0 ? num / std::sqrt(var) : std::nan("");
}

// generalised likelihood ratio over the six hypotheses "step f on sensor i axis k", with the
// per-segment mean innovations m_s = f g_h(s) + noise; the position check first (it is immune to
// position-dependent errors and vetoes an alarm the positions explain)
void FaultDetector::try_isolate_mean(double t_s, bool timeout) {
  std::array<double, 6> change_mag{};
  const PositionCheck pc = try_position_check(t_s, timeout, &change_mag);
  if (pc == PositionCheck::kDecided) return;
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
  // not before the position check could compare a segment with an earlier visit of its pair, when
  // the box was mostly quiet at its earlier rests (a box that keeps turning, like a pan/tilt unit,
  // may never give the check data: the innovation decides as it did without the check)
  const long onset_segment = post_.front().segment;
  double quiet = 0, all = 0;
  for (const Visit& v : visits_) {
    if (v.segment >= onset_segment) continue;
    quiet += v.n;
    all += v.n_all;
  }
  const bool mostly_quiet = quiet >= 10 && 2 * quiet >= all;
  if (pc == PositionCheck::kNoData && !timeout && mostly_quiet) return;
  // the step's size from the changes against earlier visits when there are any: the innovation's
  // mean also carries the position-dependent offsets of uncalibrated sensors
  record_bias_step(order[0], t_s, pc == PositionCheck::kChange ? change_mag[order[0]] : mag[order[0]], decided);
}

// the isolated bias step on channel `channel` (0-2 sensor 1's x-z, 3-5 sensor 2's) becomes the fault
void FaultDetector::record_bias_step(int channel, double t_s, double magnitude, bool confident) {
  FaultReport f;
  f.kind = FaultKind::kBiasStep;
  f.sensor = channel < 3 ? 1 : 2;
  f.axis = channel % 3;
  f.t_alarm_s = t_alarm_;
  f.t_isolated_s = t_s;
  f.t_onset_s = t_onset_;
  f.magnitude = magnitude;
  f.confident = confident;
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
