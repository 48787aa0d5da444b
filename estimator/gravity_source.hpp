// What drives the self-calibration's g-sensitivity states (accel_check.hpp): the log's accel
// columns, gravity from ref_q (no accel columns), or nothing. Standard library only.
#pragma once

#include <cstdint>

namespace driftless::est {

enum class GravitySource : std::uint8_t { kAccel, kRefQ, kNone };
const char* to_string(GravitySource s);  // "accel", "ref_q", "none" (accel_check.cpp)

}  // namespace driftless::est
