#include "importers/stamps.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace driftless::importers {
namespace {

std::string g3(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

}  // namespace

double StampReport::mean_rate_hz() const {
  if (rows < 2 || !(last_t_s > first_t_s)) return std::numeric_limits<double>::quiet_NaN();
  return static_cast<double>(rows - 1) / (last_t_s - first_t_s);
}

double StampReport::regular_rate_hz() const {
  if (regular_steps == 0 || !(regular_sum_s > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return static_cast<double>(regular_steps) / regular_sum_s;
}

void StampMonitor::learn(std::span<const double> t) {
  std::vector<double> steps;
  for (std::size_t i = 1; i < t.size(); ++i) {
    const double d = t[i] - t[i - 1];
    if (d > 0.0 && std::isfinite(d)) steps.push_back(d);
  }
  if (steps.empty()) return;
  double mean = 0.0;
  for (double d : steps) mean += d;
  mean_step_s_ = mean / static_cast<double>(steps.size());
  std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2), steps.end());
  r_.step_s = steps[steps.size() / 2];
  r_.bursty = r_.step_s < 0.5 * mean_step_s_;
}

StampMonitor::Step StampMonitor::push(double t, std::uint64_t loc) {
  ++r_.rows;
  if (std::isnan(prev_)) {
    prev_ = r_.first_t_s = r_.last_t_s = t;
    return Step::kFirst;
  }
  const double d = t - prev_;
  prev_ = t;
  r_.last_t_s = std::max(r_.last_t_s, t);
  if (d > r_.largest_step_s) r_.largest_step_s = d, r_.largest_step_loc = loc;
  if (d < 0.0) {
    if (r_.backwards++ == 0) r_.first_backwards_loc = loc;
    return Step::kBackwards;
  }
  if (d == 0.0) {
    if (r_.repeated++ == 0) r_.first_repeated_loc = loc;
    return Step::kRepeated;
  }
  if (!r_.bursty && r_.step_s > 0.0 && d > 1.5 * r_.step_s) {
    if (r_.gaps++ == 0) r_.first_gap_loc = loc;
    r_.missing += static_cast<std::uint64_t>(std::max(0.0, std::round(d / r_.step_s) - 1.0));
    return Step::kGap;
  }
  ++r_.regular_steps;
  r_.regular_sum_s += d;
  return Step::kRegular;
}

std::vector<std::string> StampReport::describe(const std::string& w) const {
  std::vector<std::string> out;
  if (rows < 2) return out;
  if (bursty) {
    out.push_back("stamps are bursty (median step " + g3(1e3 * step_s) + " ms, mean " +
                  g3(1e3 / mean_rate_hz()) + " ms, largest " + g3(largest_step_s) + " s at " + w + " " +
                  std::to_string(largest_step_loc) +
                  "): they record arrival, not sampling, so the samples are taken as uniform at the mean rate");
  } else if (gaps > 0) {
    out.push_back(std::to_string(gaps) + " gap(s) in the stamps (" + std::to_string(missing) +
                  " samples missing at the regular step " + g3(1e3 * step_s) + " ms), the first at " + w + " " +
                  std::to_string(first_gap_loc) + ", the largest " + g3(largest_step_s) + " s at " + w + " " +
                  std::to_string(largest_step_loc));
  }
  if (backwards > 0) {
    out.push_back(std::to_string(backwards) + " stamp(s) go backwards (out of order), the first at " + w + " " +
                  std::to_string(first_backwards_loc));
  }
  if (repeated > 0) {
    out.push_back(std::to_string(repeated) + " stamp(s) repeat the previous one, the first at " + w + " " +
                  std::to_string(first_repeated_loc));
  }
  return out;
}

}  // namespace driftless::importers
