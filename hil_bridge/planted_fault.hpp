// A sensor fault planted into the emulated chips (emu-i2c, emu-serial) to check the live fault
// detection end to end: from a source time on, one gyro axis of one sensor sticks at its last
// value or gains a constant bias. docs/hil.md, "Fault detection".
#pragma once

#include <memory>
#include <string>

#include "hil_bridge/imu_generator.hpp"

namespace driftless::hil {

/// The `--emu-fault` spelling: `stuck:S:A@T` or `bias:S:A:DPS@T`.
struct PlantedFault {
  enum class Kind { kNone, kStuck, kBias };
  Kind kind = Kind::kNone;
  int sensor = 1;         // 1 or 2
  int axis = 0;           // 0 = x, 1 = y, 2 = z, in that sensor's axes
  double bias_dps = 0.0;  // kBias: added to the axis, deg/s
  double t_s = 0.0;       // onset, s of the emulator's (source) time
  bool planted() const { return kind != Kind::kNone; }
  /// "stuck on sensor 2 axis y from t=60 s" (for the terminal and the log's metadata).
  std::string describe() const;
};

/// Parses `stuck:S:A@T` or `bias:S:A:DPS@T` (S 1|2, A x|y|z, DPS deg/s, T s >= 0); throws
/// std::invalid_argument naming the part that is wrong and the expected form.
PlantedFault parse_planted_fault(const std::string& spec);

/// Wraps a generator: passes its readings through, with the fault applied from fault.t_s on
/// (a stuck axis repeats the last reading before the onset exactly, so the chip's ADC gives
/// bit-identical codes).
class FaultyGenerator final : public ImuGenerator {
 public:
  FaultyGenerator(std::unique_ptr<ImuGenerator> inner, PlantedFault fault);
  ImuReading sample(int sensor, double t_s) override;

 private:
  std::unique_ptr<ImuGenerator> inner_;
  PlantedFault fault_;
  double held_dps_ = 0.0;  // the stuck axis' value
  bool have_held_ = false;
};

}  // namespace driftless::hil
