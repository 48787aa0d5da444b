#include "estimator/clip_detector.hpp"

#include <cmath>

namespace driftless::est {

void ClipDetector::push(int channel, double v_dps) {
  Channel& c = ch_[static_cast<std::size_t>(channel)];
  if (std::isnan(v_dps)) {
    c.run = 0;
    c.run_value_dps = v_dps;
    return;
  }
  const double a = std::fabs(v_dps);
  // a new largest reading: the plateau counted so far was below the channel's range
  if (a > c.max_abs_dps) {
    c.max_abs_dps = a;
    c.plateau = 0;
  }
  c.run = v_dps == c.run_value_dps ? c.run + 1 : 1;
  c.run_value_dps = v_dps;
  if (a != c.max_abs_dps) return;
  if (c.run == kMinRun) c.plateau += static_cast<std::uint64_t>(kMinRun);
  else if (c.run > kMinRun) ++c.plateau;
}

std::vector<ClippedChannel> ClipDetector::suspected() const {
  std::vector<ClippedChannel> out;
  for (std::size_t i = 0; i < ch_.size(); ++i) {
    const Channel& c = ch_[i];
    if (c.max_abs_dps >= kMinLevelDps && c.plateau >= kMinSamples) {
      out.push_back(ClippedChannel{static_cast<int>(i), c.max_abs_dps, c.plateau});
    }
  }
  return out;
}

}  // namespace driftless::est
