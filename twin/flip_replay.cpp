#include "twin/flip_replay.hpp"

#include <algorithm>
#include <cmath>

namespace driftless::twin {
namespace {
// two rests this close are the same rest: a 1e-9 rad difference moves the gyro truth by less
// than 1e-9 of the rate it sees
constexpr double kSameRestRad = 1e-9;
}  // namespace

void FlipReplay::start_recording(int i, int sign, double start_angle_rad) {
  recording_ = Flip{i, sign, start_angle_rad, {}};
  recording_->steps.reserve(4096);
}

void FlipReplay::record(const Step& s) {
  if (recording_) recording_->steps.push_back(s);
}

void FlipReplay::stop_recording(bool came_to_rest) {
  if (recording_ && came_to_rest && !recording_->steps.empty()) {
    const Flip& r = *recording_;
    std::erase_if(flips_, [&](const Flip& f) { return f.platform == r.platform && f.sign == r.sign; });
    flips_.push_back(std::move(*recording_));
  }
  recording_.reset();
}

const FlipReplay::Flip* FlipReplay::find(int i, int sign, double start_angle_rad) const {
  for (const Flip& f : flips_) {
    if (f.platform == i && f.sign == sign && std::abs(f.start_angle_rad - start_angle_rad) <= kSameRestRad) return &f;
  }
  return nullptr;
}

}  // namespace driftless::twin
