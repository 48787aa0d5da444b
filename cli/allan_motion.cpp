// `driftless allan` on a record that is not at rest: the Allan deviation of a turning sensor measures
// the motion, not the sensor's noise (a pan/tilt log, a hand-turned recording, a robot's bag). Found
// from the rate channels themselves, so it works for every input format: the 1 s means of a sensor at
// rest stay within its bias drift (hundredths of a deg/s for a MEMS gyro, a few deg/s over a full
// temperature range); a turn moves them by tens of deg/s. docs/allan.md, "A record that moves".
#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "cli/allan_input.hpp"

namespace driftless::cli::allan {
namespace {

// deg/s: a 1 s mean this far from the channel's median 1 s mean is motion, not bias drift (an MPU6050's
// turn-on bias tolerance is +-20 deg/s, but its drift over a record is below 0.06 deg/s/degC x 50 degC = 3 deg/s)
constexpr double kMotionDps = 5.0;

struct Departure {
  std::size_t blocks = 0, moving = 0;
  double largest_dps = 0.0;
  double first_s = -1.0;  // s from the start of the record (block index x block length)
};

Departure departure_of(const std::vector<double>& means, double block_s) {
  Departure d;
  std::vector<double> sorted;
  for (double m : means) {
    if (std::isfinite(m)) sorted.push_back(m);
  }
  if (sorted.empty()) return d;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  const double median = sorted[sorted.size() / 2];
  d.blocks = sorted.size();
  for (std::size_t b = 0; b < means.size(); ++b) {
    const double off = std::fabs(means[b] - median);
    if (!(off > kMotionDps)) continue;
    ++d.moving;
    d.largest_dps = std::max(d.largest_dps, off);
    if (d.first_s < 0.0) d.first_s = static_cast<double>(b) * block_s;
  }
  return d;
}

}  // namespace

void BlockMeans::push(std::span<const double> x) {
  if (per == 0) return;
  for (const double v : x) {
    if (std::isfinite(v)) sum += v, ++finite;
    if (++seen == per) {
      means.push_back(finite > 0 ? sum / static_cast<double>(finite) : std::nan(""));
      sum = 0.0, seen = 0, finite = 0;
    }
  }
}

BlockMeans::BlockMeans(double rate_hz) : per(static_cast<std::size_t>(std::max(1.0, std::round(rate_hz)))) {
  if (!(rate_hz > 0.0)) per = 0;
}

std::vector<std::string> motion_warnings(const std::vector<std::string>& names, const std::vector<BlockMeans>& per_channel,
                                         double rate_hz) {
  std::vector<std::string> out;
  std::string moving;
  double largest = 0.0, first = -1.0, share = 0.0;
  for (std::size_t c = 0; c < per_channel.size(); ++c) {
    if (per_channel[c].per == 0) continue;
    const Departure d = departure_of(per_channel[c].means, static_cast<double>(per_channel[c].per) / rate_hz);
    if (d.moving == 0) continue;
    moving += (moving.empty() ? "" : ", ") + names[c];
    largest = std::max(largest, d.largest_dps);
    share = std::max(share, static_cast<double>(d.moving) / static_cast<double>(d.blocks));
    if (first < 0.0 || d.first_s < first) first = d.first_s;
  }
  if (moving.empty()) return out;
  out.push_back(fmt::format(
      "the record is not at rest: the 1 s means of {} depart from their median by up to {:.3g} deg/s (in {:.0f} % of "
      "the seconds, first at {:.0f} s), more than the {:g} deg/s a gyro's bias drifts: the Allan deviation holds the "
      "motion, not the sensor's noise; analyse a record of the sensor at rest, or cut the motion out",
      moving, largest, 100.0 * share, first, kMotionDps));
  return out;
}

namespace {

// deg: a platform whose angle column spans more than this flipped (end-stop and encoder scatter is
// well below a degree; a flip is 90 or 180)
constexpr double kFlipSpanDeg = 10.0;
constexpr double kEarthRateDps = 15.041067 / 3600.0;  // deg/s, sidereal

// a platform that flips turns every axis of its sensor: the Earth rate's share along each axis
// changes at every flip, a square wave in the channels the motion check does not flag (the hinge
// axis reads the flip itself). A FOG's bias instability is 1e-5 deg/s; this is up to 4e-3.
void add_flip_warnings(const Loaded& in, std::vector<std::string>& out) {
  for (int p = 0; p < 2; ++p) {
    if (!(in.platform_span_deg[p] > kFlipSpanDeg)) continue;
    const std::string prefix = fmt::format("gyro{}_", p + 1);
    std::string named;
    for (const auto& c : in.channels) {
      const bool of_sensor = c.name.rfind(prefix, 0) == 0 || c.name.rfind("corrected_" + prefix, 0) == 0;
      if (of_sensor) named += (named.empty() ? "" : ", ") + c.name;
    }
    if (named.empty()) continue;
    out.push_back(fmt::format(
        "platform {0} flips (plat{0}_deg spans {1:.0f} deg): every axis of sensor {0} turns with it, so the Earth rate "
        "along each ({2:.2g} deg/s in all) changes at every flip, a square wave that the B and K of {3} hold on top "
        "of the sensor's own (above a tactical gyro's B by 100x); for the sensor's noise analyse a record with the "
        "platforms held, or run 'driftless estimate --tune auto', which measures N and K from r = M1 y1 - M2 y2, "
        "where the Earth rate cancels",
        p + 1, in.platform_span_deg[p], kEarthRateDps, named));
  }
}

}  // namespace

std::vector<std::string> motion_warnings(const Loaded& in) {
  std::vector<std::string> out;
  add_flip_warnings(in, out);
  if (!(in.rate_hz > 0.0)) return out;
  std::vector<std::string> names;
  std::vector<BlockMeans> means;
  for (const auto& c : in.channels) {
    if (!watched_for_motion(c.name, c.quantity)) continue;
    names.push_back(c.name);
    means.emplace_back(in.rate_hz);
    means.back().push(c.x);
  }
  for (auto& w : motion_warnings(names, means, in.rate_hz)) out.push_back(std::move(w));
  return out;
}

bool watched_for_motion(const std::string& name, importers::Quantity q) {
  return q == importers::Quantity::kRate && name.rfind("corrected_", 0) != 0;
}

}  // namespace driftless::cli::allan
