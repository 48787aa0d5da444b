#include "estimator/standstill_gyro.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "estimator/geometry.hpp"

namespace driftless::est {
namespace {

// the second platform starting while the first turns is seen against the first's tracked angle
// and the filter's bias estimate, whose error turns with it: a wider threshold than at rest
constexpr double kSecondStartFactor = 3.0;
// a platform whose hinge rate at rest exceeds this fraction of the threshold (the other's not)
// is left out of the fused rate: the start of its flip
constexpr double kStartingFraction = 0.2;
// s: a flip is over when its hinge rate stays below the threshold this long
constexpr double kQuietS = 0.25;
// s: time constant of the rest level (it follows the biases' slow wander and the rest noise)
constexpr double kLevelTauS = 1.0;
// a measured turn further than this from 2 flip_angle_deg (fraction of it, and at least kTurnOffDeg)
// is unlike the configured flip
constexpr double kTurnOffFraction = 0.1;
constexpr double kTurnOffDeg = 5.0;
// after a gap: the best position pair's mean difference below kSeekFitFraction of the threshold,
// every other pair's above kSeekRejectFactor times it (the box turned enough to tell them apart)
constexpr double kSeekFitFraction = 0.5;
constexpr double kSeekRejectFactor = 2.0;

double snap_deg(double p_deg, double turn_deg, double flip_deg) {
  if (std::fabs(turn_deg) < 0.5 * flip_deg) return p_deg;  // an aborted or false start: no change
  const double p = p_deg + turn_deg;
  return std::fabs(p - flip_deg) < std::fabs(p + flip_deg) ? flip_deg : -flip_deg;
}

}  // namespace

GyroFlipTracker::GyroFlipTracker(const BoxGeometry& box, double threshold_dps, double p1_deg, double p2_deg)
    : thr_dps_(threshold_dps), p1_(p1_deg), p2_(p2_deg) {
  restart(box);
}

void GyroFlipTracker::restart(const BoxGeometry& box) {
  box_ = box;
  motion_ = Motion::kRest;
  have_level_ = false;
  turn1_deg_ = turn2_deg_ = 0.0;
  quiet_ = 0;
  starting_ = 0;
  fresh_ = true;
  starting_up_ = false;
  // r1 - r2 = u1 a1 - u2 a2 (+ what lies off both hinges): least squares on [a1, -a2]
  Eigen::Matrix<double, 3, 2> A;
  A.col(0) = box_.hinge1_axis.normalized();
  A.col(1) = -box_.hinge2_axis.normalized();
  const Eigen::Matrix2d AtA = A.transpose() * A;
  can_split_ = AtA.determinant() > 0.1;  // hinges more than ~18 deg from parallel
  if (can_split_) split_ = AtA.inverse() * A.transpose();
}

bool GyroFlipTracker::rest(int i) const {
  switch (motion_) {
    case Motion::kRest: return true;
    case Motion::kPlatform1: return i == 2;
    case Motion::kPlatform2: return i == 1;
    case Motion::kBoth: return false;
    case Motion::kUnknown: return false;
  }
  return false;
}

int GyroFlipTracker::quiet_samples() const {
  const double rate = std::isfinite(box_.sample_rate_hz) ? box_.sample_rate_hz : 100.0;
  return std::max(3, static_cast<int>(kQuietS * rate));
}

// r1 - r2 - rest level with both sensors turned into box axes at their last rest positions
Eigen::Vector3d GyroFlipTracker::rest_difference(const Eigen::Vector3d& y1, const Eigen::Vector3d& y2) const {
  return geo::rot_about_axis_deg(box_.hinge1_axis, p1_) * y1 - geo::rot_about_axis_deg(box_.hinge2_axis, p2_) * y2 -
         level_;
}

void GyroFlipTracker::push(const Eigen::Vector3d& y1, const Eigen::Vector3d& y2, const Eigen::Vector3d& b1,
                           const Eigen::Vector3d& b2, double dt_s, double t_s) {
  const double interval_s = std::isfinite(box_.sample_rate_hz) ? 1.0 / box_.sample_rate_hz : kNaN;
  if (std::isfinite(dt_s) && dt_s > gap_threshold_s(interval_s)) start_gap(dt_s, t_s);
  if (starting_up_) {
    step_start(y1, y2, b1, b2, dt_s, t_s);
    return;
  }
  if (motion_ == Motion::kUnknown) {
    seek_positions(y1, y2, b1, b2, t_s);
    return;
  }
  if (!have_level_) {  // the first sample sets the rest level (the box starts at rest)
    if (fresh_ && begin_start(y1, y2, b1, b2, t_s)) return;  // it does not: a flip is under way
    fresh_ = false;
    level_ = rest_difference(y1, y2);
    have_level_ = true;
    return;
  }
  const Eigen::Vector3d diff = rest_difference(y1, y2);
  if (motion_ == Motion::kRest) {
    const Eigen::Vector2d u = can_split_ ? Eigen::Vector2d(split_ * diff) : Eigen::Vector2d::Constant(diff.norm());
    const double low = kStartingFraction * thr_dps_;
    const bool s1 = std::fabs(u[0]) > low, s2 = std::fabs(u[1]) > low;
    starting_ = can_split_ && s1 != s2 ? (s1 ? 1 : 2) : 0;
    if (u.cwiseAbs().maxCoeff() <= thr_dps_) {
      const double a = std::min(1.0, std::isfinite(dt_s) ? dt_s / kLevelTauS : 0.01);
      level_ += a * diff;
      return;
    }
    start_motion(u);
  }
  if (motion_ == Motion::kBoth) {
    track_both(y1, y2, b1, b2, dt_s);
  } else {
    track_one(diff, y1, y2, b1, b2, dt_s);
  }
}

void GyroFlipTracker::start_motion(const Eigen::Vector2d& u) {
  const bool m1 = std::fabs(u[0]) > thr_dps_, m2 = std::fabs(u[1]) > thr_dps_;
  motion_ = (m1 && m2) || !can_split_ ? Motion::kBoth : m1 ? Motion::kPlatform1 : Motion::kPlatform2;
  if (motion_ == Motion::kBoth) ++simultaneous_;
  turn1_deg_ = turn2_deg_ = 0.0;
  quiet_ = 0;
}

// one platform turns, the other rests: its hinge rate is exact from the rest difference; the
// other platform starting is looked for in what is left once the tracked turn is taken out
void GyroFlipTracker::track_one(const Eigen::Vector3d& diff, const Eigen::Vector3d& y1, const Eigen::Vector3d& y2,
                                const Eigen::Vector3d& b1, const Eigen::Vector3d& b2, double dt_s) {
  const bool one = motion_ == Motion::kPlatform1;
  const Eigen::Vector3d a1 = box_.hinge1_axis.normalized(), a2 = box_.hinge2_axis.normalized();
  const double rate = one ? diff.dot(a1) : -diff.dot(a2);
  double& turn = one ? turn1_deg_ : turn2_deg_;
  if (std::isfinite(dt_s)) turn += rate * dt_s;
  // r_k at the tracked angle (bias estimate turned with it), the other at rest: what remains of
  // the difference beyond the rest level and the tracked hinge rate is the other platform moving
  const Eigen::Vector3d r1 = one ? Eigen::Vector3d(geo::rot_about_axis_deg(a1, p1_ + turn) * (y1 - b1) +
                                                   geo::rot_about_axis_deg(a1, p1_) * b1)
                                 : Eigen::Vector3d(geo::rot_about_axis_deg(a1, p1_) * y1);
  const Eigen::Vector3d r2 = one ? Eigen::Vector3d(geo::rot_about_axis_deg(a2, p2_) * y2)
                                 : Eigen::Vector3d(geo::rot_about_axis_deg(a2, p2_ + turn) * (y2 - b2) +
                                                   geo::rot_about_axis_deg(a2, p2_) * b2);
  const Eigen::Vector3d e = r1 - r2 - level_ - (one ? rate * a1 : Eigen::Vector3d(-rate * a2));
  const double other = one ? -e.dot(a2) : e.dot(a1);
  if (std::fabs(other) > kSecondStartFactor * thr_dps_) {
    motion_ = Motion::kBoth;
    ++simultaneous_;
    quiet_ = 0;
    return;
  }
  quiet_ = std::fabs(rate) < thr_dps_ ? quiet_ + 1 : 0;
  if (quiet_ >= quiet_samples()) end_motion(y1, y2);
}

// both platforms turn: with both sensors turned into box axes at their tracked angles (bias
// estimate removed), r1 - r2 = theta1' a1 - theta2' a2, so both hinge rates come from its split
void GyroFlipTracker::track_both(const Eigen::Vector3d& y1, const Eigen::Vector3d& y2, const Eigen::Vector3d& b1,
                                 const Eigen::Vector3d& b2, double dt_s) {
  double rate = 0.0;
  if (can_split_) {
    const Eigen::Vector3d d = geo::rot_about_axis_deg(box_.hinge1_axis, p1_ + turn1_deg_) * (y1 - b1) -
                              geo::rot_about_axis_deg(box_.hinge2_axis, p2_ + turn2_deg_) * (y2 - b2);
    const Eigen::Vector2d u = split_ * d;
    if (std::isfinite(dt_s)) {
      turn1_deg_ += u[0] * dt_s;
      turn2_deg_ += u[1] * dt_s;
    }
    rate = u.cwiseAbs().maxCoeff();
  } else {
    // parallel hinges: the turns cannot be told apart; the motion is over when the rest
    // difference is back at its level (the positions are kept)
    rate = rest_difference(y1, y2).norm();
  }
  quiet_ = rate < thr_dps_ ? quiet_ + 1 : 0;
  if (quiet_ >= quiet_samples()) end_motion(y1, y2);
}

void GyroFlipTracker::end_motion(const Eigen::Vector3d& y1, const Eigen::Vector3d& y2) {
  note_turn(turn1_deg_);
  note_turn(turn2_deg_);
  p1_ = snap_deg(p1_, turn1_deg_, box_.flip_angle_deg);
  p2_ = snap_deg(p2_, turn2_deg_, box_.flip_angle_deg);
  motion_ = Motion::kRest;
  turn1_deg_ = turn2_deg_ = 0.0;
  quiet_ = 0;
  level_.setZero();
  level_ = rest_difference(y1, y2);  // the new rest level from this sample (refined as it rests)
}

// a flip (a turn of at least half the configured one) between +-f turns 2f: a turn unlike
// 2 flip_angle_deg says the platforms rest elsewhere than the configuration assumes
void GyroFlipTracker::note_turn(double turn_deg) {
  const double expected = 2.0 * box_.flip_angle_deg, turn = std::fabs(turn_deg);
  if (turn < 0.5 * box_.flip_angle_deg) return;  // an aborted or false start
  ++angles_.flips;
  if (std::fabs(turn - expected) <= std::max(kTurnOffDeg, kTurnOffFraction * expected)) return;
  // the first such flip is the one measured: it starts from the configured positions, the later
  // ones from positions snapped to the wrong stops (on a turning box their turns are then off too)
  if (angles_.unlike++ == 0) angles_.measured_flip_angle_deg = 0.5 * turn;
}

// the first sample of a source: at rest both sensors read the box rate (plus their biases), so
// their rate norms agree, wherever the platforms stand; a platform turning at it (the log starts
// during a flip) makes its norm the larger by about its hinge rate. Then no level is taken: the
// positions are unknown (kUnknown) until the flip has ended (step_start)
bool GyroFlipTracker::begin_start(const Eigen::Vector3d& y1, const Eigen::Vector3d& y2, const Eigen::Vector3d& b1,
                                  const Eigen::Vector3d& b2, double t_s) {
  norm_diff0_dps_ = (y1 - b1).norm() - (y2 - b2).norm();
  if (!(std::fabs(norm_diff0_dps_) > thr_dps_)) return false;
  starting_up_ = true;
  motion_ = Motion::kUnknown;
  rate0_dps_ = {box_.hinge1_axis.normalized().dot(y1 - b1), box_.hinge2_axis.normalized().dot(y2 - b2)};
  start_turn_deg_.setZero();
  norm_diff_sum_dps_ = 0.0;
  norm_diff_n_ = 0;
  start_.t_first_s = t_s;
  return true;
}

// the norms' difference stays within the threshold of its running mean for quiet_samples(): the
// flip has ended. The platform that turned at the first sample (the larger hinge component of its
// own reading: a turn about a_i keeps a_i, so a_i . y_i is the hinge rate plus the box's rate about
// a_i) rests where its turn took it: +flip_angle_deg for a positive turn (rests at +-f)
void GyroFlipTracker::step_start(const Eigen::Vector3d& y1, const Eigen::Vector3d& y2, const Eigen::Vector3d& b1,
                                 const Eigen::Vector3d& b2, double dt_s, double t_s) {
  if (std::isfinite(dt_s)) {
    start_turn_deg_ += Eigen::Vector2d(box_.hinge1_axis.normalized().dot(y1 - b1),
                                       box_.hinge2_axis.normalized().dot(y2 - b2)) * dt_s;
  }
  const double nd = (y1 - b1).norm() - (y2 - b2).norm();
  if (norm_diff_n_ > 0 && std::fabs(nd - norm_diff_sum_dps_ / double(norm_diff_n_)) > thr_dps_) norm_diff_n_ = 0;
  if (norm_diff_n_ == 0) norm_diff_sum_dps_ = 0.0;
  norm_diff_sum_dps_ += nd;
  if (++norm_diff_n_ < quiet_samples()) return;
  starting_up_ = false;
  fresh_ = false;
  if (std::fabs(norm_diff0_dps_ - norm_diff_sum_dps_ / double(norm_diff_n_)) > thr_dps_) {
    const int i = std::fabs(rate0_dps_[0]) >= std::fabs(rate0_dps_[1]) ? 1 : 2;
    const double turn = start_turn_deg_[i - 1];
    start_.mid_flip = true;
    start_.platform = i;
    start_.rate_dps = rate0_dps_[i - 1];
    start_.t_known_s = t_s;
    start_.position_deg = turn >= 0.0 ? box_.flip_angle_deg : -box_.flip_angle_deg;
    (i == 1 ? p1_ : p2_) = start_.position_deg;
    start_.positions_deg = {p1_, p2_};
  }
  // at rest from here: the level from this sample (refined as it rests), as after a flip
  motion_ = Motion::kRest;
  level_ = rest_difference(y1, y2);
  have_level_ = true;
}

// a time gap: whatever turned in it was not seen, so the positions are unknown from here
void GyroFlipTracker::start_gap(double dt_s, double t_s) {
  if (gap_.count++ == 0) {
    gap_.t_s = std::isfinite(t_s) ? t_s - dt_s : kNaN;
    gap_.length_s = dt_s;
  }
  if (motion_ != Motion::kUnknown || starting_up_) {
    p1_before_gap_ = p1_;
    p2_before_gap_ = p2_;
  }
  motion_ = Motion::kUnknown;
  starting_up_ = fresh_ = false;  // a start still waiting for its flip's end: the gap's search takes over
  turn1_deg_ = turn2_deg_ = 0.0;
  quiet_ = starting_ = 0;
  seek_n_ = 0;
  for (auto& v : seek_sum_) v.setZero();
}

// eq. (2) at rest with the bias estimate removed: M1 (y1 - b1) - M2 (y2 - b2) = 0 at the right
// positions; a wrong pair leaves (M M'^T - I) w of the box rate w. Decided over blocks of
// quiet_samples(): one pair must fit and every other one must not
void GyroFlipTracker::seek_positions(const Eigen::Vector3d& y1, const Eigen::Vector3d& y2, const Eigen::Vector3d& b1,
                                     const Eigen::Vector3d& b2, double t_s) {
  const double f = box_.flip_angle_deg;
  const std::array<std::array<double, 2>, 4> pairs{{{f, f}, {f, -f}, {-f, f}, {-f, -f}}};
  for (std::size_t c = 0; c < pairs.size(); ++c) {
    seek_sum_[c] += geo::rot_about_axis_deg(box_.hinge1_axis, pairs[c][0]) * (y1 - b1) -
                    geo::rot_about_axis_deg(box_.hinge2_axis, pairs[c][1]) * (y2 - b2);
  }
  if (++seek_n_ < quiet_samples()) return;
  std::array<double, 4> m{};
  for (std::size_t c = 0; c < pairs.size(); ++c) m[c] = seek_sum_[c].norm() / double(seek_n_);
  const std::size_t best = static_cast<std::size_t>(std::min_element(m.begin(), m.end()) - m.begin());
  double second = std::numeric_limits<double>::infinity();
  for (std::size_t c = 0; c < pairs.size(); ++c) second = c == best ? second : std::min(second, m[c]);
  seek_n_ = 0;
  for (auto& v : seek_sum_) v.setZero();
  if (!(m[best] < kSeekFitFraction * thr_dps_ && second > kSeekRejectFactor * thr_dps_)) return;
  p1_ = pairs[best][0];
  p2_ = pairs[best][1];
  ++gap_.recovered;
  if (p1_ != p1_before_gap_ || p2_ != p2_before_gap_) ++gap_.changed;
  if (std::isnan(gap_.recovered_t_s)) gap_.recovered_t_s = t_s;
  motion_ = Motion::kRest;
  have_level_ = false;  // the next sample sets the rest level at the recovered positions
}

}  // namespace driftless::est
