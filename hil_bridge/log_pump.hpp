// The live loop's log on a thread of its own. Formatting a row and handing the buffered rows to
// the OS used to happen on the loop's thread between two samples: a write() of the buffer takes
// ~0.25 ms per MiB on this machine and up to 10 ms when the page cache is under pressure
// (measured: 40 writes of 1 MiB, median 243 us, max 10.3 ms), longer than the 1 ms a 1 kHz loop
// has. Here the loop copies the sample into a ring allocated (and touched) up front and returns;
// the pump's thread writes the rows and event lines in the loop's order, so the log's bytes are
// those of writing directly, and hands them to the OS at least every `flush_every_s`.
#pragma once

#include <atomic>
#include <cstdint>
#include <exception>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "estimator/log.hpp"

namespace driftless::hil {

class LogPump {
 public:
  /// `writer` must outlive the pump and is not touched by anyone else until close() returns.
  /// `flush_every_s`: the rows reach the OS at least this often (s of wall time); `capacity`:
  /// rows and events the ring holds (8192: 8 s at 1 kHz) before the loop has to wait.
  explicit LogPump(log::LogWriter& writer, double flush_every_s = 0.5, std::size_t capacity = 8192);
  ~LogPump();  // as close(), but an error of the writer is not reported (close() reports it)
  LogPump(const LogPump&) = delete;
  LogPump& operator=(const LogPump&) = delete;

  /// Queues a row (rethrows an error the writer raised on the pump's thread, e.g. a full disk).
  void write(const Sample& s);
  /// Queues an event line at session time t_s (s).
  void event(double t_s, std::string_view text);
  /// Writes what is queued, stops the thread and rethrows the writer's error if it had one.
  void close();
  /// How often the loop found the ring full and waited for the pump (0 when it keeps up).
  std::uint64_t waits() const { return waits_; }

 private:
  struct Item {
    bool is_event = false;
    Sample sample;
    double t_s = 0.0;
    std::string text;
  };
  Item& next_slot();  // waits while the ring is full
  void publish() { head_.store(head_.load(std::memory_order_relaxed) + 1, std::memory_order_release); }
  void run();
  void drain();
  void stop_thread();

  log::LogWriter& writer_;
  double flush_every_s_;
  std::vector<Item> ring_;
  std::atomic<std::uint64_t> head_{0};  // next slot the loop fills
  std::atomic<std::uint64_t> tail_{0};  // next slot the pump writes
  std::atomic<bool> closing_{false};
  std::atomic<bool> failed_{false};
  std::exception_ptr error_;  // set by the pump's thread before failed_
  bool reported_ = false;
  std::uint64_t waits_ = 0;
  std::thread thread_;
};

}  // namespace driftless::hil
