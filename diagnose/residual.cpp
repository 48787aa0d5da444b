#include "diagnose/residual.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/core.h>

#include "estimator/sample.hpp"

namespace driftless::diagnose {
namespace {

double median_abs(std::vector<double> v) {
  if (v.empty()) return 0.0;
  auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end(), [](double a, double b) { return std::abs(a) < std::abs(b); });
  return std::abs(*mid);
}

// a platform that leaves its stop while the log says it rests (lifted by a box acceleration the
// servo cannot hold, or bouncing after a flip) turns the sensor about the hinge axis only: the
// residual along the hinge jumps between samples far beyond the noise while the other axes do
// not. Those bursts are left out (no model here predicts them); returns how many samples.
std::size_t mask_hinge_bursts(const Replay& r, int s, Residual& res) {
  const std::size_t n = res.n;
  const Eigen::Vector3d a = r.hinge_axis[s];
  std::vector<double> dh(n, 0.0), doff(n, 0.0), sample;
  for (std::size_t k = 1; k < n; ++k) {
    if (!res.mask[k] || !res.mask[k - 1]) continue;
    Eigen::Vector3d d;
    for (int j = 0; j < 3; ++j) d[j] = res.e_dps(s * 3 + j, k) - res.e_dps(s * 3 + j, k - 1);
    dh[k] = std::abs(a.dot(d));
    doff[k] = (d - a * a.dot(d)).norm();
    if (k % 3 == 0) sample.push_back(dh[k]);
  }
  if (sample.size() < 20) return 0;
  // robust spread of the hinge differences (floored: a noise-free log has none)
  const double sd = std::max(1.4826 * median_abs(sample), 1e-3);
  const auto guard = static_cast<std::size_t>(std::ceil(0.1 * res.fs_hz));
  std::vector<std::uint8_t> bad(n, 0);
  for (std::size_t k = 1; k < n; ++k) {
    if (!(dh[k] > 12.0 * sd && dh[k] > 3.0 * doff[k])) continue;
    const std::size_t lo = k >= guard ? k - guard : 0, hi = std::min(n - 1, k + guard);
    std::fill(bad.begin() + static_cast<std::ptrdiff_t>(lo), bad.begin() + static_cast<std::ptrdiff_t>(hi + 1), 1);
  }
  std::size_t cnt = 0;
  for (std::size_t k = 0; k < n; ++k) {
    if (bad[k] && res.mask[k]) {
      res.mask[k] = 0;
      ++cnt;
    }
  }
  return cnt;
}

// blocks of block_s: a block enters the fits when at least half its samples are usable
void lay_out_blocks(const Replay& r, double block_s, Residual& res) {
  const std::size_t n = res.n;
  const std::size_t L = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(block_s * res.fs_hz)));
  const std::size_t mb = (n + L - 1) / L;
  res.block_len = L;
  res.blocks = mb;
  BlockSeries& b = res.block_series;
  b.sample_rate_hz = res.fs_hz;
  b.t_s.resize(mb);
  b.count.resize(mb);
  for (std::size_t j = 0; j < mb; ++j) {
    const std::size_t a = j * L, e = std::min(n, a + L);
    int cnt = 0;
    for (std::size_t k = a; k < e; ++k) cnt += res.mask[k];
    b.count[j] = static_cast<std::uint16_t>(2 * static_cast<std::size_t>(cnt) >= L ? cnt : 0);
    b.t_s[j] = 0.5 * (r.t_s[a] + r.t_s[e - 1]);
  }
  res.bmask.resize(n);
  for (std::size_t k = 0; k < n; ++k) res.bmask[k] = res.mask[k] && b.count[k / L] > 0;
}

}  // namespace

Residual make_residual(const Replay& r, const CompareModel& model, double block_s) {
  Residual res;
  res.n = r.size();
  res.fs_hz = r.sample_rate_hz;
  res.sensors = r.sensors;
  // platforms resting on stops: the model's stop errors plus the servo's press into the stop
  // (the MuJoCo box settled on them); logs with an encoder read the true angle instead
  const Eigen::Matrix2d settled = r.encoder_readback ? Eigen::Matrix2d::Zero() : settled_stop_offsets_deg(model.box);
  res.replay = &r;
  for (int s = 0; s < 2; ++s) {
    SensorPrediction& p = res.pred[s];
    p = predict_sensor(r, s, model.sensor[s], model.box, model.time_offset_s, settled);
    for (int j = 0; j < 3; ++j) {
      std::vector<float>& e = res.e_f[static_cast<std::size_t>(s * 3 + j)];
      e.resize(res.n);
      for (std::size_t k = 0; k < res.n; ++k) e[k] = static_cast<float>(r.gyro_dps[s][k][j] - p.gyro_dps[k][j]);
    }
    p.gyro_dps = std::vector<Eigen::Vector3d>();  // (not "= {}": that clears and keeps the memory)
    // the log's temperature where it has one everywhere: read from the replay, not copied
    const bool all_logged = p.temp_from_log && std::all_of(r.temp_c[s].begin(), r.temp_c[s].end(), [](double t) { return std::isfinite(t); });
    if (all_logged) p.temp_c = std::vector<double>();
  }
  if (!r.has_temp) res.notes.push_back("the log has no temperature columns: the model's temperature curve is used");
  res.mask.resize(res.n);
  for (std::size_t k = 0; k < res.n; ++k) res.mask[k] = r.usable[k] && !r.flipping[k] && !r.rough[k];
  for (int s = 0; s < res.sensors; ++s) {
    const std::size_t cnt = mask_hinge_bursts(r, s, res);
    if (cnt == 0) continue;
    res.notes.push_back(fmt::format(
        "{} samples where platform {} turned about its hinge while the log says it rests (gyro {} jumps along the "
        "hinge axis beyond 12x its noise, the other axes do not: the platform left its stop) are left out of the fits",
        cnt, s + 1, s + 1));
  }
  res.samples_used = static_cast<std::size_t>(std::count(res.mask.begin(), res.mask.end(), 1));
  if (res.samples_used < 50) {
    throw std::runtime_error(fmt::format("{}: only {} samples with both platforms at rest and known truth; "
                                         "compare needs at least 50", r.log_path, res.samples_used));
  }
  lay_out_blocks(r, block_s, res);
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (int s = 0; s < res.sensors; ++s) {
    for (std::size_t k = 0; k < res.n; k += 10) {
      lo = std::min(lo, res.temp_c(s, k));
      hi = std::max(hi, res.temp_c(s, k));
    }
  }
  res.temp_span_c = hi - lo;
  return res;
}

}  // namespace driftless::diagnose
