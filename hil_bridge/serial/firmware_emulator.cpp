#include "hil_bridge/serial/firmware_emulator.hpp"

#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <vector>

#include "hil_bridge/clock.hpp"
#include "hil_bridge/serial/frame.hpp"

namespace driftless::hil {

using namespace mpu6050;

FirmwareEmulator::FirmwareEmulator(FirmwareParams p) : p_(std::move(p)) {}

FirmwareEmulator::~FirmwareEmulator() { stop(); }

std::string FirmwareEmulator::open_pty() {
  // raw from the start: a cooked line discipline would echo and translate the binary frames
  termios tio{};
  ::cfmakeraw(&tio);
  ::cfsetispeed(&tio, B921600);
  ::cfsetospeed(&tio, B921600);
  char name[256] = {};
  if (::openpty(&master_, &slave_, name, &tio, nullptr) != 0) {
    return std::string("emu-serial: openpty failed: ") + std::strerror(errno);
  }
  ::fcntl(master_, F_SETFL, ::fcntl(master_, F_GETFL) | O_NONBLOCK);
  ::fcntl(master_, F_SETFD, FD_CLOEXEC);
  ::fcntl(slave_, F_SETFD, FD_CLOEXEC);
  std::error_code ec;
  std::filesystem::remove(p_.link_path, ec);
  std::filesystem::create_symlink(name, p_.link_path, ec);
  if (ec) return "emu-serial: cannot create the link " + p_.link_path + ": " + ec.message();
  return {};
}

void FirmwareEmulator::close_pty() {
  std::error_code ec;
  std::filesystem::remove(p_.link_path, ec);
  if (slave_ >= 0) ::close(slave_);
  if (master_ >= 0) ::close(master_);
  slave_ = master_ = -1;
}

std::string FirmwareEmulator::start() {
  if (!(p_.rate_hz > 0.0)) return "emu-serial: rate_hz must be > 0 Hz";
  if (std::string err = open_pty(); !err.empty()) return err;
  thread_ = std::thread([this] { run(); });
  return {};
}

void FirmwareEmulator::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  close_pty();
}

void FirmwareEmulator::run() {
  // MCU time is exact (k / rate); the wall clock only paces it
  VirtualClock mcu;
  EmulatedMotors motors(mcu, p_.motors);
  BoxAtRestGenerator::Params gp = p_.generator;
  gp.sample_rate_hz = p_.rate_hz;
  const std::unique_ptr<ImuGenerator> gen =
      p_.make_generator ? p_.make_generator(&motors, p_.rate_hz) : std::make_unique<BoxAtRestGenerator>(gp, &motors);
  SteadyClock wall;
  const double wall0 = wall.now_s() + p_.start_delay_s;
  serial::Decoder commands;
  std::vector<std::uint8_t> out;
  bool overflow = false;
  bool hung_up = false;
  const FirmwareFaults& f = p_.faults;
  for (std::uint64_t k = 0; !stop_; ++k) {
    const double t = static_cast<double>(k) / p_.rate_hz;
    if (t >= p_.duration_s) break;
    if (p_.realtime) wall.sleep_until(wall0 + t);
    mcu.sleep_until(t);

    // hang-up and replug: the tty disappears, a new one takes its name
    const bool in_hangup = t >= f.hangup_from_s && t < f.hangup_to_s;
    if (in_hangup && !hung_up) {
      close_pty();
      hung_up = true;
    } else if (!in_hangup && hung_up) {
      if (!open_pty().empty()) break;
      hung_up = false;
    }
    // motor commands from the host
    if (master_ >= 0) {
      std::uint8_t buf[256];
      ssize_t n;
      while ((n = ::read(master_, buf, sizeof buf)) > 0) commands.feed(buf, static_cast<std::size_t>(n));
      serial::MotorCommand cmd;
      for (auto r = commands.next(nullptr, &cmd); r != serial::Decoder::Result::kNone; r = commands.next(nullptr, &cmd)) {
        if (r != serial::Decoder::Result::kMotor) continue;
        ++commands_;
        if (cmd.target1 != 0) motors.command(1, cmd.target1 > 0 ? 1 : -1);
        if (cmd.target2 != 0) motors.command(2, cmd.target2 > 0 ? 1 : -1);
      }
    }

    // sample both sensors as the MPU-6050 registers would hold them
    serial::SampleFrame fr;
    fr.seq = static_cast<std::uint16_t>(k);
    fr.t_us = p_.t0_us + static_cast<std::uint32_t>(std::llround(t * 1e6));
    fr.config = static_cast<std::uint8_t>((p_.gyro_fs_sel & 3) | (p_.accel_fs_sel & 3) << 2);
    for (int s = 0; s < 2; ++s) {
      const ImuReading r = gen->sample(s, t);
      RawRecord rec;
      for (int a = 0; a < 3; ++a) {
        const auto u = static_cast<std::size_t>(a);
        rec.gyro[u] = clip_round_i16(r.gyro_dps[a] * gyro_lsb_per_dps(p_.gyro_fs_sel));
        rec.accel[u] = clip_round_i16(r.accel_mps2[a] / kStandardGravityMps2 * accel_lsb_per_g(p_.accel_fs_sel));
      }
      rec.temp = temp_raw_from_c(r.temp_c);
      encode_record(rec, s == 0 ? fr.sensor1.data() : fr.sensor2.data());
    }
    if (t >= f.fail_sensor2_from_s && t < f.fail_sensor2_to_s) {
      fr.status |= serial::kStatusSensor2Failed;
      fr.sensor2.fill(0);
    }
    for (int pl = 1; pl <= 2; ++pl) {
      const EndStop st = motors.end_stop(pl);
      const std::uint8_t minus = pl == 1 ? serial::kStop1Minus : serial::kStop2Minus;
      const std::uint8_t plus = pl == 1 ? serial::kStop1Plus : serial::kStop2Plus;
      if (st == EndStop::kMinus) fr.end_stops |= minus;
      if (st == EndStop::kPlus) fr.end_stops |= plus;
      if (motors.rate_dps(pl, t) != 0.0) fr.end_stops |= pl == 1 ? serial::kMotor1Driving : serial::kMotor2Driving;
    }
    if (overflow) fr.status |= serial::kStatusMcuOverflow;
    ++made_;

    const bool paused = t >= f.pause_from_s && t < f.pause_to_s;
    if (hung_up || paused || f.drop_seq.count(fr.seq)) continue;
    out.clear();
    if (f.garbage_before_seq.count(fr.seq)) {
      static constexpr std::uint8_t kGarbage[5] = {0x00, 0xA5, 0x13, 0x37, 0xFF};
      for (std::uint8_t b : kGarbage) out.push_back(b);
    }
    const std::size_t start = out.size();
    serial::encode(fr, out);
    if (f.corrupt_seq.count(fr.seq)) out[start + 12] ^= 0x04;  // one bit in sensor 1's data
    const ssize_t w = ::write(master_, out.data(), out.size());
    if (w == static_cast<ssize_t>(out.size())) {
      ++sent_;
      overflow = false;
    } else {
      overflow = true;  // the host is not reading: this frame is lost, the next one says so
    }
  }
  finished_ = true;
  // keep the pty open until stop(): the host may still be reading the last frames
  while (!stop_) std::this_thread::sleep_for(std::chrono::milliseconds(5));
}

}  // namespace driftless::hil
