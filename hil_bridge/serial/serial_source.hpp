// Samples from the box's microcontroller over a serial link (USB CDC or UART): sample frames
// (serial/frame.hpp, docs/hil.md) read through termios, checked by CRC and sequence number.
// Also the motor back end that drives the platforms over the same link (SerialMotors).
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <string>

#include "hil_bridge/clock.hpp"
#include "hil_bridge/motors.hpp"
#include "hil_bridge/raw_sample.hpp"
#include "hil_bridge/serial/frame.hpp"
#include "hil_bridge/serial/serial_port.hpp"
#include "hil_bridge/source.hpp"

namespace driftless::hil {

struct SerialSourceParams {
  std::string path;               // the tty, e.g. /dev/ttyACM0
  int baud = 921600;              // bit/s; 43-byte frames at 1 kHz need >= 460800
  double sample_rate_hz = 100.0;  // the microcontroller's sample rate, Hz
  double stop_deg = 90.0;         // platform angle at the end stops, deg
  double poll_timeout_s = 0.1;    // read() waits at most this long, s
  double stall_timeout_s = 1.0;   // no frame for this long is reported as a time-out, s
  void validate() const;
};

class SerialSource final : public SampleSource {
 public:
  SerialSource(Clock& clock, SerialSourceParams p);
  std::string name() const override { return "serial:" + p_.path; }
  double sample_rate_hz() const override { return p_.sample_rate_hz; }
  std::uint32_t fields() const override { return kFieldAccel | kFieldTemp; }

  Status configure() override;
  Status activate() override;
  ReadStatus read(Sample& out) override;
  Status reconnect() override;
  void deactivate() override;

  /// Sends a motor command frame (SerialMotors uses it). False when the link is down.
  bool send(const serial::MotorCommand& cmd);
  /// End-stop state from the latest frame.
  EndStop end_stop(int platform) const { return stops_[static_cast<std::size_t>(platform - 1)]; }
  std::uint64_t frames_ok() const { return frames_ok_; }
  std::uint64_t corrupt_frames() const { return decoder_.corrupt_frames(); }

 private:
  void process(const serial::SampleFrame& f);
  double t_last() const { return have_last_ ? t_last_s_ : kNaN; }

  Clock& clock_;
  SerialSourceParams p_;
  SerialPort port_;
  serial::Decoder decoder_;
  std::deque<Sample> ready_;
  bool active_ = false;
  bool gone_ = false;
  bool have_last_ = false;
  bool rebase_ = false;         // after a reconnect: time continues from the host clock
  std::uint16_t last_seq_ = 0;
  std::uint32_t last_t_us_ = 0;
  double t_last_s_ = 0.0;       // source time of the last sample, s
  double last_frame_host_s_ = 0.0;
  double lost_host_s_ = 0.0;    // host time when the link went down
  std::uint8_t last_status_ = 0;
  std::array<EndStop, 2> stops_{EndStop::kNone, EndStop::kNone};
  SaturationTracker saturation_;
  std::uint64_t frames_ok_ = 0;
};

/// The hardware motors: commands over the serial link, end stops from the sample frames.
/// The microcontroller drives a platform toward the commanded stop until its switch closes.
class SerialMotors final : public Motors {
 public:
  explicit SerialMotors(SerialSource& link) : link_(link) {}
  std::string name() const override { return "serial"; }
  Status command(int platform, int sign) override;
  EndStop end_stop(int platform) const override { return link_.end_stop(platform); }

 private:
  SerialSource& link_;
  serial::MotorCommand cmd_;
};

}  // namespace driftless::hil
