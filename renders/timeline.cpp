#include "renders/timeline.hpp"

#include <fmt/core.h>

namespace driftless::render {

void TimelineParams::validate() const {
  if (!(fps > 0.0 && fps <= 240.0)) {
    throw std::invalid_argument(fmt::format("--fps {} frames/s is outside (0, 240]", fps));
  }
  if (!(speed > 0.0 && std::isfinite(speed))) {
    throw std::invalid_argument(fmt::format("--speed {} must be a positive factor (x real time)",
                                            speed));
  }
  if (!std::isnan(from_s) && !std::isfinite(from_s)) {
    throw std::invalid_argument("--from must be a finite time in s");
  }
  if (!std::isnan(to_s) && !std::isfinite(to_s)) {
    throw std::invalid_argument("--to must be a finite time in s");
  }
  if (!std::isnan(from_s) && !std::isnan(to_s) && !(to_s > from_s)) {
    throw std::invalid_argument(
        fmt::format("--to {} s must be later than --from {} s", to_s, from_s));
  }
  if (!std::isnan(realtime_flip_every_s) && !(realtime_flip_every_s >= 0.0)) {
    throw std::invalid_argument("--realtime-flip-every must be >= 0 s (0: never)");
  }
  if (!(flip_lead_s >= 0.0 && flip_tail_s >= 0.0)) {
    throw std::invalid_argument("flip lead and tail must be >= 0 s");
  }
}

double TimelineParams::realtime_flip_interval_s() const {
  if (std::isnan(realtime_flip_every_s)) return speed * kRealtimeFlipVideoGapS;
  if (realtime_flip_every_s == 0.0) return std::numeric_limits<double>::infinity();
  return realtime_flip_every_s;
}

bool PlatformTracker::update(double t_s, double plat1_deg, double plat2_deg) {
  const double deg[2] = {plat1_deg, plat2_deg};
  const double dt = t_s - last_t_s_;
  bool started = false;
  int starter = -1;
  for (int i = 0; i < 2; ++i) {
    bool now_moving;
    if (std::isnan(deg[i])) {
      now_moving = true;  // hardware logs leave the angle empty while the platform moves
    } else if (std::isnan(prev_raw_deg_[i]) || !(dt > 0.0)) {
      now_moving = false;  // an angle after a gap: hardware reports it at the end stop
    } else {
      now_moving = std::abs(deg[i] - prev_raw_deg_[i]) / dt > rest_rate_dps_;
    }
    if (now_moving && !moving_[i] && !std::isnan(last_t_s_)) {
      if (!started) starter = i;
      started = true;
      from_deg_[i] = last_deg_[i];
    }
    moving_[i] = now_moving;
    if (!std::isnan(deg[i])) last_deg_[i] = deg[i];
    prev_raw_deg_[i] = deg[i];
  }
  if (started) {
    prev_start_s_ = last_start_s_;
    last_start_s_ = t_s;
    last_platform_ = starter;
    ++flips_;
  }
  if (any_moving()) {
    rest_since_s_ = kNaN;
  } else if (std::isnan(rest_since_s_)) {
    rest_since_s_ = t_s;
  }
  last_t_s_ = t_s;
  return started;
}

double PlatformTracker::predicted_next_flip_s() const {
  if (std::isnan(prev_start_s_) || std::isnan(last_start_s_)) return kNaN;
  return last_start_s_ + (last_start_s_ - prev_start_s_);
}

}  // namespace driftless::render
