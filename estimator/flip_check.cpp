#include "estimator/flip_check.hpp"

#include <algorithm>
#include <cmath>

namespace driftless::est {
namespace {

bool near(double x, double target) { return std::fabs(x / target - 1.0) <= kFlipTurnTolerance; }

double median(std::vector<double> v) {
  if (v.empty()) return kNaN;
  const std::size_t h = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h), v.end());
  const double hi = v[h];
  if (v.size() % 2 == 1) return hi;
  return 0.5 * (hi + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(h)));
}

// the standard error of the median from the spread: 1.4826 MAD is sigma for a normal spread, and
// the median's error is sqrt(pi/2) = 1.2533 times the mean's; NaN for fewer than 3 values
double median_sigma(const std::vector<double>& v) {
  if (v.size() < 3) return kNaN;
  const double m = median(v);
  std::vector<double> dev(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) dev[i] = std::fabs(v[i] - m);
  return 1.2533 * 1.4826 * median(std::move(dev)) / std::sqrt(double(v.size()));
}

// a platform whose every flip turned the same way has its "−1" flips wrapped, not signed wrong
void mark_wrapped(std::vector<FlipTurnRecord>& recs, int platform) {
  int pos = 0, neg = 0;
  for (const FlipTurnRecord& r : recs) {
    if (r.platform != platform || r.kind == FlipTurn::kStuck) continue;
    (r.turn_deg > 0.0 ? pos : neg) += 1;
  }
  if (pos + neg < 2 || (pos > 0 && neg > 0)) return;
  for (FlipTurnRecord& r : recs) {
    if (r.platform == platform && r.kind == FlipTurn::kSign) r.kind = FlipTurn::kWrapped;
  }
}

// the six channels (raw, or bias-corrected: a constant offset keeps the clip's runs of one value)
void push_clip(ClipDetector& d, const Eigen::Vector3d& y1, const Eigen::Vector3d& y2) {
  for (int i = 0; i < 3; ++i) {
    d.push(i, y1[i], false);
    d.push(3 + i, y2[i], false);
  }
}

}  // namespace

FlipTurn classify_flip(const Eigen::Vector3d& v, const Eigen::Vector3d& w, const Eigen::Vector3d& a, double dtheta_deg,
                       double moving_raw_deg, double resting_raw_deg, bool clipped) {
  const double d = std::fabs(dtheta_deg);
  if (!(d > 0.0) || !v.allFinite() || !w.allFinite()) return FlipTurn::kOther;
  // "a turn of Δθ": within the tolerance, or for a clipped flip anything it can have been cut to
  const auto one = [clipped](double x) {
    return clipped ? x >= kFlipTurnTolerance && x <= 1.0 + kFlipTurnTolerance : near(x, 1.0);
  };
  const double vn = v.norm();
  const double along = vn > 0.0 ? std::fabs(a.dot(v)) / vn : 0.0;  // |cos| of the turn axis to the hinge
  const double r = a.dot(v) / dtheta_deg;
  // the box's own turn over the window (the resting sensor's) is taken out in the moving sensor's
  // start frame, but its part across the hinge turns with the platform, so up to twice it stays
  // across the hinge: on a box that turns during the flip (the twin's Fig. 9 pan/tilt, 80-105 deg in
  // a flip's window) a turn of ±Δθ about the hinge is the hinge (agreeing, or of the wrong sign),
  // whatever that leftover leans it by
  const double across = std::sqrt(std::max(0.0, vn * vn - a.dot(v) * a.dot(v)));
  const bool on_hinge =
      along >= kFlipAxisCos || ((one(r) || one(-r)) && across <= kFlipAxisTan * d + 2.0 * resting_raw_deg);
  if (on_hinge) {
    if (one(r)) return FlipTurn::kAgrees;
    if (one(-r)) return FlipTurn::kSign;
    const double ar = std::fabs(r);
    if (near(ar, kRadPerDeg)) return FlipTurn::kGyroRadPerS;
    if (near(ar, 1.0 / kRadPerDeg)) return FlipTurn::kAngleRadians;
    if (near(ar, 1e3)) return FlipTurn::kTimeMs;
    if (near(ar, 1e6)) return FlipTurn::kTimeUs;
  }
  if (vn < kFlipTurnTolerance * d) return FlipTurn::kStuck;
  // the resting sensor's column turned by about Δθ about the moving hinge while the moving one's
  // barely turned (the box's own turn in a second is well under half a flip): columns swapped
  const double wn = w.norm();
  if (one(wn / d) && std::fabs(a.dot(w)) >= kFlipAxisCos * wn && one(resting_raw_deg / d) &&
      moving_raw_deg < 0.5 * d) {
    return FlipTurn::kSwapped;
  }
  if (!on_hinge) return FlipTurn::kAxis;
  return FlipTurn::kOther;
}

// the rest's mean readings: a running mean, exponential with kRestMeanS once the rest is longer
void FlipCheck::rest_sample(const Eigen::Vector3d& y1_dps, const Eigen::Vector3d& y2_dps, double dt_s) {
  rest_n_ += 1.0;
  const double w = std::max(1.0 / rest_n_, std::isfinite(dt_s) ? std::min(1.0, dt_s / kRestMeanS) : 0.0);
  rest1_ += w * (y1_dps - rest1_);
  rest2_ += w * (y2_dps - rest2_);
}

bool FlipCheck::push(double t_s, const Eigen::Vector3d& y1_dps, const Eigen::Vector3d& y2_dps, double plat1_deg,
                     double plat2_deg, bool both_rest) {
  const bool valid = std::isfinite(t_s) && y1_dps.allFinite() && y2_dps.allFinite();
  const double dt_s = valid && std::isfinite(t_last_s_) ? t_s - t_last_s_ : kNaN;
  t_last_s_ = valid ? t_s : kNaN;
  if (!valid) {  // a flip with a hole in it is not measured, nor is a rest with one its bias
    open_ = was_rest_ = false;
    t_back_s_ = kNaN;
    rest_n_ = 0.0;
    return false;
  }
  if (open_) {
    if (!std::isfinite(dt_s)) {
      open_ = false;
    } else {
      s1_ += y1_dps * dt_s;
      s2_ += y2_dps * dt_s;
      window_s_ += dt_s;
      push_clip(clip_, y1_dps, y2_dps);
    }
  }
  if (both_rest && open_) {
    if (!std::isfinite(t_back_s_)) {  // back at rest: the end of the turn, then settle_s more
      t_back_s_ = t_s;
      p1_end_ = plat1_deg;
      p2_end_ = plat2_deg;
    }
    if (t_s - t_back_s_ < settle_s_) return false;
  }
  if (!both_rest) t_back_s_ = kNaN;
  if (both_rest) {
    const bool closing = open_;
    open_ = false;
    was_rest_ = std::isfinite(plat1_deg) && std::isfinite(plat2_deg);
    t_rest_s_ = t_s;
    if (closing) {
      t_end_s_ = t_back_s_;  // the flip's length leaves the settle time out
      t_back_s_ = kNaN;
      rest_n_ = 0.0;  // the next flip's bias comes from the rest after this one's settle time
    }
    if (was_rest_) rest_sample(y1_dps, y2_dps, dt_s);
    p1_rest_ = plat1_deg;
    p2_rest_ = plat2_deg;
    if (!closing || !was_rest_) return false;
    ++windows_;
    // a gyro clipped in the flip: its turn reads short (the saturation finding), its axis and sign hold
    window_clipped_ = !clip_.suspected().empty();
    clipped_ += window_clipped_ ? 1 : 0;
    // one platform turned, the other stayed (within a twentieth of the turn: encoder noise)
    const double d1 = std::fabs(p1_end_ - p1_start_), d2 = std::fabs(p2_end_ - p2_start_);
    return std::isfinite(d1 + d2) && std::max(d1, d2) > 0.0 && std::min(d1, d2) < 0.05 * std::max(d1, d2);
  }
  if (!open_ && was_rest_ && rest_n_ > 0.0 && std::isfinite(dt_s)) {
    open_ = true;
    p1_start_ = p1_rest_;
    p2_start_ = p2_rest_;
    t_start_s_ = t_rest_s_;
    s1_ = y1_dps * dt_s;
    s2_ = y2_dps * dt_s;
    window_s_ = dt_s;
    start_rest1_ = rest1_;
    start_rest2_ = rest2_;
    clip_ = ClipDetector{};
    push_clip(clip_, y1_dps, y2_dps);
  }
  rest_n_ = 0.0;
  was_rest_ = false;
  return false;
}

void FlipCheck::close(const Frames& f) {
  FlipTurnRecord r;
  r.platform = std::fabs(p1_end_ - p1_start_) > std::fabs(p2_end_ - p2_start_) ? 1 : 2;
  const bool m1 = r.platform == 1;
  const Eigen::Matrix3d& Mm = m1 ? f.M1_start : f.M2_start;
  const Eigen::Matrix3d& Ms = m1 ? f.M2_start : f.M1_start;
  const Eigen::Matrix3d C0 = Mm.transpose() * Ms;  // resting sensor -> moving sensor at its start
  // each sensor's turn over the window, its bias (and Earth rate) from the rest before taken out
  const Eigen::Vector3d Sm = (m1 ? s1_ : s2_) - window_s_ * (m1 ? start_rest1_ : start_rest2_);
  const Eigen::Vector3d Ss = (m1 ? s2_ : s1_) - window_s_ * (m1 ? start_rest2_ : start_rest1_);
  const Eigen::Vector3d a = (Mm.transpose() * (m1 ? f.hinge1_box : f.hinge2_box)).normalized();
  const Eigen::Vector3d v = Sm - C0 * Ss, w = Ss - C0.transpose() * Sm;
  r.t_start_s = t_start_s_;
  r.duration_s = t_end_s_ - t_start_s_;
  r.window_s = window_s_;
  r.dtheta_deg = m1 ? p1_end_ - p1_start_ : p2_end_ - p2_start_;
  r.turn_deg = a.dot(v);
  r.ratio = r.turn_deg / r.dtheta_deg;
  const double vn = v.norm();
  r.axis_sensor = vn > 0.0 ? Eigen::Vector3d(v / vn * (r.dtheta_deg < 0.0 ? -1.0 : 1.0)) : Eigen::Vector3d::Zero();
  r.hinge_sensor = a;
  r.clipped = window_clipped_;
  r.kind = classify_flip(v, w, a, r.dtheta_deg, Sm.norm(), Ss.norm(), r.clipped);
  // a clipped flip that reads as no turn, or as none of the kinds, says nothing about the hinge
  if (r.clipped && (r.kind == FlipTurn::kStuck || r.kind == FlipTurn::kOther)) {
    ++clipped_unusable_;
    return;
  }
  records_.push_back(r);
}

FlipCheckResult FlipCheck::finish() const {
  std::vector<FlipTurnRecord> recs = records_;
  mark_wrapped(recs, 1);
  mark_wrapped(recs, 2);
  FlipCheckResult out;
  out.flip_max_s = flip_max_s_;
  out.clipped = clipped_;
  out.clipped_unusable = clipped_unusable_;
  out.windows = windows_;
  for (int p = 1; p <= 2; ++p) {
    PlatformFlipSummary& s = out.platform[static_cast<std::size_t>(p - 1)];
    s.first_t_s.fill(kNaN);
    s.median_ratio.fill(kNaN);
    s.median_ratio_sigma.fill(kNaN);
    std::array<std::vector<double>, kFlipTurnKinds> ratios;
    for (const FlipTurnRecord& r : recs) {
      if (r.platform != p) continue;
      const int k = static_cast<int>(r.kind);
      ++s.flips;
      ++s.count[k];
      if (std::isnan(s.first_t_s[k])) s.first_t_s[k] = r.t_start_s;
      s.clipped += r.clipped ? 1 : 0;
      // a clipped flip's short turn stays out of the agreeing flips' median (the scale along the hinge)
      if (!r.clipped || r.kind != FlipTurn::kAgrees) ratios[k].push_back(r.ratio);
      s.scale_flips += !r.clipped && r.kind == FlipTurn::kAgrees ? 1 : 0;
      if (r.kind == FlipTurn::kAxis) s.axis_sensor += r.axis_sensor;
      s.hinge_sensor = r.hinge_sensor;
      if (r.duration_s > flip_max_s_) ++s.slower_than_max;
      s.longest_s = std::max(s.longest_s, r.duration_s);
      if (std::fabs(r.dtheta_deg) > 0.0) {
        s.rate_to_ratio_s_per_deg = std::max(s.rate_to_ratio_s_per_deg, r.window_s / std::fabs(r.dtheta_deg));
      }
      if (r.kind != FlipTurn::kAgrees && r.kind != FlipTurn::kWrapped) ++out.disagree;
    }
    for (int k = 0; k < kFlipTurnKinds; ++k) {
      s.median_ratio[k] = median(ratios[k]);
      s.median_ratio_sigma[k] = median_sigma(ratios[k]);
    }
    if (s.axis_sensor.norm() > 0.0) s.axis_sensor.normalize();
    out.flips += s.flips;
  }
  return out;
}

}  // namespace driftless::est
