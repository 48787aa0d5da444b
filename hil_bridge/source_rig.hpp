// Builds a source from its command-line spelling, with everything it needs (clock, bus,
// emulators, motors, flip schedule):
//   twin | replay:FILE | i2c:/dev/i2c-N | serial:/dev/ttyX | emu-i2c | emu-serial
// emu-i2c and emu-serial run the I2C driver / serial source against the emulators (no hardware).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "estimator/log.hpp"
#include "hil_bridge/clock.hpp"
#include "hil_bridge/imu_generator.hpp"
#include "hil_bridge/planted_fault.hpp"
#include "hil_bridge/motors.hpp"
#include "hil_bridge/source.hpp"

namespace driftless::hil {

struct RigOptions {
  bool realtime = false;         // pace by the wall clock (hardware sources always are)
  double sample_rate_hz = 100.0; // i2c, serial and the emulators, Hz
  double standstill_s = 10.0;    // flip schedule hold time (emulated and serial motors), s
  int baud = 921600;             // serial, bit/s
  std::string work_dir = ".";    // emu-serial puts its tty link here
  std::string scenario;          // twin: scenario YAML (empty: the built-in default)
  bool twin_bridge_flips = false;  // twin: the bridge's flip schedule (standstill_s) commands the
                                   // twin's servos instead of the scenario's flip_schedule
  std::uint64_t seed = 1;        // emulators and the twin
  BoxAtRestGenerator::Params emulated_box;  // what emu-i2c / emu-serial measure
  std::string emu_sensor;        // emu-i2c, emu-serial: a twin sensor-model preset ("mpu6050", "ideal")
                                 // instead of the built-in bias + white-noise generator
  PlantedFault emu_fault;        // emu-i2c, emu-serial: a sensor fault planted into the chips' readings
};

/// A ready-to-configure source and its helpers. Owns everything it points to.
class SourceRig {
 public:
  virtual ~SourceRig() = default;
  std::string spec;
  SampleSource* source = nullptr;
  Motors* motors = nullptr;          // null: the source drives its platforms itself (twin) or has none
  FlipSchedule* schedule = nullptr;  // drives `motors`
  Clock* clock = nullptr;            // the clock the source runs on
  /// Starts helpers (emulator threads) before configure(); "" or an error message.
  virtual std::string start() { return {}; }
};

/// Parses `spec` and builds the rig (throws std::invalid_argument on an unknown spelling).
std::unique_ptr<SourceRig> make_source_rig(const std::string& spec, const RigOptions& opt);

/// The spellings make_source_rig understands, for help texts.
const char* source_spec_help();

}  // namespace driftless::hil
