#include "estimator/allan_stream.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace driftless::est {
namespace {

std::size_t log2_exact(std::size_t v) {
  std::size_t k = 0;
  while ((std::size_t{1} << k) < v) ++k;
  return k;
}

constexpr std::size_t kOffsetSamples = 4096;  // the offset is the mean of this many first samples
constexpr std::size_t kMaxLevels = 60;

}  // namespace

void StreamingOptions::validate() const {
  if (!(sample_rate_hz > 0.0) || !std::isfinite(sample_rate_hz)) {
    throw std::invalid_argument("allan stream: sample_rate_hz must be a positive number (Hz)");
  }
  if (deviation == Deviation::kModifiedAllan) {
    throw std::invalid_argument("allan stream: the modified Allan deviation needs the record in memory");
  }
  if (exact_up_to_m < 1 || (exact_up_to_m & (exact_up_to_m - 1)) != 0) {
    throw std::invalid_argument("allan stream: exact_up_to_m must be a power of two (samples)");
  }
  if (!(confidence > 0.0 && confidence < 1.0)) throw std::invalid_argument("allan stream: confidence must be in (0, 1)");
}

StreamingOctaveDeviation::StreamingOctaveDeviation(const StreamingOptions& opt)
    : opt_(opt), span_(span_in_m(opt.deviation)), exact_log2_(log2_exact(opt.exact_up_to_m)) {
  opt_.validate();
  levels_.reserve(kMaxLevels);  // a level's scratch is read by the next one: no reallocation moves it
}

void StreamingOctaveDeviation::push(std::span<const double> rate) {
  if (rate.empty()) return;
  if (!have_offset_) {
    const std::size_t k = std::min(rate.size(), kOffsetSamples);
    double s = 0.0;
    for (std::size_t i = 0; i < k; ++i) s += rate[i];
    offset_ = s / static_cast<double>(k);
    have_offset_ = true;
  }
  // the phase written where it goes, the finiteness checked once per call (the sum's order is kept)
  const std::size_t lead = seg_samples_ == 0 ? 1 : 0;  // S[0] of a new segment
  scratch_.resize(rate.size() + lead);
  double* out = scratch_.data() + lead;
  if (lead == 1) scratch_[0] = 0.0;
  bool finite = true;
  double phase = phase_;
  for (std::size_t i = 0; i < rate.size(); ++i) {
    finite &= std::isfinite(rate[i]);
    phase += rate[i] - offset_;
    out[i] = phase;
  }
  if (!finite) {
    const auto bad = std::find_if(rate.begin(), rate.end(), [](double v) { return !std::isfinite(v); });
    throw std::invalid_argument("allan: sample " + std::to_string(samples_ + static_cast<std::size_t>(bad - rate.begin())) +
                                " is not a finite number (break the segment at gaps instead)");
  }
  phase_ = phase;
  seg_samples_ += rate.size();
  samples_ += rate.size();
  append(0, scratch_.data(), scratch_.size());
}

void StreamingOctaveDeviation::append(std::size_t j, const double* v, std::size_t n) {
  if (j >= kMaxLevels || n == 0) return;
  if (levels_.size() <= j) levels_.resize(j + 1);
  Level& L = levels_[j];
  const std::size_t old_end = L.count;
  L.buf.insert(L.buf.end(), v, v + n);
  L.count += n;
  for (std::size_t i = 0; i < n && L.id.size() < kMaxIdClusters + 1; ++i) L.id.push_back(v[i]);
  accumulate(j, old_end);
  // the next level: every other value (global index even), i.e. the phase at stride 2^(j+1);
  // the level's own scratch (kept: a fresh array each block is a fresh set of pages to fault in)
  std::vector<double>& half = L.half;
  half.clear();
  for (std::size_t g = old_end + (old_end % 2); g < L.count; g += 2) half.push_back(L.buf[g - L.base]);
  // keep what the longest difference still needs
  const std::size_t keep = span_ * opt_.exact_up_to_m;
  if (L.buf.size() > 2 * keep + 4096) {
    const std::size_t drop = L.buf.size() - keep;
    L.buf.erase(L.buf.begin(), L.buf.begin() + static_cast<std::ptrdiff_t>(drop));
    L.base += drop;
  }
  append(j + 1, half.data(), half.size());
}

void StreamingOctaveDeviation::accumulate(std::size_t j, std::size_t old_end) {
  Level& L = levels_[j];
  const std::size_t R = opt_.exact_up_to_m;
  // level 0: every lag 1..R (exact octaves); level j >= 1: lag R on the phase at stride 2^j
  for (std::size_t lag = (j == 0 ? 1 : R), k = (j == 0 ? 0 : exact_log2_ + j); lag <= R; lag *= 2, ++k) {
    const std::size_t reach = span_ * lag;
    if (L.count > reach) {
      const std::size_t i0 = std::max(old_end, reach) - reach, i1 = L.count - reach;
      if (sums_.size() <= k) sums_.resize(k + 1);
      if (i0 < i1) accumulate_range(opt_.deviation, L.buf.data(), i0 - L.base, i1 - L.base, lag, 1, sums_[k]);
    }
  }
}

void StreamingOctaveDeviation::break_segment() {
  if (seg_samples_ == 0) return;
  segment_lengths_.push_back(seg_samples_);
  for (Level& L : levels_) {
    if (L.id.size() > L.id_best.size()) L.id_best = L.id;
    L.id.clear();
    L.buf.clear();
    L.base = L.count = 0;
  }
  seg_samples_ = 0;
  phase_ = 0.0;
}

std::vector<double> StreamingOctaveDeviation::level_means(std::size_t k) const {
  std::vector<double> out;
  if (k >= levels_.size()) return out;
  const Level& L = levels_[k];
  const std::vector<double>& id = L.id.size() > L.id_best.size() ? L.id : L.id_best;
  const double m = std::ldexp(1.0, static_cast<int>(k));
  for (std::size_t c = 0; c + 1 < id.size(); ++c) out.push_back((id[c + 1] - id[c]) / m);
  return out;
}

AllanCurve StreamingOctaveDeviation::finish(double sample_rate_hz) const {
  const double rate = sample_rate_hz > 0.0 ? sample_rate_hz : opt_.sample_rate_hz;
  AllanCurve curve;
  curve.deviation = opt_.deviation;
  curve.sample_rate_hz = rate;
  curve.samples = samples_;
  curve.overlapping = true;
  curve.confidence = opt_.confidence;
  CiInput ci;
  ci.segment_lengths = segment_lengths_;
  if (seg_samples_ > 0) ci.segment_lengths.push_back(seg_samples_);
  curve.segments = ci.segment_lengths.size();
  for (std::size_t k = 0; k < sums_.size(); ++k) {
    if (sums_[k].terms == 0) continue;
    AllanPoint p;
    p.m = std::size_t{1} << k;
    p.tau_s = static_cast<double>(p.m) / rate;
    p.terms = sums_[k].terms;
    p.adev = deviation_from_sum(opt_.deviation, sums_[k], p.m);
    curve.points.push_back(p);
    ci.cluster_means.push_back(level_means(k));
  }
  if (curve.points.empty()) throw std::invalid_argument("allan: no averaging time fits the record (too few samples)");
  if (sums_.size() > exact_log2_ + 1) {
    curve.notes.push_back("taus beyond m = " + std::to_string(opt_.exact_up_to_m) +
                          " samples use every (m / " + std::to_string(opt_.exact_up_to_m) +
                          ")-th difference (streaming pass)");
  }
  attach_confidence_intervals(curve, ci);
  return curve;
}

}  // namespace driftless::est
