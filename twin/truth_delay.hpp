// model.time_offset_s (docs/scenario.md): the sensors sample the truth `offset` before the log's
// time stamp. The Simulator and the closed-form FastBox delay their per-sample sensor truths
// through this one short history: linear interpolation between the output samples around
// t - offset (before the first sample: the first sample's truth).
#pragma once

#include <cstddef>
#include <deque>

#include <Eigen/Core>

namespace driftless::twin {

class TruthDelay {
 public:
  /// `offset_s` >= 0 (0: no delay; negative or NaN throws std::invalid_argument naming
  /// model.time_offset_s), `sample_rate_hz` the output rate.
  TruthDelay(double offset_s, double sample_rate_hz);
  /// Takes this output sample's truths per sensor (rate in rad/s, specific force in m/s^2, sensor
  /// axes) and replaces them with the truths `offset_s` earlier.
  void apply(Eigen::Vector3d w_radps[2], Eigen::Vector3d f_mps2[2]);

 private:
  struct Entry {
    Eigen::Vector3d w_radps[2], f_mps2[2];
  };
  double shift_;  // the offset in output samples
  std::size_t whole_, keep_;
  double frac_;
  std::deque<Entry> history_;
};

}  // namespace driftless::twin
