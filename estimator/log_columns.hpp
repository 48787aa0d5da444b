// The column table of the log format (docs/log-format.md, "Columns"): one list drives the reader,
// the writer and column_names(). Internal to the log reader and writer.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

#include "estimator/sample.hpp"

namespace driftless::log::detail {

// name, the optional group it belongs to (0 = required), decimals written, the sensor it belongs
// to (0 = the box; sensor-2 columns are absent from the single-sensor form), and whether it is a
// gyro reading (checked against the full scale)
struct ColumnSpec {
  std::string_view name;
  std::uint32_t field;
  int decimals;
  int sensor;
  bool gyro;
};

inline constexpr std::array<ColumnSpec, 35> kColumns = {{
    {"t", 0, 6, 0, false},
    {"gyro1_x", 0, 7, 1, true}, {"gyro1_y", 0, 7, 1, true}, {"gyro1_z", 0, 7, 1, true},
    {"gyro2_x", 0, 7, 2, true}, {"gyro2_y", 0, 7, 2, true}, {"gyro2_z", 0, 7, 2, true},
    {"plat1_deg", 0, 6, 1, false}, {"plat2_deg", 0, 6, 2, false},
    {"ref_qw", kFieldRefQ, 10, 0, false}, {"ref_qx", kFieldRefQ, 10, 0, false},
    {"ref_qy", kFieldRefQ, 10, 0, false}, {"ref_qz", kFieldRefQ, 10, 0, false},
    {"ref_px", kFieldRefP, 4, 0, false}, {"ref_py", kFieldRefP, 4, 0, false}, {"ref_pz", kFieldRefP, 4, 0, false},
    {"accel1_x", kFieldAccel, 5, 1, false}, {"accel1_y", kFieldAccel, 5, 1, false},
    {"accel1_z", kFieldAccel, 5, 1, false}, {"accel2_x", kFieldAccel, 5, 2, false},
    {"accel2_y", kFieldAccel, 5, 2, false}, {"accel2_z", kFieldAccel, 5, 2, false},
    {"temp1", kFieldTemp, 3, 1, false}, {"temp2", kFieldTemp, 3, 2, false},
    {"true_bias1_x", kFieldTrueBias, 9, 1, false}, {"true_bias1_y", kFieldTrueBias, 9, 1, false},
    {"true_bias1_z", kFieldTrueBias, 9, 1, false}, {"true_bias2_x", kFieldTrueBias, 9, 2, false},
    {"true_bias2_y", kFieldTrueBias, 9, 2, false}, {"true_bias2_z", kFieldTrueBias, 9, 2, false},
    {"true_rate_x", kFieldTrueRate, 9, 0, false}, {"true_rate_y", kFieldTrueRate, 9, 0, false},
    {"true_rate_z", kFieldTrueRate, 9, 0, false},
    {"true_plat1_deg", kFieldTruePlat, 6, 1, false}, {"true_plat2_deg", kFieldTruePlat, 6, 2, false},
}};

inline constexpr std::uint32_t kAllFields = kFieldAccel | kFieldTemp | kFieldRefQ | kFieldRefP |
                                            kFieldTrueBias | kFieldTrueRate | kFieldTruePlat;
static_assert(kAllFields == 0x7f, "a new column group needs its bit in kAllFields");
inline constexpr std::size_t kPlat1Column = 7;

/// Column i is part of a log with these fields (layout bit included).
constexpr bool column_in_layout(std::size_t i, std::uint32_t fields) {
  const ColumnSpec& c = kColumns[i];
  if ((fields & kLayoutSingleSensor) != 0 && c.sensor == 2) return false;
  return c.field == 0 || (fields & c.field) != 0;
}

/// Column i must be in the header of a log of this layout (plat1_deg is optional in the
/// single-sensor form: a sensor fixed to the box, read as 0 deg).
constexpr bool column_required(std::size_t i, bool single_sensor) {
  const ColumnSpec& c = kColumns[i];
  if (c.field != 0) return false;
  if (single_sensor) return c.sensor != 2 && i != kPlat1Column;
  return true;
}

/// Where column i's value lives inside a Sample.
double& column_slot(Sample& s, std::size_t i);

}  // namespace driftless::log::detail
