#include "hil_bridge/serial/serial_source.hpp"

#include <cmath>
#include <stdexcept>

namespace driftless::hil {

void SerialSourceParams::validate() const {
  if (path.empty()) throw std::invalid_argument("serial: no tty path given (e.g. serial:/dev/ttyACM0)");
  if (baud_constant(baud) == 0) throw std::invalid_argument("serial: " + std::to_string(baud) + " bit/s is not a standard baud rate");
  if (!(sample_rate_hz > 0.0)) throw std::invalid_argument("serial: sample_rate_hz must be > 0 Hz");
  // 10 bits per byte on the wire (8N1)
  if (sample_rate_hz * serial::kSampleFrameBytes * 10.0 > baud) {
    throw std::invalid_argument("serial: " + std::to_string(baud) + " bit/s cannot carry " +
                                std::to_string(sample_rate_hz) + " frames/s of " +
                                std::to_string(serial::kSampleFrameBytes) + " bytes (needs " +
                                std::to_string(sample_rate_hz * serial::kSampleFrameBytes * 10.0) + " bit/s)");
  }
  if (!(poll_timeout_s > 0.0 && stall_timeout_s > 0.0)) throw std::invalid_argument("serial: time-outs must be > 0 s");
}

SerialSource::SerialSource(Clock& clock, SerialSourceParams p) : clock_(clock), p_(std::move(p)) {}

Status SerialSource::configure() {
  try {
    p_.validate();
  } catch (const std::invalid_argument& e) {
    return Status::BadConfig(e.what());
  }
  if (std::string err = port_.open(p_.path, p_.baud); !err.empty()) return Status::NotFound(err);
  return Status::Ok();
}

Status SerialSource::activate() {
  if (!port_.is_open()) {
    if (std::string err = port_.open(p_.path, p_.baud); !err.empty()) return Status::NotFound(err);
  }
  decoder_.reset();
  ready_.clear();
  have_last_ = false;
  rebase_ = false;
  gone_ = false;
  active_ = true;
  last_frame_host_s_ = clock_.now_s();
  return Status::Ok();
}

void SerialSource::deactivate() {
  active_ = false;
  port_.close();
}

bool SerialSource::send(const serial::MotorCommand& cmd) {
  std::vector<std::uint8_t> bytes;
  serial::encode(cmd, bytes);
  return port_.write(bytes.data(), bytes.size(), 0.05) == SerialPort::Io::kOk;
}

void SerialSource::process(const serial::SampleFrame& f) {
  const double period = 1.0 / p_.sample_rate_hz;
  double t;
  if (!have_last_) {
    t = 0.0;
  } else if (rebase_) {
    // the link was down: the microcontroller may have restarted, so its clock and sequence say
    // nothing; the host clock places the first frame after the gap
    const double away = clock_.now_s() - lost_host_s_;
    const double steps = std::max(1.0, std::round(away / period));
    t = t_last_s_ + steps * period;
    const auto lost = static_cast<std::uint64_t>(steps - 1.0);
    report(EventKind::kGap, t_last_s_,
           "link was down for " + std::to_string(away) + " s: about " + std::to_string(lost) + " samples lost", lost);
  } else {
    const auto gap = static_cast<std::uint16_t>(f.seq - last_seq_ - 1);
    const std::uint32_t dt_us = f.t_us - last_t_us_;  // unsigned: unwraps the 32-bit counter
    if (gap > 0 && gap < 0x8000) {
      report(EventKind::kSequenceGap, t_last_s_,
             "sequence " + std::to_string(last_seq_) + " -> " + std::to_string(f.seq) + ": " +
                 std::to_string(gap) + " frames missing",
             gap);
    } else if (gap != 0) {
      // a sequence number from the past: a duplicate or a restarted microcontroller
      report(EventKind::kCorruptFrame, t_last_s_,
             "sequence went back from " + std::to_string(last_seq_) + " to " + std::to_string(f.seq) + ": frame dropped");
      return;
    }
    if (dt_us == 0 || dt_us > 10'000'000u) {
      // a clock that stands still or jumps > 10 s: trust the sequence number instead
      t = t_last_s_ + (gap + 1.0) * period;
      report(EventKind::kInfo, t_last_s_, "microcontroller clock jumped by " + std::to_string(dt_us) + " us: time from sequence numbers");
    } else {
      t = t_last_s_ + dt_us * 1e-6;
    }
  }
  rebase_ = false;
  have_last_ = true;
  last_seq_ = f.seq;
  last_t_us_ = f.t_us;
  t_last_s_ = t;
  last_frame_host_s_ = clock_.now_s();
  ++frames_ok_;

  Sample s;
  s.t_s = t;
  const int fs = f.config & 3, afs = (f.config >> 2) & 3;
  const std::array<const std::uint8_t*, 2> regs{f.sensor1.data(), f.sensor2.data()};
  for (int k = 0; k < 2; ++k) {
    const int mask = fill_from_raw(k, mpu6050::decode_record(regs[static_cast<std::size_t>(k)]), fs, afs, s);
    if (std::string msg = saturation_.update(k, mask, fs); !msg.empty()) report(EventKind::kSaturation, t, msg);
    const std::uint8_t failed = k == 0 ? serial::kStatusSensor1Failed : serial::kStatusSensor2Failed;
    if (f.status & failed) {
      // the microcontroller could not read this sensor: no data, not zeros
      (k == 0 ? s.gyro1_dps : s.gyro2_dps).setConstant(kNaN);
      (k == 0 ? s.accel1_mps2 : s.accel2_mps2).setConstant(kNaN);
      (k == 0 ? s.temp1_c : s.temp2_c) = kNaN;
    }
    if ((f.status & failed) != (last_status_ & failed)) {
      report(EventKind::kBusError, t,
             "microcontroller: sensor " + std::to_string(k + 1) +
                 ((f.status & failed) ? " read failed (I2C NACK/EIO on the box): written empty" : " reads again"));
    }
  }
  if ((f.status & serial::kStatusMcuOverflow) && !(last_status_ & serial::kStatusMcuOverflow)) {
    report(EventKind::kInfo, t, "microcontroller: its send buffer overflowed (the host read too slowly)");
  }
  last_status_ = f.status;
  auto stop = [](std::uint8_t b, std::uint8_t minus, std::uint8_t plus) {
    const bool m = b & minus, p = b & plus;
    return m == p ? EndStop::kNone : (p ? EndStop::kPlus : EndStop::kMinus);
  };
  stops_[0] = stop(f.end_stops, serial::kStop1Minus, serial::kStop1Plus);
  stops_[1] = stop(f.end_stops, serial::kStop2Minus, serial::kStop2Plus);
  s.plat1_deg = known_angle_deg(stops_[0], p_.stop_deg);
  s.plat2_deg = known_angle_deg(stops_[1], p_.stop_deg);
  ready_.push_back(s);
}

ReadStatus SerialSource::read(Sample& out) {
  auto pop = [&] {
    out = ready_.front();
    ready_.pop_front();
    return ReadStatus::kSample;
  };
  if (!ready_.empty()) return pop();
  if (!active_) return ReadStatus::kEnd;
  if (gone_) return ReadStatus::kDisconnected;
  const double deadline = clock_.now_s() + p_.poll_timeout_s;
  std::uint8_t buf[4096];
  bool fault = false;
  for (;;) {
    std::size_t n = 0;
    const double wait = std::max(0.0, deadline - clock_.now_s());
    const SerialPort::Io io = port_.read(buf, sizeof buf, wait, n);
    if (io == SerialPort::Io::kHangup) {
      gone_ = true;
      // frames still buffered in the tty die with it: the gap starts at the last frame received
      lost_host_s_ = have_last_ ? last_frame_host_s_ : clock_.now_s();
      port_.close();
      report(EventKind::kDisconnected, t_last(), p_.path + " hung up (device unplugged or reset)");
      return ReadStatus::kDisconnected;
    }
    if (n > 0) decoder_.feed(buf, n);
    serial::SampleFrame f;
    for (;;) {
      const auto r = decoder_.next(&f, nullptr);
      if (r == serial::Decoder::Result::kNone) break;
      if (r == serial::Decoder::Result::kCorrupt) {
        fault = true;
        report(EventKind::kCorruptFrame, t_last(), "corrupt frame (CRC or header): dropped");
      } else if (r == serial::Decoder::Result::kSample) {
        process(f);
      }
    }
    if (!ready_.empty()) return pop();
    if (fault) return ReadStatus::kFault;
    if (clock_.now_s() >= deadline) {
      const double now = clock_.now_s();
      if (now - last_frame_host_s_ >= p_.stall_timeout_s) {
        report(EventKind::kTimeout, t_last(), "no frame from " + p_.path + " for " + std::to_string(now - last_frame_host_s_) + " s");
        last_frame_host_s_ = now;
      }
      return ReadStatus::kPending;
    }
  }
}

Status SerialSource::reconnect() {
  if (std::string err = port_.open(p_.path, p_.baud); !err.empty()) return Status::DeviceError(err);
  decoder_.reset();
  gone_ = false;
  rebase_ = have_last_;
  last_frame_host_s_ = clock_.now_s();
  report(EventKind::kReconnected, t_last(), p_.path + " is back");
  return Status::Ok();
}

Status SerialMotors::command(int platform, int sign) {
  if (platform < 1 || platform > 2 || (sign != -1 && sign != 1)) {
    return Status::BadConfig("motors: platform must be 1 or 2 and sign -1 or +1");
  }
  (platform == 1 ? cmd_.target1 : cmd_.target2) = static_cast<std::int8_t>(sign);
  ++cmd_.seq;
  if (!link_.send(cmd_)) return Status::DeviceError("motors: the serial link is down; command not sent");
  return Status::Ok();
}

}  // namespace driftless::hil
