// Stage 1 of a comparison: the model's prediction along a replayed log, the residual
// (measured - predicted) per channel, which samples the fits may use, and the block layout.
// docs/compare.md sections 1-2.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
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
  // the model's temperature per sensor (the prediction's output is dropped once e_f is formed;
  // its temperature too when it is the log's, read from the replay instead)
  std::array<SensorPrediction, 2> pred;
  /// measured - predicted per channel (sensor c / 3, axis c % 3), deg/s, as float: 7 significant
  /// digits of a residual of the noise's size, half of what the double prediction took
  std::array<std::vector<float>, 6> e_f;
  /// measured - predicted of channel c at sample k, deg/s; NaN where unusable. The replay it was
  /// made from must outlive it
  double e_dps(int c, std::size_t k) const { return replay->usable[k] ? static_cast<double>(e_f[c][k]) : kNaN; }
  /// The model's noise-free output of sensor s, axis j at sample k (measured - e_f), deg/s.
  double pred_dps(int s, int j, std::size_t k) const {
    return replay->gyro_dps[s][k][j] - static_cast<double>(e_f[s * 3 + j][k]);
  }
  /// The temperature the model runs at for sensor s at sample k, degC.
  double temp_c(int s, std::size_t k) const {
    return pred[s].temp_c.empty() ? replay->temp_c[s][k] : pred[s].temp_c[k];
  }
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

/// Block means of x(k) over the samples the fits use (bmask; NaN skipped) into `out`: the same
/// sums in the same order as block_means() of the series, without a per-sample copy of it.
template <class X>
void block_means_of(const Residual& res, X&& x, std::vector<double>& out) {
  out.resize(res.blocks);
  for (std::size_t b = 0; b < res.blocks; ++b) {
    double acc = 0.0;
    int cnt = 0;
    const std::size_t a = b * res.block_len, e = std::min(res.n, a + res.block_len);
    for (std::size_t k = a; k < e; ++k) {
      if (!res.bmask[k]) continue;
      const double v = x(k);
      if (std::isfinite(v)) acc += v, ++cnt;
    }
    out[b] = cnt > 0 ? acc / cnt : 0.0;
  }
}

}  // namespace driftless::diagnose
