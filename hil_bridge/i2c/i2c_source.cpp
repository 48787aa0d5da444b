#include "hil_bridge/i2c/i2c_source.hpp"

#include "hil_bridge/raw_sample.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

namespace driftless::hil {

using namespace mpu6050;

namespace {
std::string hex(std::uint8_t v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", v);
  return buf;
}
// a FIFO this close to full may overflow while it is read: treat it as overflowed
constexpr int kFifoNearFullBytes = kFifoSizeBytes - 4 * kRecordBytes;
}  // namespace

int I2cSourceParams::smplrt_div() const {
  const double out = gyro_output_rate_hz(dlpf_cfg);
  const double div = out / sample_rate_hz - 1.0;
  const double r = std::round(div);
  if (!(std::abs(div - r) < 1e-9 && r >= 0.0 && r <= 255.0)) {
    throw std::invalid_argument(
        "i2c: sample rate " + std::to_string(sample_rate_hz) + " Hz is not " +
        std::to_string(static_cast<int>(out)) + " Hz / (1 + SMPLRT_DIV) with SMPLRT_DIV in 0..255 "
        "(DLPF_CFG " + std::to_string(dlpf_cfg) + "); e.g. 1000, 500, 200, 100, 50 Hz");
  }
  return static_cast<int>(r);
}

void I2cSourceParams::validate() const {
  if (address1 == address2) throw std::invalid_argument("i2c: the two sensors need different addresses");
  if (dlpf_cfg < 0 || dlpf_cfg > 6) throw std::invalid_argument("i2c: dlpf_cfg must be 0..6");
  if (gyro_fs_sel < 0 || gyro_fs_sel > 3) throw std::invalid_argument("i2c: gyro_fs_sel must be 0..3");
  if (accel_fs_sel < 0 || accel_fs_sel > 3) throw std::invalid_argument("i2c: accel_fs_sel must be 0..3");
  if (!(sample_rate_hz > 0.0)) throw std::invalid_argument("i2c: sample_rate_hz must be > 0 Hz");
  smplrt_div();
  if (!(poll_timeout_s > 0.0 && stall_timeout_s > 0.0)) {
    throw std::invalid_argument("i2c: poll_timeout_s and stall_timeout_s must be > 0 s");
  }
  if (!(wake_margin_s >= 0.0 && repoll_interval_s > 0.0)) {
    throw std::invalid_argument("i2c: wake_margin_s must be >= 0 s and repoll_interval_s > 0 s");
  }
  if (max_consecutive_errors < 1) throw std::invalid_argument("i2c: max_consecutive_errors must be >= 1");
  if (max_records_per_read < 1 || max_records_per_read * kRecordBytes > kFifoSizeBytes) {
    throw std::invalid_argument("i2c: max_records_per_read must be 1..73");
  }
}

I2cSource::I2cSource(I2cTransport& bus, Clock& clock, I2cSourceParams p)
    : bus_(bus), clock_(clock), p_(p) {}

Status I2cSource::configure() {
  try {
    p_.validate();
  } catch (const std::invalid_argument& e) {
    return Status::BadConfig(e.what());
  }
  if (std::string err = bus_.open(); !err.empty()) return Status::NotFound(err);
  for (std::uint8_t addr : {p_.address1, p_.address2}) {
    std::uint8_t who = 0;
    const I2cResult r = bus_.read_regs(addr, kWhoAmI, &who, 1);
    if (r != I2cResult::kOk) {
      return Status::NotFound(bus_.name() + ": no MPU6050 answers at " + hex(addr) + " (" + to_string(r) +
                              "); check wiring and power, AD0 low for 0x68 and high for 0x69 "
                              "(list devices with 'i2cdetect -y N')");
    }
    if (who != kWhoAmIValue) {
      return Status::DeviceError(bus_.name() + ": device at " + hex(addr) + " has WHO_AM_I " + hex(who) +
                                 ", expected 0x68 (an MPU-6050)");
    }
  }
  return Status::Ok();
}

Status I2cSource::init_chip(std::uint8_t addr) {
  auto fail = [&](I2cResult r, const char* what) {
    return Status::DeviceError(bus_.name() + ": " + hex(addr) + ": " + to_string(r) + " while " + what);
  };
  std::uint8_t who = 0;
  if (auto r = bus_.read_regs(addr, kWhoAmI, &who, 1); r != I2cResult::kOk) return fail(r, "reading WHO_AM_I");
  if (who != kWhoAmIValue) {
    return Status::DeviceError(bus_.name() + ": " + hex(addr) + ": WHO_AM_I " + hex(who) + ", expected 0x68");
  }
  // reset, then wake with the X-gyro PLL as clock (more stable than the internal oscillator)
  if (auto r = bus_.write_reg(addr, kPwrMgmt1, kPwrDeviceReset); r != I2cResult::kOk) return fail(r, "resetting");
  clock_.sleep_for(p_.reset_wait_s);
  const std::uint8_t want[5] = {kClkPllXGyro, static_cast<std::uint8_t>(p_.smplrt_div()),
                                static_cast<std::uint8_t>(p_.dlpf_cfg),
                                static_cast<std::uint8_t>(p_.gyro_fs_sel << 3),
                                static_cast<std::uint8_t>(p_.accel_fs_sel << 3)};
  const std::uint8_t regs[5] = {kPwrMgmt1, kSmplrtDiv, kConfig, kGyroConfig, kAccelConfig};
  for (int i = 0; i < 5; ++i) {
    if (auto r = bus_.write_reg(addr, regs[i], want[i]); r != I2cResult::kOk) return fail(r, "configuring");
  }
  // read back: a device that ignores writes is broken or not an MPU-6050
  for (int i = 0; i < 5; ++i) {
    std::uint8_t v = 0;
    if (auto r = bus_.read_regs(addr, regs[i], &v, 1); r != I2cResult::kOk) return fail(r, "verifying");
    if (v != want[i]) {
      return Status::DeviceError(bus_.name() + ": " + hex(addr) + ": register " + hex(regs[i]) + " reads " +
                                 hex(v) + " after writing " + hex(want[i]));
    }
  }
  const std::uint8_t fifo_en = p_.use_fifo ? kFifoEnTempGyroAccel : 0;
  if (auto r = bus_.write_reg(addr, kFifoEn, fifo_en); r != I2cResult::kOk) return fail(r, "enabling the FIFO");
  if (auto r = bus_.write_reg(addr, kIntEnable, kIntFifoOflow | kIntDataRdy); r != I2cResult::kOk) {
    return fail(r, "enabling interrupts");
  }
  return Status::Ok();
}

Status I2cSource::activate() {
  for (std::uint8_t addr : {p_.address1, p_.address2}) {
    if (Status s = init_chip(addr); !s.ok()) return s;
  }
  ready_.clear();
  n_next_ = 0;
  saturation_ = SaturationTracker();
  if (p_.use_fifo) {
    if (reset_fifos("start") != ReadStatus::kPending) {
      return Status::DeviceError(bus_.name() + ": cannot reset the FIFOs");
    }
  } else {
    // clear a stale DATA_RDY
    std::uint8_t st = 0;
    bus_.read_regs(p_.address1, kIntStatus, &st, 1);
  }
  t0_host_s_ = clock_.now_s();
  last_data_host_s_ = t0_host_s_;
  active_ = true;
  gone_ = false;
  errors_in_row_ = 0;
  return Status::Ok();
}

void I2cSource::deactivate() {
  if (!active_) return;
  active_ = false;
  // put both chips to sleep; errors do not matter here
  bus_.write_reg(p_.address1, kPwrMgmt1, kPwrSleep | kClkPllXGyro);
  bus_.write_reg(p_.address2, kPwrMgmt1, kPwrSleep | kClkPllXGyro);
}

std::uint64_t I2cSource::expected_index() const {
  const double n = std::floor((clock_.now_s() - t0_host_s_) * p_.sample_rate_hz);
  return n <= 0.0 ? 0 : static_cast<std::uint64_t>(n);
}

ReadStatus I2cSource::bus_error(I2cResult r, std::uint8_t addr, const char* what) {
  const double t_last = n_next_ > 0 ? t_of(n_next_ - 1) : kNaN;
  if (r == I2cResult::kNoAdapter) {
    gone_ = true;
    report(EventKind::kDisconnected, t_last, bus_.name() + " vanished (" + what + ")");
    return ReadStatus::kDisconnected;
  }
  ++errors_in_row_;
  report(r == I2cResult::kTimeout ? EventKind::kTimeout : EventKind::kBusError, t_last,
         bus_.name() + " " + hex(addr) + ": " + to_string(r) + " " + what + " (" +
             std::to_string(errors_in_row_) + " in a row)");
  if (errors_in_row_ >= p_.max_consecutive_errors) {
    gone_ = true;
    report(EventKind::kDisconnected, t_last,
           bus_.name() + " " + hex(addr) + " stopped answering after " + std::to_string(errors_in_row_) +
               " failed transactions");
    return ReadStatus::kDisconnected;
  }
  return ReadStatus::kFault;
}

ReadStatus I2cSource::reset_fifos(const std::string& why) {
  for (std::uint8_t addr : {p_.address1, p_.address2}) {
    if (auto r = bus_.write_reg(addr, kUserCtrl, kUserFifoEn | kUserFifoReset); r != I2cResult::kOk) {
      return bus_error(r, addr, "resetting the FIFO");
    }
    std::uint8_t st = 0;  // clear a latched overflow flag
    if (auto r = bus_.read_regs(addr, kIntStatus, &st, 1); r != I2cResult::kOk) {
      return bus_error(r, addr, "clearing INT_STATUS");
    }
  }
  if (why != "start") {
    // samples the devices made since the last one we read are gone: stamp the next one where the
    // host clock says it belongs, so the log shows the gap instead of closing it
    const std::uint64_t n_new = std::max(n_next_, expected_index());
    const std::uint64_t lost = n_new - n_next_;
    const double t_last = n_next_ > 0 ? t_of(n_next_ - 1) : kNaN;
    report(EventKind::kFifoOverflow, t_last,
           "FIFO " + why + ": both FIFOs reset, about " + std::to_string(lost) + " samples lost", lost);
    n_next_ = n_new;
  }
  return ReadStatus::kPending;
}

void I2cSource::check_stall() {
  const double now = clock_.now_s();
  if (now - last_data_host_s_ < p_.stall_timeout_s) return;
  const double t_last = n_next_ > 0 ? t_of(n_next_ - 1) : kNaN;
  // a device that reset itself (brown-out, replugged) is asleep: wake it up again
  for (std::uint8_t addr : {p_.address1, p_.address2}) {
    std::uint8_t pwr = 0;
    if (bus_.read_regs(addr, kPwrMgmt1, &pwr, 1) != I2cResult::kOk) continue;
    if (pwr & kPwrSleep) {
      report(EventKind::kTimeout, t_last,
             "no data for " + std::to_string(now - last_data_host_s_) + " s: " + hex(addr) +
                 " was reset (PWR_MGMT_1 " + hex(pwr) + "), re-initialising both sensors");
      if (init_chip(p_.address1).ok() && init_chip(p_.address2).ok()) {
        reset_fifos("restart after a device reset");
        report(EventKind::kReconnected, t_last, bus_.name() + ": sensors re-initialised");
      }
      last_data_host_s_ = clock_.now_s();
      return;
    }
  }
  report(EventKind::kTimeout, t_last, "no data from " + bus_.name() + " for " +
                                          std::to_string(now - last_data_host_s_) + " s");
  last_data_host_s_ = now;  // report once per stall period
}

void I2cSource::emit(const RawRecord& r1, const RawRecord& r2) {
  Sample s;
  s.t_s = t_of(n_next_);
  const RawRecord* recs[2] = {&r1, &r2};
  for (int k = 0; k < 2; ++k) {
    const int mask = fill_from_raw(k, *recs[k], p_.gyro_fs_sel, p_.accel_fs_sel, s);
    if (std::string msg = saturation_.update(k, mask, p_.gyro_fs_sel); !msg.empty()) {
      report(EventKind::kSaturation, s.t_s, std::move(msg));
    }
  }
  ready_.push_back(s);
  ++n_next_;
}

ReadStatus I2cSource::poll_fifo() {
  std::uint8_t st[2] = {0, 0};
  int count[2] = {0, 0};
  const std::uint8_t addr[2] = {p_.address1, p_.address2};
  for (int k = 0; k < 2; ++k) {
    if (auto r = bus_.read_regs(addr[k], kIntStatus, &st[k], 1); r != I2cResult::kOk) {
      return bus_error(r, addr[k], "reading INT_STATUS");
    }
    std::uint8_t c[2];
    if (auto r = bus_.read_regs(addr[k], kFifoCountH, c, 2); r != I2cResult::kOk) {
      return bus_error(r, addr[k], "reading FIFO_COUNT");
    }
    count[k] = c[0] << 8 | c[1];
  }
  errors_in_row_ = 0;
  if ((st[0] | st[1]) & kIntFifoOflow) return reset_fifos("overflow");
  if (count[0] >= kFifoNearFullBytes || count[1] >= kFifoNearFullBytes) return reset_fifos("nearly full");
  // the two chips run on their own clocks: far apart means one FIFO fills while the other does not
  if (std::abs(count[0] - count[1]) > 8 * kRecordBytes) return reset_fifos("counts diverged");
  const int records = std::min({count[0] / kRecordBytes, count[1] / kRecordBytes, p_.max_records_per_read});
  if (records == 0) return ReadStatus::kPending;
  const std::size_t n = static_cast<std::size_t>(records * kRecordBytes);
  std::uint8_t buf[2][kFifoSizeBytes];
  for (int k = 0; k < 2; ++k) {
    if (auto r = bus_.read_regs(addr[k], kFifoRw, buf[k], n); r != I2cResult::kOk) {
      // part of the FIFO may have been read: alignment is unknown, start both afresh
      const ReadStatus s = bus_error(r, addr[k], "reading the FIFO");
      if (s == ReadStatus::kFault) reset_fifos("read failed");
      return s;
    }
  }
  for (int i = 0; i < records; ++i) {
    emit(decode_record(buf[0] + i * kRecordBytes), decode_record(buf[1] + i * kRecordBytes));
  }
  last_data_host_s_ = clock_.now_s();
  return ReadStatus::kSample;
}

ReadStatus I2cSource::poll_burst() {
  std::uint8_t st = 0;
  if (auto r = bus_.read_regs(p_.address1, kIntStatus, &st, 1); r != I2cResult::kOk) {
    return bus_error(r, p_.address1, "reading INT_STATUS");
  }
  if ((st & kIntDataRdy) == 0) return ReadStatus::kPending;
  std::uint8_t buf[2][kRecordBytes];
  const std::uint8_t addr[2] = {p_.address1, p_.address2};
  for (int k = 0; k < 2; ++k) {
    if (auto r = bus_.read_regs(addr[k], kAccelXoutH, buf[k], kRecordBytes); r != I2cResult::kOk) {
      return bus_error(r, addr[k], "reading the data registers");
    }
  }
  errors_in_row_ = 0;
  // the data registers hold the latest sample only: a late host misses samples
  const std::uint64_t n_now = expected_index();
  const std::uint64_t n = std::max(n_next_, n_now > 0 ? n_now - 1 : 0);
  if (n > n_next_) {
    report(EventKind::kGap, n_next_ > 0 ? t_of(n_next_ - 1) : kNaN,
           "burst read late: " + std::to_string(n - n_next_) + " samples missed", n - n_next_);
    n_next_ = n;
  }
  emit(decode_record(buf[0]), decode_record(buf[1]));
  last_data_host_s_ = clock_.now_s();
  return ReadStatus::kSample;
}

ReadStatus I2cSource::read(Sample& out) {
  if (!ready_.empty()) {
    out = ready_.front();
    ready_.pop_front();
    ++samples_;
    return ReadStatus::kSample;
  }
  if (!active_) return ReadStatus::kEnd;
  if (gone_) return ReadStatus::kDisconnected;
  const double deadline = clock_.now_s() + p_.poll_timeout_s;
  for (;;) {
    const ReadStatus s = p_.use_fifo ? poll_fifo() : poll_burst();
    if (!ready_.empty()) {
      out = ready_.front();
      ready_.pop_front();
      ++samples_;
      return ReadStatus::kSample;
    }
    if (s == ReadStatus::kFault || s == ReadStatus::kDisconnected) return s;
    const double now = clock_.now_s();
    if (now >= deadline) {
      check_stall();
      return ReadStatus::kPending;
    }
    // sleep until the next sample is due (a little after, so it is there)
    const double due = t0_host_s_ + static_cast<double>(expected_index() + 1) / p_.sample_rate_hz + p_.wake_margin_s;
    clock_.sleep_until(std::min(deadline, std::max(due, now + p_.repoll_interval_s)));
  }
}

Status I2cSource::reconnect() {
  if (!active_) return Status::DeviceError(name() + ": not active");
  if (!bus_.reopen()) return Status::DeviceError(bus_.name() + " is still gone");
  for (std::uint8_t addr : {p_.address1, p_.address2}) {
    if (Status s = init_chip(addr); !s.ok()) return s;
  }
  ready_.clear();
  gone_ = false;
  errors_in_row_ = 0;
  const double t_last = n_next_ > 0 ? t_of(n_next_ - 1) : kNaN;
  report(EventKind::kReconnected, t_last, bus_.name() + ": both sensors answer again, re-initialised");
  if (reset_fifos("restart after reconnect") != ReadStatus::kPending) {
    return Status::DeviceError(bus_.name() + ": cannot reset the FIFOs");
  }
  last_data_host_s_ = clock_.now_s();
  return Status::Ok();
}

}  // namespace driftless::hil
