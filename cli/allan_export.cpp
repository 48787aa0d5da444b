// Noise files for visual-inertial tools from the fits: Kalibr imu.yaml (aggregated and per axis),
// OpenVINS kalibr_imu_chain.yaml, the VINS-Mono IMU block. SI units, the unit beside each value,
// the inflation factor stated (docs/allan.md, exports).
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/core.h>

#include "cli/allan_result.hpp"
#include "estimator/sample.hpp"
#include "estimator/output_file.hpp"

namespace driftless::cli::allan {
namespace {

// one exported value: the fit's value or, when not identifiable, its 95 % upper bound
struct Value {
  double v = std::nan("");
  std::string how;  // "" (measured) or why it is a bound
  std::string from;  // the channel it came from
};

Value pick(const est::NoiseParameter& p, double scale, const std::string& ch) {
  if (p.valid) return {p.value * scale, "", ch};
  if (std::isfinite(p.upper_95)) return {p.upper_95 * scale, "95 % upper bound (not identifiable from this record)", ch};
  return {};
}

// the worst (largest) over channels of one quantity, or one channel's
Value worst(const Result& r, importers::Quantity q, bool noise, int axis) {
  Value best;
  for (const auto& c : r.channels) {
    if (c.quantity != q || (axis >= 0 && c.axis != axis)) continue;
    const double scale = q == importers::Quantity::kRate ? driftless::kRadPerDeg : 1.0;
    const Value v = pick(noise ? c.fit.N : c.fit.K, scale, c.name);
    if (std::isfinite(v.v) && (!std::isfinite(best.v) || v.v > best.v)) best = v;
    if (axis >= 0 && std::isfinite(best.v)) break;
  }
  return best;
}

struct Noise {
  Value gn, gw, an, aw;  // gyro density, gyro walk, accel density, accel walk
};

Noise noise_of(const Result& r, int axis, double inflate) {
  Noise n{worst(r, importers::Quantity::kRate, true, axis), worst(r, importers::Quantity::kRate, false, axis),
          worst(r, importers::Quantity::kAccel, true, axis), worst(r, importers::Quantity::kAccel, false, axis)};
  for (Value* v : {&n.gn, &n.gw, &n.an, &n.aw}) v->v *= inflate;
  return n;
}

std::string line(const char* key, const Value& v, const char* unit, const char* what, int width = 30) {
  if (!std::isfinite(v.v)) return fmt::format("# {}: not measured ({} channels absent)\n", key, what);
  std::string s = fmt::format("{:<{}} # {}", fmt::format("{}: {:.6e}", key, v.v), width, unit);
  s += v.from.empty() ? "" : " (" + v.from + ")";
  if (!v.how.empty()) s += "; " + v.how;
  return s + "\n";
}

std::string head(const Result& r, const ExportOptions& o, const std::string& scope) {
  return fmt::format(
      "# IMU noise from driftless allan on {} ({})\n# {}; continuous-time densities, SI units beside each value\n"
      "# inflation factor {:g} applied to every density and random walk (--inflate; 1 = as measured)\n",
      r.source, r.format, scope, o.inflate);
}

std::string kalibr_body(const Result& r, const Noise& n, const ExportOptions& o, const char* indent) {
  std::string s;
  s += indent + line("accelerometer_noise_density", n.an, "m/s^2/sqrt(Hz)", "accelerometer");
  s += indent + line("accelerometer_random_walk", n.aw, "m/s^3/sqrt(Hz)", "accelerometer");
  s += indent + line("gyroscope_noise_density", n.gn, "rad/s/sqrt(Hz)", "gyro");
  s += indent + line("gyroscope_random_walk", n.gw, "rad/s^2/sqrt(Hz)", "gyro");
  s += fmt::format("{}rostopic: {}\n{}update_rate: {:.6g}  # Hz\n", indent, o.topic, indent, r.rate_hz);
  return s;
}

void write(const std::filesystem::path& p, const std::string& s, std::vector<std::filesystem::path>& written) {
  io::write_file(p, s);
  written.push_back(p);
}

std::string vins_line(const char* key, const Value& v, const char* unit) {
  if (!std::isfinite(v.v)) return fmt::format("# {}: not measured\n", key);
  return fmt::format("{:<24} # {}{}\n", fmt::format("{}: {:.6e}", key, v.v), unit, v.how.empty() ? "" : "; " + v.how);
}

}  // namespace

std::vector<std::filesystem::path> write_exports(const std::filesystem::path& dir, const Result& r, const ExportOptions& o) {
  std::vector<std::filesystem::path> written;
  const Noise all = noise_of(r, -1, o.inflate);
  if (o.kalibr) {
    write(dir / "imu.yaml", head(r, o, "aggregated: the largest (worst) axis of each sensor") + kalibr_body(r, all, o, ""), written);
    for (int axis = 0; axis < 3; ++axis) {
      const Noise n = noise_of(r, axis, o.inflate);
      if (!std::isfinite(n.gn.v) && !std::isfinite(n.an.v)) continue;
      const std::string name = std::string("imu_") + "xyz"[axis] + ".yaml";
      write(dir / name, head(r, o, std::string("axis ") + "xyz"[axis] + " only") + kalibr_body(r, n, o, ""), written);
    }
  }
  if (o.openvins) {
    std::string s = "%YAML:1.0\n" + head(r, o, "OpenVINS kalibr_imu_chain.yaml, aggregated: the worst axis") + "imu0:\n";
    s += "  T_i_b:\n    - [1.0, 0.0, 0.0, 0.0]\n    - [0.0, 1.0, 0.0, 0.0]\n    - [0.0, 0.0, 1.0, 0.0]\n    - [0.0, 0.0, 0.0, 1.0]\n";
    s += kalibr_body(r, all, o, "  ");
    s += "  model: calibrated\n  time_offset: 0.0  # s\n";
    write(dir / "kalibr_imu_chain.yaml", s, written);
  }
  if (o.vins_mono) {
    std::string s = "%YAML:1.0\n" + head(r, o, "VINS-Mono IMU block, aggregated: the worst axis");
    s += "# copy into the VINS-Mono config: acc_n/gyr_n white-noise densities, acc_w/gyr_w bias random walks\n";
    s += vins_line("acc_n", all.an, "m/s^2/sqrt(Hz)") + vins_line("gyr_n", all.gn, "rad/s/sqrt(Hz)");
    s += vins_line("acc_w", all.aw, "m/s^3/sqrt(Hz)") + vins_line("gyr_w", all.gw, "rad/s^2/sqrt(Hz)");
    s += "g_norm: 9.80665          # m/s^2, standard gravity: put your local value\n";
    write(dir / "vins_mono_imu.yaml", s, written);
  }
  return written;
}

}  // namespace driftless::cli::allan
