#include "hil_bridge/i2c/emulated_bus.hpp"

namespace driftless::hil {

EmulatedI2cBus::EmulatedI2cBus(const Clock& clock, VirtualClock* virtual_clock, double bus_hz)
    : clock_(clock), vclock_(virtual_clock), bus_hz_(bus_hz) {}

void EmulatedI2cBus::attach(std::uint8_t addr, Mpu6050Emulator* device) { devices_[addr] = device; }

void EmulatedI2cBus::fail_next(std::uint8_t addr, int count, I2cResult result, double timeout_s) {
  pending_.push_back(Pending{addr, count, result, timeout_s});
}

void EmulatedI2cBus::unplug(std::uint8_t addr, double from_s, double to_s) {
  unplugged_.push_back(Window{addr, from_s, to_s});
}

void EmulatedI2cBus::unplug_adapter(double from_s, double to_s) {
  unplugged_.push_back(Window{0, from_s, to_s});
}

bool EmulatedI2cBus::reopen() {
  const double now = clock_.now_s();
  for (const auto& w : unplugged_) {
    if (w.addr == 0 && now >= w.from_s && now < w.to_s) return false;
  }
  adapter_lost_ = false;
  return true;
}

I2cResult EmulatedI2cBus::transfer(std::uint8_t addr, const std::uint8_t* wr, std::size_t nwr,
                                   std::uint8_t* rd, std::size_t nrd) {
  ++transactions_;
  // time on the wire: start, address (+ repeated start and address), data, 9 bits per byte
  if (vclock_) {
    const double bytes = 1.0 + static_cast<double>(nwr) + (nrd > 0 ? 1.0 + static_cast<double>(nrd) : 0.0);
    vclock_->advance(bytes * 9.0 / bus_hz_);
  }
  const double now = clock_.now_s();
  auto fail = [&](I2cResult r) {
    ++failed_;
    return r;
  };
  // unplug windows: the adapter, or one device (which comes back in its power-on state)
  for (auto& w : unplugged_) {
    const bool inside = now >= w.from_s && now < w.to_s;
    if (w.addr == 0 && inside) adapter_lost_ = true;
    if (w.addr == addr && inside) return fail(I2cResult::kNack);
    if (w.addr == addr && now >= w.to_s && !w.reset_done) {
      w.reset_done = true;
      if (auto it = devices_.find(addr); it != devices_.end()) it->second->power_on_reset();
    }
  }
  if (adapter_lost_) return fail(I2cResult::kNoAdapter);
  for (auto it = pending_.begin(); it != pending_.end(); ++it) {
    if (it->addr != 0 && it->addr != addr) continue;
    const I2cResult r = it->result;
    if (r == I2cResult::kTimeout && vclock_) vclock_->advance(it->timeout_s);
    if (--it->count <= 0) pending_.erase(it);
    return fail(r);
  }
  auto dev = devices_.find(addr);
  if (dev == devices_.end()) return fail(I2cResult::kNack);
  // a combined transaction: the write sets the register pointer, the read follows
  if (nwr > 0) dev->second->i2c_write(wr, nwr);
  if (nrd > 0) dev->second->i2c_read(rd, nrd);
  return I2cResult::kOk;
}

}  // namespace driftless::hil
