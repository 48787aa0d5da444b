#include "estimator/clip_detector.hpp"

#include <cmath>

namespace driftless::est {

void ClipDetector::push(int channel, double v_dps, bool platforms_resting) {
  Channel& c = ch_[static_cast<std::size_t>(channel)];
  ++c.rows;
  if (!std::isnan(v_dps)) {
    if (c.finite++ == 0) c.first_dps = v_dps;
    c.varies = c.varies || v_dps != c.first_dps;
  }
  if (std::isnan(v_dps)) {
    c.run = c.run_at_rest = 0;
    c.run_value_dps = v_dps;
    return;
  }
  const double a = std::fabs(v_dps);
  // a new largest reading: the plateau counted so far was below the channel's range
  if (a > c.max_abs_dps) {
    c.max_abs_dps = a;
    c.plateau = c.plateau_at_rest = 0;
  }
  const bool same = v_dps == c.run_value_dps;
  c.run = same ? c.run + 1 : 1;
  c.run_at_rest = (same ? c.run_at_rest : 0) + (platforms_resting ? 1 : 0);
  c.run_value_dps = v_dps;
  if (a != c.max_abs_dps || c.run < kMinRun) return;
  // the run's first kMinRun samples count once it is long enough, then each one as it comes
  if (c.run == kMinRun) {
    c.plateau += static_cast<std::uint64_t>(kMinRun);
    c.plateau_at_rest += static_cast<std::uint64_t>(c.run_at_rest);
  } else {
    ++c.plateau;
    c.plateau_at_rest += platforms_resting ? 1 : 0;
  }
}

std::vector<ClippedChannel> ClipDetector::suspected() const {
  std::vector<ClippedChannel> out;
  for (std::size_t i = 0; i < ch_.size(); ++i) {
    const Channel& c = ch_[i];
    if (c.max_abs_dps >= kMinLevelDps && c.plateau >= kMinSamples) {
      out.push_back(ClippedChannel{static_cast<int>(i), c.max_abs_dps, c.plateau, c.plateau_at_rest});
    }
  }
  return out;
}

std::vector<DeadChannel> ClipDetector::dead(int channels) const {
  std::vector<DeadChannel> out;
  for (int i = 0; i < channels && i < static_cast<int>(ch_.size()); ++i) {
    const Channel& c = ch_[static_cast<std::size_t>(i)];
    if (c.rows == 0) continue;
    if (c.finite == 0) {
      out.push_back(DeadChannel{DeadChannel::Kind::kEmpty, i, 0.0, c.rows});
      continue;
    }
    // stuck: one value throughout while a sibling axis of the same sensor moves (a noise-free
    // log of a box that never moves holds every channel constant: not a dead axis)
    const int first = i < 3 ? 0 : 3;
    bool sibling_varies = false;
    for (int j = first; j < first + 3; ++j) sibling_varies |= j != i && ch_[static_cast<std::size_t>(j)].varies;
    if (!c.varies && c.finite >= kMinStuckRows && sibling_varies) {
      out.push_back(DeadChannel{DeadChannel::Kind::kStuck, i, c.first_dps, c.rows});
    }
  }
  return out;
}

}  // namespace driftless::est
