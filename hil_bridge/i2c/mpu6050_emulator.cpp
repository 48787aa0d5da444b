#include "hil_bridge/i2c/mpu6050_emulator.hpp"

#include <array>
#include <cmath>

namespace driftless::hil {

using namespace mpu6050;

namespace {
// more samples than this in one catch-up cannot all matter: the FIFO holds 73 records
constexpr std::uint64_t kMaxCatchUp = 200;
}  // namespace

Mpu6050Emulator::Mpu6050Emulator(int sensor, ImuGenerator& generator, const Clock& clock)
    : sensor_(sensor), gen_(generator), clock_(clock) {
  power_on_reset();
}

void Mpu6050Emulator::power_on_reset() {
  regs_.fill(0);
  regs_[kPwrMgmt1] = kPwrMgmt1Reset;
  regs_[kWhoAmI] = kWhoAmIValue;
  fifo_.clear();
  ptr_ = 0;
  reanchor();
}

double Mpu6050Emulator::sample_rate_hz() const {
  return mpu6050::sample_rate_hz(regs_[kConfig] & 7, regs_[kSmplrtDiv]);
}

double Mpu6050Emulator::gyro_delay_s() const { return gyro_dlpf_delay_s(regs_[kConfig] & 7); }

void Mpu6050Emulator::reanchor() {
  t_anchor_s_ = clock_.now_s();
  k_anchor_ = samples_;
}

void Mpu6050Emulator::advance() {
  if (!awake()) return;
  const double now = clock_.now_s();
  const double rate = sample_rate_hz();
  // how many ticks are due by now
  const double due = std::floor((now - t_anchor_s_) * rate + 1e-9);
  if (due < 1.0) return;
  std::uint64_t target = k_anchor_ + static_cast<std::uint64_t>(due);
  if (target <= samples_) return;
  if (target - samples_ > kMaxCatchUp) {
    // the host was away for long: the skipped samples overflow the FIFO in any case
    const std::uint64_t skip = target - samples_ - kMaxCatchUp;
    const bool fifo_on = (regs_[kUserCtrl] & kUserFifoEn) != 0 && regs_[kFifoEn] != 0;
    if (fifo_on) {
      overflow_lost_ += skip * kRecordBytes;
      regs_[kIntStatus] |= kIntFifoOflow;
    }
    samples_ += skip;
  }
  while (samples_ < target) {
    produce(t_anchor_s_ + static_cast<double>(samples_ + 1 - k_anchor_) / rate);
  }
}

void Mpu6050Emulator::produce(double t_tick_s) {
  ++samples_;
  // the DLPF delays the signal: the sample at t shows the input at t - delay
  last_ = gen_.sample(sensor_, t_tick_s - gyro_delay_s());
  const int fs = (regs_[kGyroConfig] >> 3) & 3;
  const int afs = (regs_[kAccelConfig] >> 3) & 3;
  RawRecord rec;
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    rec.gyro[i] = clip_round_i16(last_.gyro_dps[a] * gyro_lsb_per_dps(fs));
    rec.accel[i] = clip_round_i16(last_.accel_mps2[a] / kStandardGravityMps2 * accel_lsb_per_g(afs));
  }
  rec.temp = temp_raw_from_c(last_.temp_c);
  std::array<std::uint8_t, kRecordBytes> bytes{};
  encode_record(rec, bytes.data());
  for (int i = 0; i < kRecordBytes; ++i) regs_[static_cast<std::size_t>(kAccelXoutH + i)] = bytes[static_cast<std::size_t>(i)];
  regs_[kIntStatus] |= kIntDataRdy;

  // FIFO: the enabled registers in register order (accel, temp, gyro x, y, z)
  if ((regs_[kUserCtrl] & kUserFifoEn) == 0) return;
  const std::uint8_t en = regs_[kFifoEn];
  auto push = [&](int first, int n) {
    for (int i = 0; i < n; ++i) {
      if (fifo_.size() >= static_cast<std::size_t>(kFifoSizeBytes)) {
        // full: the oldest byte is lost and the overflow interrupt is raised
        fifo_.pop_front();
        ++overflow_lost_;
        regs_[kIntStatus] |= kIntFifoOflow;
      }
      fifo_.push_back(bytes[static_cast<std::size_t>(first + i)]);
    }
  };
  if (en & 0x08) push(0, 6);   // ACCEL_FIFO_EN
  if (en & 0x80) push(6, 2);   // TEMP_FIFO_EN
  if (en & 0x40) push(8, 2);   // XG_FIFO_EN
  if (en & 0x20) push(10, 2);  // YG_FIFO_EN
  if (en & 0x10) push(12, 2);  // ZG_FIFO_EN
}

void Mpu6050Emulator::write_reg(std::uint8_t r, std::uint8_t v) {
  switch (r) {
    case kWhoAmI:
    case kIntStatus:
    case kFifoCountH:
    case kFifoCountH + 1:
      return;  // read-only
    case kPwrMgmt1: {
      if (v & kPwrDeviceReset) {
        power_on_reset();
        return;
      }
      const bool was_awake = awake();
      regs_[r] = v;
      if (!was_awake && awake()) reanchor();
      return;
    }
    case kUserCtrl:
      if (v & kUserFifoReset) fifo_.clear();
      regs_[r] = v & static_cast<std::uint8_t>(~kUserFifoReset);  // reset bits clear themselves
      return;
    case kFifoRw:
      return;  // host writes to the FIFO are not used
    case kSmplrtDiv:
    case kConfig:
      regs_[r] = v;
      reanchor();  // the sample clock restarts at the new rate
      return;
    default:
      if (r >= kAccelXoutH && r <= kGyroZoutL) return;  // data registers are read-only
      regs_[r] = v;
  }
}

std::uint8_t Mpu6050Emulator::read_reg(std::uint8_t r) {
  switch (r) {
    case kIntStatus: {
      const std::uint8_t v = regs_[r];
      regs_[r] = 0;  // cleared on read
      return v;
    }
    case kFifoCountH:
      // the count is latched when the high byte is read
      fifo_count_latch_ = static_cast<std::uint16_t>(fifo_.size());
      return static_cast<std::uint8_t>(fifo_count_latch_ >> 8);
    case kFifoCountH + 1: return static_cast<std::uint8_t>(fifo_count_latch_ & 0xFF);
    case kFifoRw: {
      if (fifo_.empty()) return 0xFF;
      const std::uint8_t v = fifo_.front();
      fifo_.pop_front();
      return v;
    }
    default: return regs_[r];
  }
}

void Mpu6050Emulator::i2c_write(const std::uint8_t* data, std::size_t n) {
  advance();
  if (n == 0) return;
  ptr_ = data[0] & 0x7F;
  for (std::size_t i = 1; i < n; ++i) {
    write_reg(ptr_, data[i]);
    ptr_ = static_cast<std::uint8_t>((ptr_ + 1) & 0x7F);
  }
}

void Mpu6050Emulator::i2c_read(std::uint8_t* out, std::size_t n) {
  advance();
  for (std::size_t i = 0; i < n; ++i) {
    out[i] = read_reg(ptr_);
    if (ptr_ != kFifoRw) ptr_ = static_cast<std::uint8_t>((ptr_ + 1) & 0x7F);
  }
}

}  // namespace driftless::hil
