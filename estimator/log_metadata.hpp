// The one writer of a log's standard metadata (docs/log-format.md): whatever produces a log (the
// twin, the fast closed-form box, the calibration rig, a HIL source) fills a typed LogInfo and
// write_log_info() turns it into '# key: value' text, numbers in their shortest exact form (a
// hinge axis keeps every digit; std::to_string kept six decimals).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "estimator/log.hpp"
#include "estimator/sample.hpp"

namespace driftless::log {

/// The standard keys, typed. Empty text, NaN and nullopt are left out.
struct LogInfo {
  double sample_rate_hz = kNaN;                 // Hz
  double latitude_deg = kNaN;                   // deg, north positive
  std::optional<Eigen::Vector3d> hinge1_axis;   // platform 1 hinge, box axes
  std::optional<Eigen::Vector3d> hinge2_axis;   // platform 2 hinge, box axes
  std::string source;                           // "twin", a device, a generator
  std::string scenario;                         // scenario name
  std::optional<std::uint64_t> seed;
  double duration_s = kNaN;                     // s, planned length of the run
  std::string motion;                           // motion type
  std::string carrier;                          // what carries the box in renders
  std::string platform_readback;                // end_stops | encoder
  double flip_angle_deg = kNaN;                 // deg, platform rest angles +-this
  double standstill_s = kNaN;                   // s, rest between flips
  std::string flip_control;                     // who commands the flips when not the schedule
  double end_stop_deg = kNaN;                   // deg
  std::string sensor1_preset;
  std::string sensor2_preset;
};

/// Sets every given field of `info` in `meta` (existing keys keep their place), in the order above.
void write_log_info(Metadata& meta, const LogInfo& info);

/// A number as exact text (shortest round trip).
void set_number(Metadata& meta, const std::string& key, double value);
/// A 3-vector as "x y z", each exact.
void set_vector3(Metadata& meta, const std::string& key, const Eigen::Vector3d& v);
/// "x y z" of a 3-vector, each number exact.
std::string vector3_text(const Eigen::Vector3d& v);

}  // namespace driftless::log
