// Which data time each video frame shows: real time, slow motion, or a time-lapse in which
// flips are still shown in real time every so often (docs/render.md, "time-lapse rule").
#pragma once

#include <cmath>
#include <deque>
#include <limits>
#include <stdexcept>
#include <utility>

#include "estimator/sample.hpp"

namespace driftless::render {

/// The frame clock. Times are data (simulation or log) seconds.
struct TimelineParams {
  double fps = 30.0;             // video frames per second of video, frames/s
  double speed = 1.0;            // data seconds per video second (x real time); < 1 = slow motion
  double from_s = kNaN;          // first data time shown, s (NaN: the first sample)
  double to_s = kNaN;            // data time at which the video ends (exclusive), s (NaN: the end)
  // time-lapse (speed > 1): a flip that starts at least this long after the last flip shown in
  // real time is played at x1; NaN: speed * kRealtimeFlipVideoGapS; 0 or inf: never
  double realtime_flip_every_s = kNaN;
  double flip_lead_s = 0.5;      // real-time play starts this long before a flip, s
  double flip_tail_s = 0.5;      // and ends this long after both platforms are at rest, s

  /// Video seconds of time-lapse between two real-time flips when realtime_flip_every_s is NaN.
  static constexpr double kRealtimeFlipVideoGapS = 5.0;

  /// Throws std::invalid_argument naming the option (fps, speed, from/to) on bad values.
  void validate() const;
  /// The rule's interval in data seconds (resolves the NaN default), inf when disabled.
  double realtime_flip_interval_s() const;
};

/// Platform motion as seen in a stream of plat*_deg values (NaN = moving, as hardware logs it).
class PlatformTracker {
 public:
  /// rest_rate_dps: a platform turning slower than this counts as at rest.
  explicit PlatformTracker(double rest_rate_dps = 2.0) : rest_rate_dps_(rest_rate_dps) {}
  /// Feeds one sample; returns true when a flip starts at this sample (rest -> moving).
  bool update(double t_s, double plat1_deg, double plat2_deg);
  bool moving(int i) const { return moving_[i]; }
  bool any_moving() const { return moving_[0] || moving_[1]; }
  /// Last known angle of platform i (0 or 1), deg (NaN before any).
  double angle_deg(int i) const { return last_deg_[i]; }
  /// Angle of platform i when its latest flip started (at rest before it), deg (NaN before any).
  double flip_from_deg(int i) const { return from_deg_[i]; }
  /// Start time of the latest flip of any platform, s (NaN before any).
  double last_flip_start_s() const { return last_start_s_; }
  /// Which platform (0/1) moved in the latest flip, -1 before any.
  int last_flip_platform() const { return last_platform_; }
  /// Time since both platforms came to rest, s (0 while moving).
  double rest_duration_s(double t_s) const {
    return any_moving() || std::isnan(rest_since_s_) ? 0.0 : t_s - rest_since_s_;
  }
  /// Predicted start of the next flip: last start + last interval between starts (NaN if unknown).
  double predicted_next_flip_s() const;
  /// Platform expected to flip next: the other one (Fig. 3 alternates), -1 if unknown.
  int predicted_next_platform() const { return last_platform_ < 0 ? -1 : 1 - last_platform_; }
  int flips_seen() const { return flips_; }

 private:
  double rest_rate_dps_;
  bool moving_[2] = {false, false};
  double last_deg_[2] = {kNaN, kNaN};      // last finite angle
  double from_deg_[2] = {kNaN, kNaN};      // angle at the start of the latest flip
  double prev_raw_deg_[2] = {kNaN, kNaN};  // previous sample's value, NaN kept
  double last_t_s_ = kNaN;
  double rest_since_s_ = kNaN;
  double last_start_s_ = kNaN;
  double prev_start_s_ = kNaN;
  int last_platform_ = -1;
  int flips_ = 0;
};

/// What a frame shows and why.
struct FrameInfo {
  double t_s = kNaN;        // data time of the frame
  std::uint64_t index = 0;  // frame number in the video
  bool realtime_flip = false;  // part of a flip played at x1 inside a time-lapse
};

/// Turns a time-ordered stream of samples into frames, streaming at bounded memory. Each frame
/// shows the latest sample at or before its time (sample and hold). Payload: what a frame
/// needs of a sample (the caller's pose and overlay state).
template <class Payload>
class FramePlanner {
 public:
  explicit FramePlanner(const TimelineParams& p)
      : p_(p), every_s_(p.realtime_flip_interval_s()), timelapse_(p.speed > 1.0) {
    p_.validate();
  }

  /// Feeds the next sample. flip_starts / at_rest_s come from a PlatformTracker fed the same
  /// sample. Calls emit(const FrameInfo&, const Payload&) for every frame now decided.
  /// Returns false once the video is complete (the caller may stop reading).
  template <class Emit>
  bool push(double t_s, bool flip_starts, double at_rest_s, Payload payload, Emit&& emit) {
    if (done_) return false;
    if (std::isnan(next_s_)) next_s_ = std::isnan(p_.from_s) ? t_s : p_.from_s;
    if (buffer_.empty() && next_s_ < t_s) next_s_ = t_s;  // the video starts with the data
    const bool shown = std::isnan(p_.from_s) || t_s >= p_.from_s;
    // a selected flip inside a time-lapse moves the clock back to just before it; every frame
    // so far is older than this sample, and the samples since the last frame are kept
    if (timelapse_ && !realtime_ && flip_starts && shown &&
        (std::isnan(last_rt_flip_s_) || t_s - last_rt_flip_s_ >= every_s_)) {
      realtime_ = true;
      last_rt_flip_s_ = t_s;
      double start = t_s - p_.flip_lead_s;
      if (!std::isnan(last_frame_s_)) start = std::max(start, last_frame_s_ + 1.0 / p_.fps);
      if (!std::isnan(p_.from_s)) start = std::max(start, p_.from_s);
      next_s_ = std::max(start, buffer_front_t());
    }
    rest_s_ = at_rest_s;
    while (t_s > next_s_ && !done_) emit_next(emit);
    buffer_.emplace_back(t_s, std::move(payload));
    trim();
    return !done_;
  }

  /// Ends the stream: frames up to the last sample (and before to_s) are emitted.
  template <class Emit>
  void finish(Emit&& emit) {
    if (!buffer_.empty()) {
      const double last_t = buffer_.back().first;
      while (!done_ && next_s_ <= last_t + 1e-9) emit_next(emit);
    }
    done_ = true;
  }

  bool done() const { return done_; }
  std::uint64_t frames() const { return frames_; }
  /// Data time of the next frame to be emitted (NaN before the first sample).
  double next_frame_s() const { return next_s_; }
  bool in_realtime_flip() const { return realtime_; }
  /// Samples held for later frames (bounded by speed/fps data seconds).
  std::size_t buffered() const { return buffer_.size(); }

 private:
  double step_fast() const { return p_.speed / p_.fps; }
  double buffer_front_t() const {
    return buffer_.empty() ? -std::numeric_limits<double>::infinity() : buffer_.front().first;
  }

  template <class Emit>
  void emit_next(Emit& emit) {
    if (!std::isnan(p_.to_s) && next_s_ >= p_.to_s - 1e-9) {
      done_ = true;
      return;
    }
    // the held sample: the latest at or before the frame time (the first, before the data)
    const Payload* held = nullptr;
    for (auto it = buffer_.rbegin(); it != buffer_.rend(); ++it) {
      if (it->first <= next_s_ + 1e-9) {
        held = &it->second;
        break;
      }
    }
    if (held == nullptr) {
      if (buffer_.empty()) {  // unreachable: push() starts the clock at the first sample
        done_ = true;
        return;
      }
      held = &buffer_.front().second;
    }
    FrameInfo info;
    info.t_s = next_s_;
    info.index = frames_;
    info.realtime_flip = realtime_;
    emit(info, *held);
    if (frames_ == 0) origin_s_ = next_s_;
    ++frames_;
    last_frame_s_ = next_s_;
    // the next frame time: x1 inside a shown flip, else the chosen speed; without a time-lapse
    // frames count from a fixed origin so long runs accumulate no rounding
    if (realtime_ && rest_s_ >= p_.flip_tail_s) realtime_ = false;
    if (!timelapse_) {
      next_s_ = origin_s_ + static_cast<double>(frames_) * step_fast();
    } else {
      next_s_ = last_frame_s_ + (realtime_ ? 1.0 / p_.fps : step_fast());
    }
  }

  void trim() {
    // keep the sample held by the next frame and, in a time-lapse, all since the last frame
    double keep_from = next_s_;
    if (timelapse_ && !std::isnan(last_frame_s_)) keep_from = std::min(keep_from, last_frame_s_);
    while (buffer_.size() > 1 && buffer_[1].first <= keep_from + 1e-9) buffer_.pop_front();
  }

  TimelineParams p_;
  double every_s_;
  bool timelapse_;
  bool realtime_ = false;
  bool done_ = false;
  double next_s_ = kNaN;
  double last_frame_s_ = kNaN;
  double last_rt_flip_s_ = kNaN;
  double rest_s_ = 0.0;
  double origin_s_ = kNaN;
  std::uint64_t frames_ = 0;
  std::deque<std::pair<double, Payload>> buffer_;
};

}  // namespace driftless::render
