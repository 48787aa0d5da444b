// The sensors' sampling offset (see truth_delay.hpp).
#include "twin/truth_delay.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/core.h>

namespace driftless::twin {

namespace {

double checked_shift(double offset_s, double sample_rate_hz) {
  if (!(offset_s >= 0)) {
    throw std::invalid_argument(fmt::format(
        "model.time_offset_s = {} s: simulate models sensors sampling before the log's time stamp "
        "(offset >= 0) only; compare and diagnose honour negative offsets",
        offset_s));
  }
  return offset_s * sample_rate_hz;
}

}  // namespace

TruthDelay::TruthDelay(double offset_s, double sample_rate_hz)
    : shift_(checked_shift(offset_s, sample_rate_hz)),
      whole_(shift_ > 0 ? static_cast<std::size_t>(std::floor(shift_)) : 0),
      keep_(shift_ > 0 ? static_cast<std::size_t>(std::ceil(shift_)) + 2 : 0),
      frac_(shift_ > 0 ? shift_ - std::floor(shift_) : 0.0) {}

void TruthDelay::apply(Eigen::Vector3d w_radps[2], Eigen::Vector3d f_mps2[2]) {
  if (!(shift_ > 0)) return;
  history_.push_back({{w_radps[0], w_radps[1]}, {f_mps2[0], f_mps2[1]}});
  while (history_.size() > keep_) history_.pop_front();
  const std::size_t last = history_.size() - 1;
  const Entry& a = history_[last >= whole_ ? last - whole_ : 0];
  const Entry& b = history_[last >= whole_ + 1 ? last - whole_ - 1 : 0];
  for (int i = 0; i < 2; ++i) {
    w_radps[i] = (1.0 - frac_) * a.w_radps[i] + frac_ * b.w_radps[i];
    f_mps2[i] = (1.0 - frac_) * a.f_mps2[i] + frac_ * b.f_mps2[i];
  }
}

}  // namespace driftless::twin
