// The box's microcontroller, emulated: samples two sensors (a BoxAtRestGenerator, or any
// ImuGenerator such as the twin's sensor model, quantised as an MPU-6050 would), drives the platform motors on command (EmulatedMotors) and streams sample
// frames into a pseudo-terminal at the sample rate, from its own thread. The host opens the tty
// at `link_path` (a symlink to the pty), exactly as it would open /dev/ttyACM0.
// Faults for tests: corrupt and dropped frames, stray bytes, a pause, a hang-up and replug.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>

#include "hil_bridge/imu_generator.hpp"
#include "hil_bridge/motors.hpp"

namespace driftless::hil {

struct FirmwareFaults {
  std::set<std::uint16_t> corrupt_seq;       // these frames go out with a flipped payload bit
  std::set<std::uint16_t> drop_seq;          // these frames are never sent (a sequence gap)
  std::set<std::uint16_t> garbage_before_seq;  // stray bytes precede these frames
  double pause_from_s = -1.0, pause_to_s = -1.0;    // no frames in [from, to) (MCU time, s)
  double hangup_from_s = -1.0, hangup_to_s = -1.0;  // the tty vanishes in [from, to), then a new one
  double fail_sensor2_from_s = -1.0, fail_sensor2_to_s = -1.0;  // sensor 2 reads fail (status bit)
};

struct FirmwareParams {
  std::string link_path;          // symlink the emulator creates to its pty
  double rate_hz = 100.0;         // frames per second
  double duration_s = 1e9;        // stop sending after this much MCU time, s
  int gyro_fs_sel = 0;
  int accel_fs_sel = 0;
  std::uint32_t t0_us = 0;        // MCU clock at the first frame, us (tests wrap-around)
  double start_delay_s = 0.05;    // wall time before the first frame (the host opens the tty), s
  bool realtime = true;           // pace frames by the wall clock; false: as fast as the pty takes them
  BoxAtRestGenerator::Params generator;
  /// What the sensors measure, built in the emulator's thread from its motors; empty: a
  /// BoxAtRestGenerator from `generator` (e.g. the twin's sensor model: hil::SensorModelGenerator)
  std::function<std::unique_ptr<ImuGenerator>(const EmulatedMotors* motors, double rate_hz)> make_generator;
  EmulatedMotors::Params motors;
  FirmwareFaults faults;
};

class FirmwareEmulator {
 public:
  explicit FirmwareEmulator(FirmwareParams p);
  ~FirmwareEmulator();
  FirmwareEmulator(const FirmwareEmulator&) = delete;
  FirmwareEmulator& operator=(const FirmwareEmulator&) = delete;

  /// Opens the pty, makes the link and starts the thread. Returns "" or an error message.
  std::string start();
  /// Stops the thread and removes the link (also done by the destructor).
  void stop();
  const std::string& tty_path() const { return p_.link_path; }

  std::uint64_t frames_sent() const { return sent_.load(); }
  std::uint64_t frames_made() const { return made_.load(); }
  std::uint64_t commands_received() const { return commands_.load(); }
  bool finished() const { return finished_.load(); }

 private:
  std::string open_pty();
  void close_pty();
  void run();

  FirmwareParams p_;
  int master_ = -1, slave_ = -1;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> finished_{false};
  std::atomic<std::uint64_t> sent_{0}, made_{0}, commands_{0};
};

}  // namespace driftless::hil
