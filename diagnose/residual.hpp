// Stage 1 of a comparison: the model's prediction along a replayed log, the residual
// (measured - predicted) per channel, which samples the fits may use, and the block layout.
// docs/compare.md sections 1-2.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "diagnose/bias_filter.hpp"
#include "diagnose/compare_model.hpp"
#include "diagnose/replay.hpp"

namespace driftless::diagnose {

/// The residual of a log against a model, per sample and per 0.1 s block.
struct Residual {
  std::size_t n = 0;            // samples
  double fs_hz = 0.0;           // sample rate of the replay
  std::size_t block_len = 1;    // samples per block
  std::size_t blocks = 0;       // number of blocks
  std::array<SensorPrediction, 2> pred;       // noise-free prediction and temperature per sensor
  /// measured - predicted of channel c (sensor c / 3, axis c % 3) at sample k, deg/s; NaN where
  /// unusable. Formed when asked from the replay it was made from (which must outlive it): a
  /// stored copy was 17 MB for a 1 h log at 100 Hz
  double e_dps(int c, std::size_t k) const {
    const int s = c / 3, j = c % 3;
    return replay->usable[k] ? replay->gyro_dps[s][k][j] - pred[s].gyro_dps[k][j] : kNaN;
  }
  /// The whole series of channel c (e_dps(c, k) for every k), deg/s.
  std::vector<double> e_series(int c) const;
  const Replay* replay = nullptr;             // the replay the residual was made from
  std::vector<std::uint8_t> mask;   // sample enters the fits (usable, at rest, rebuilt, no burst)
  std::vector<std::uint8_t> bmask;  // ... and its block has enough data
  BlockSeries block_series;         // block times and sample counts (0 = block left out)
  double temp_span_c = 0.0;         // spread of the temperature over the log, degC
  int sensors = 2;                  // 1: a single-sensor log; channels 3..5 (sensor 2) are absent
  /// The channels with data: 0..2, or 0..5.
  int channels() const { return 3 * sensors; }
  std::size_t samples_used = 0;
  std::vector<std::string> notes;   // what was left out and why
};

/// Predicts both sensors along `r` with `model`, forms the residual, leaves out samples where a
/// platform left its stop while the log says it rests, and lays out blocks of `block_s`.
/// Throws std::runtime_error when fewer than 50 samples remain.
Residual make_residual(const Replay& r, const CompareModel& model, double block_s);

/// Block means of a per-sample series over the residual's blocks (masked samples only).
std::vector<double> block_series_of(const Residual& res, const std::vector<double>& x);

}  // namespace driftless::diagnose
