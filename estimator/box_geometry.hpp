// The box the filter runs on, as typed values: hinge axes, sample rate, latitude and the end-stop
// (flip) angle. The filter is built from this struct; a log's text metadata is turned into it at
// the edge (box_geometry_from_metadata), never parsed inside the filter. docs/estimator.md.
#pragma once

#include <Eigen/Core>

#include "estimator/sample.hpp"

namespace driftless::log {
class Metadata;
}

namespace driftless::est {

/// Fixed geometry of a dual-gyro box (paper section 2, Fig. 2).
struct BoxGeometry {
  Eigen::Vector3d hinge1_axis = Eigen::Vector3d::UnitZ();  // platform 1's hinge, box axes (unit)
  Eigen::Vector3d hinge2_axis = Eigen::Vector3d::UnitX();  // platform 2's hinge, box axes (unit)
  double sample_rate_hz = kNaN;  // Hz, nominal output rate; NaN = unknown (taken from time stamps)
  double latitude_deg = kNaN;    // deg, for the Earth rate; NaN = unknown
  double flip_angle_deg = 90.0;  // deg, the platforms rest at +-this (paper: +-90)
  /// Throws std::invalid_argument naming the field on a bad value; normalises the hinge axes.
  void validate();
};

/// eq. (5)'s position sequence (+,+) -> (+,-) -> (-,-) -> (-,+): the angle (deg) of `sensor`
/// (1 or 2) at step `pattern` (any integer, taken mod 4) for platforms resting at +-flip_angle_deg.
double eq5_position_deg(int pattern, int sensor, double flip_angle_deg);
/// The step (0..3) of eq. (5)'s sequence whose signs match the two angles (>= 0 counts as +).
int eq5_pattern_of(double plat1_deg, double plat2_deg);

/// The geometry a log's metadata describes: hinge1_axis / hinge2_axis (default z / x),
/// sample_rate_hz, latitude_deg, flip_angle_deg (else end_stop_deg, else 90). Throws
/// log::LogError naming the key on a malformed value, std::invalid_argument on a bad geometry.
BoxGeometry box_geometry_from_metadata(const log::Metadata& meta);

}  // namespace driftless::est
