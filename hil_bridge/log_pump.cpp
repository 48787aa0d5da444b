#include "hil_bridge/log_pump.hpp"

#include <chrono>
#include <stdexcept>

namespace driftless::hil {

namespace {
// the pump wakes this often: 5 rows at 1 kHz per wake-up, far below the ring's capacity
constexpr auto kPumpPeriod = std::chrono::milliseconds(5);
// the loop's wait for a free slot when the pump fell 'capacity' rows behind
constexpr auto kFullWait = std::chrono::microseconds(100);
}  // namespace

LogPump::LogPump(log::LogWriter& writer, double flush_every_s, std::size_t capacity)
    : writer_(writer), flush_every_s_(flush_every_s), ring_(capacity) {
  if (!(flush_every_s > 0.0)) throw std::invalid_argument("log pump: flush interval must be > 0 s");
  if (capacity == 0) throw std::invalid_argument("log pump: the ring needs at least one slot");
  thread_ = std::thread([this] { run(); });
}

LogPump::~LogPump() { stop_thread(); }

LogPump::Item& LogPump::next_slot() {
  const std::uint64_t head = head_.load(std::memory_order_relaxed);
  for (;;) {
    if (failed_.load(std::memory_order_acquire) && !reported_) {
      reported_ = true;
      std::rethrow_exception(error_);
    }
    if (head - tail_.load(std::memory_order_acquire) < ring_.size()) break;
    ++waits_;
    std::this_thread::sleep_for(kFullWait);
  }
  return ring_[head % ring_.size()];
}

void LogPump::write(const Sample& s) {
  Item& it = next_slot();
  it.is_event = false;
  it.sample = s;
  publish();
}

void LogPump::event(double t_s, std::string_view text) {
  Item& it = next_slot();
  it.is_event = true;
  it.t_s = t_s;
  it.text.assign(text);
  publish();
}

void LogPump::drain() {
  const std::uint64_t head = head_.load(std::memory_order_acquire);
  for (std::uint64_t i = tail_.load(std::memory_order_relaxed); i < head; ++i) {
    const Item& it = ring_[i % ring_.size()];
    if (it.is_event) {
      writer_.event(it.t_s, it.text);
    } else {
      writer_.write(it.sample);
    }
    tail_.store(i + 1, std::memory_order_release);
  }
}

void LogPump::run() {
  using Clock = std::chrono::steady_clock;
  const auto flush_every = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(flush_every_s_));
  auto last_flush = Clock::now();
  try {
    for (;;) {
      // read closing_ first: whatever the loop queued before it asked to close is then drained
      const bool closing = closing_.load(std::memory_order_acquire);
      drain();
      if (closing) return;
      if (Clock::now() - last_flush >= flush_every) {
        writer_.flush();
        last_flush = Clock::now();
      }
      std::this_thread::sleep_for(kPumpPeriod);
    }
  } catch (...) {
    error_ = std::current_exception();
    failed_.store(true, std::memory_order_release);
  }
}

void LogPump::stop_thread() {
  if (!thread_.joinable()) return;
  closing_.store(true, std::memory_order_release);
  thread_.join();
}

void LogPump::close() {
  stop_thread();
  if (failed_.load(std::memory_order_acquire) && !reported_) {
    reported_ = true;
    std::rethrow_exception(error_);
  }
}

}  // namespace driftless::hil
