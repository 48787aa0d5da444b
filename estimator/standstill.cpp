#include "estimator/standstill.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace driftless::est {
namespace {

bool finite(double v) { return std::isfinite(v); }

}  // namespace

StandstillDetector::StandstillDetector(const EstimatorConfig& cfg, const BoxGeometry& box)
    : cfg_(cfg), gyro_(box, cfg.gyro_motion_threshold_dps, cfg.initial_plat1_deg, cfg.initial_plat2_deg) {
  restart(box);
}

void StandstillDetector::restart(const BoxGeometry& box) {
  box_ = box;
  active_ = false;
  seg_ = StandstillSegment{};
  prev_p1_ = prev_p2_ = kNaN;
  prev_rate1_dps_ = prev_rate2_dps_ = kNaN;
  prev_both_moving_ = false;
  sched_start_s_ = kNaN;
  gyro_.restart(box);  // positions kept, motion and rest level re-learned
  n_closed_ = 0;
  // the end-margin ring, sized once (unknown rate: assume up to 1 kHz)
  const double rate = finite(box_.sample_rate_hz) ? box_.sample_rate_hz : 1000.0;
  ring_capacity_ = static_cast<std::size_t>(std::ceil(cfg_.end_margin_s * rate - 1e-9));
  ring_.assign(ring_capacity_ + 1, Pending{});
  ring_head_ = ring_count_ = 0;
}

double StandstillDetector::rate_hz(const StandstillSegment& seg) const {
  if (finite(box_.sample_rate_hz)) return box_.sample_rate_hz;
  const double span = seg.span_s();
  return seg.n >= 2 && span > 0.0 ? double(seg.n - 1) / span : kNaN;
}

StandstillDetector::Pending StandstillDetector::pending_of(const Sample& s) {
  Pending p;
  p.y1 = s.gyro1_dps;
  p.y2 = s.gyro2_dps;
  p.f1 = s.accel1_mps2;
  p.f2 = s.accel2_mps2;
  // "up" in box axes from the reference attitude q_enu_from_body (gravity's direction reversed)
  p.up = s.ref_q_wxyz.allFinite() ? Eigen::Vector3d(s.q_enu_from_body().conjugate() * Eigen::Vector3d::UnitZ())
                                  : Eigen::Vector3d::Constant(kNaN);
  p.temp1 = s.temp1_c;
  p.temp2 = s.temp2_c;
  p.t_s = s.t_s;
  return p;
}

// the hinge rate whose mean with the previous one is the angle change over the interval (the
// attitude integrator's trapezoid then turns the box by what the columns say): at rest 0; while
// moving (1 + l) change / dt - l previous. l = 1 is that exactly, but lets an encoder's noise build
// up from sample to sample; l = kHingeRateMemory keeps it bounded and misses the trapezoid by
// (1 - l) / 2 of the rate's change over the interval, which sums to nothing over a flip that
// starts and ends at rest (lag on a ramp: (1 - l) / (2 (1 + l)) of a sample)
double StandstillDetector::hinge_rate_dps(double angle_deg, double prev_deg, double prev_rate_dps, bool rest,
                                          double dt_s) {
  constexpr double kHingeRateMemory = 0.9;
  if (rest) return 0.0;
  if (!finite(angle_deg) || !finite(prev_deg) || !(dt_s > 0.0)) return kNaN;
  return (1.0 + kHingeRateMemory) * (angle_deg - prev_deg) / dt_s -
         kHingeRateMemory * (finite(prev_rate_dps) ? prev_rate_dps : 0.0);
}

// an angle change above the tolerance but too small for a flip: the read-back's own noise
void StandstillDetector::note_jitter(double d1_deg, double d2_deg) {
  if (!finite(d1_deg) || !finite(d2_deg)) return;
  ++jitter_.samples;
  const double d = std::max(std::fabs(d1_deg), std::fabs(d2_deg));
  if (d <= cfg_.angle_tolerance_deg || d > kAngleJitterDeg) return;
  ++jitter_.jittery;
  jitter_.max_change_deg = std::max(jitter_.max_change_deg, d);
}

// at-rest test for the platform columns: a platform rests when its angle is finite and unchanged
bool StandstillDetector::classify(const Sample& s, double dt_s, StandstillStep& st) {
  st.plat1_deg = s.plat1_deg;
  st.plat2_deg = s.plat2_deg;
  const double tol = cfg_.angle_tolerance_deg;
  st.plat1_rest = finite(s.plat1_deg) && finite(prev_p1_) && std::fabs(s.plat1_deg - prev_p1_) <= tol;
  st.plat2_rest = finite(s.plat2_deg) && finite(prev_p2_) && std::fabs(s.plat2_deg - prev_p2_) <= tol;
  note_jitter(s.plat1_deg - prev_p1_, s.plat2_deg - prev_p2_);
  st.plat1_rate_dps = hinge_rate_dps(s.plat1_deg, prev_p1_, prev_rate1_dps_, st.plat1_rest, dt_s);
  st.plat2_rate_dps = hinge_rate_dps(s.plat2_deg, prev_p2_, prev_rate2_dps_, st.plat2_rest, dt_s);
  // both moving with their angles read (not the first sample, whose angles count from the next)
  st.both_moving = !st.plat1_rest && !st.plat2_rest && finite(prev_p1_) && finite(prev_p2_);
  if (st.both_moving && !prev_both_moving_) ++both_moving_;
  prev_both_moving_ = st.both_moving;
  // the very first sample with both angles known counts as at rest only from the next one on
  prev_p1_ = s.plat1_deg;
  prev_p2_ = s.plat2_deg;
  prev_rate1_dps_ = st.plat1_rate_dps;
  prev_rate2_dps_ = st.plat2_rate_dps;
  return st.plat1_rest && st.plat2_rest;
}

void StandstillDetector::schedule_positions(const Sample& s, StandstillStep& st) {
  if (!finite(sched_start_s_)) sched_start_s_ = s.t_s;
  const std::int64_t tag = static_cast<std::int64_t>(std::floor((s.t_s - sched_start_s_) / cfg_.standstill_period_s));
  const int first = eq5_pattern_of(cfg_.initial_plat1_deg, cfg_.initial_plat2_deg);
  st.plat1_deg = eq5_position_deg(first + static_cast<int>(tag % 4), 1, box_.flip_angle_deg);
  st.plat2_deg = eq5_position_deg(first + static_cast<int>(tag % 4), 2, box_.flip_angle_deg);
  st.plat1_rest = st.plat2_rest = true;
  seg_tag_ = tag;
}

StandstillStep StandstillDetector::push(const Sample& s, double dt_s, const Eigen::Vector3d& bias1_dps,
                                        const Eigen::Vector3d& bias2_dps) {
  n_closed_ = 0;
  discarded_last_ = false;
  StandstillStep st;
  bool at_rest = false;
  seg_tag_ = 0;
  switch (cfg_.standstill) {
    case StandstillSource::kPlatformColumns:
      at_rest = classify(s, dt_s, st);
      break;
    case StandstillSource::kGyroSignal:
      gyro_.push(s.gyro1_dps, s.gyro2_dps, bias1_dps, bias2_dps, dt_s, s.t_s);
      at_rest = gyro_.motion() == GyroFlipTracker::Motion::kRest;
      // after a time gap the positions are unknown until the tracker finds them again
      st.plat1_deg = gyro_.motion() == GyroFlipTracker::Motion::kUnknown ? kNaN : gyro_.position_deg(1);
      st.plat2_deg = gyro_.motion() == GyroFlipTracker::Motion::kUnknown ? kNaN : gyro_.position_deg(2);
      // each platform on its own: the one that rests still gives the box rate during the other's flip
      st.plat1_rest = gyro_.rest(1);
      st.plat2_rest = gyro_.rest(2);
      st.plat1_starting = gyro_.starting(1);
      st.plat2_starting = gyro_.starting(2);
      st.both_moving = gyro_.motion() == GyroFlipTracker::Motion::kBoth;
      break;
    case StandstillSource::kSchedule:
      schedule_positions(s, st);
      at_rest = true;
      break;
  }
  // a change of position, or motion, closes the segment
  if (!at_rest) {
    end_standstill();
    st.state = StandstillStep::State::kMoving;
  } else {
    const double tol = cfg_.angle_tolerance_deg;
    const bool same = active_ && seg_.tag == seg_tag_ && std::fabs(st.plat1_deg - seg_.plat1_deg) <= tol &&
                      std::fabs(st.plat2_deg - seg_.plat2_deg) <= tol;
    if (!same) {
      end_standstill();
      start_segment(s.t_s, st.plat1_deg, st.plat2_deg, seg_tag_);
    }
    t_rest_last_s_ = s.t_s;
    if (s.t_s - seg_.t_rest_s < cfg_.settle_s) {
      st.state = StandstillStep::State::kSettling;
    } else {
      st.state = StandstillStep::State::kAccumulating;
      accumulate(pending_of(s));
    }
  }
  st.closed = n_closed_;
  return st;
}

int StandstillDetector::finish() {
  n_closed_ = 0;
  discarded_last_ = false;
  if (!active_) return 0;
  // no motion follows: the samples of the end margin are good data
  while (ring_count_ > 0) {
    const Pending p = ring_[ring_head_];
    ring_head_ = (ring_head_ + 1) % ring_.size();
    --ring_count_;
    commit(p);
  }
  close_segment(SegmentEnd::kFinish);
  return n_closed_;
}

void StandstillDetector::start_segment(double t_s, double p1, double p2, std::int64_t tag) {
  seg_ = StandstillSegment{};
  ring_head_ = ring_count_ = 0;
  active_ = true;
  seg_.t_rest_s = t_s;
  seg_.plat1_deg = p1;
  seg_.plat2_deg = p2;
  seg_.tag = tag;
}

// closes the standstill in progress; the end margin (samples just before the motion) is dropped
void StandstillDetector::end_standstill() {
  ring_head_ = ring_count_ = 0;
  close_segment(SegmentEnd::kMotion);
}

// hands the committed samples over (or counts a standstill too short to use)
void StandstillDetector::close_segment(SegmentEnd why) {
  if (!active_) return;
  active_ = false;
  if (cfg_.per_sample_updates) return;  // its samples were handed over one by one
  StandstillSegment s = seg_;
  s.end = why;
  const double rate = rate_hz(s);
  const double duration = finite(rate) ? double(s.n) / rate : 0.0;
  if (s.n == 0 || !finite(rate) || duration + 1e-9 < cfg_.min_standstill_s) {
    ++too_short_;
    discarded_last_ = true;
    note_short_rest(finite(t_rest_last_s_) ? t_rest_last_s_ - s.t_rest_s : 0.0, duration);
    return;
  }
  hand_over(s);
}

// a rest too short to use: its length as logged and the part that was left of it
void StandstillDetector::note_short_rest(double logged_s, double usable_s) {
  ++short_rests_.count;
  if (!finite(logged_s) || logged_s < 0.0) logged_s = 0.0;
  short_rests_.sum_logged_s += logged_s;
  short_rests_.longest_logged_s = std::max(short_rests_.longest_logged_s, logged_s);
  if (finite(usable_s)) short_rests_.longest_usable_s = std::max(short_rests_.longest_usable_s, usable_s);
}

void StandstillDetector::hand_over(const StandstillSegment& seg) {
  if (n_closed_ < static_cast<int>(closed_.size())) closed_[static_cast<std::size_t>(n_closed_++)] = seg;
}

// a resting sample enters the ring; the one falling out of the end margin is committed
void StandstillDetector::accumulate(const Pending& p) {
  if (ring_capacity_ == 0) {
    commit(p);
    return;
  }
  const std::size_t slots = ring_.size();
  if (ring_count_ == ring_capacity_) {
    const Pending old = ring_[ring_head_];
    ring_head_ = (ring_head_ + 1) % slots;
    --ring_count_;
    commit(old);
  }
  ring_[(ring_head_ + ring_count_) % slots] = p;
  ++ring_count_;
}

void StandstillDetector::commit(const Pending& p) {
  if (seg_.n == 0) seg_.t_first_s = p.t_s;
  seg_.t_last_s = p.t_s;
  ++seg_.n;
  seg_.sum_gyro1_dps += p.y1;
  seg_.sum_gyro2_dps += p.y2;
  if (p.f1.allFinite() && p.f2.allFinite()) {
    ++seg_.n_accel;
    seg_.sum_accel1_mps2 += p.f1;
    seg_.sum_accel2_mps2 += p.f2;
  }
  if (p.up.allFinite()) {
    ++seg_.n_up;
    seg_.sum_up_box += p.up;
  }
  if (finite(p.temp1) && finite(p.temp2)) {
    ++seg_.n_temp;
    seg_.sum_temp1_c += p.temp1;
    seg_.sum_temp2_c += p.temp2;
  }
  if (cfg_.per_sample_updates) {
    // one segment per sample
    StandstillSegment one = seg_;
    one.n = 1;
    one.t_first_s = one.t_last_s = p.t_s;
    one.sum_gyro1_dps = p.y1;
    one.sum_gyro2_dps = p.y2;
    one.n_accel = p.f1.allFinite() && p.f2.allFinite() ? 1 : 0;
    one.sum_accel1_mps2 = one.n_accel ? p.f1 : Eigen::Vector3d::Zero();
    one.sum_accel2_mps2 = one.n_accel ? p.f2 : Eigen::Vector3d::Zero();
    one.n_up = p.up.allFinite() ? 1 : 0;
    one.sum_up_box = one.n_up ? p.up : Eigen::Vector3d::Zero();
    one.n_temp = finite(p.temp1) && finite(p.temp2) ? 1 : 0;
    one.sum_temp1_c = one.n_temp ? p.temp1 : 0.0;
    one.sum_temp2_c = one.n_temp ? p.temp2 : 0.0;
    one.end = SegmentEnd::kSample;
    hand_over(one);
  } else if (cfg_.max_standstill_s > 0.0 && p.t_s - seg_.t_first_s >= cfg_.max_standstill_s) {
    // split a long standstill: hand over now, keep accumulating the same position (no settle);
    // the ring of pending samples carries over
    const StandstillSegment keep = seg_;
    close_segment(SegmentEnd::kSplit);
    seg_ = StandstillSegment{};
    active_ = true;
    seg_.t_rest_s = keep.t_rest_s;
    seg_.plat1_deg = keep.plat1_deg;
    seg_.plat2_deg = keep.plat2_deg;
    seg_.tag = keep.tag;
  }
}

}  // namespace driftless::est
