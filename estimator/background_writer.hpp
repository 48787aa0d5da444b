// Formatting and writing on the second core: the producer (a pass over a log) hands over fixed-size
// blocks of records; one worker thread turns each block into text and writes it, in order, while
// the producer fills the next block. Used for the largest per-sample output (estimate's
// corrected.csv); standard library only.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

namespace driftless::io {

template <class Record>
class BackgroundWriter {
 public:
  /// `consume` runs on the worker thread, once per block, in push order (it formats and writes;
  /// an exception it throws, e.g. a full disk, is rethrown by the next push() or finish()).
  explicit BackgroundWriter(std::function<void(const std::vector<Record>&)> consume, std::size_t block_records = 8192)
      : consume_(std::move(consume)), block_records_(block_records) {
    filling_.reserve(block_records_);
    worker_ = std::thread([this] { run(); });
  }
  /// Stops the worker; a block not yet handed over is dropped (call finish() to keep it).
  ~BackgroundWriter() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    ready_.notify_all();
    if (worker_.joinable()) worker_.join();
  }
  BackgroundWriter(const BackgroundWriter&) = delete;
  BackgroundWriter& operator=(const BackgroundWriter&) = delete;

  void push(const Record& r) {
    filling_.push_back(r);
    if (filling_.size() >= block_records_) hand_over();
  }
  /// Hands over the last block, waits until everything is written, rethrows a worker's exception.
  void finish() {
    if (!filling_.empty()) hand_over();
    std::unique_lock<std::mutex> lock(mutex_);
    idle_.wait(lock, [this] { return !has_pending_ || error_; });
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
  }

 private:
  // waits until the worker took the previous block, then gives it this one
  void hand_over() {
    std::unique_lock<std::mutex> lock(mutex_);
    idle_.wait(lock, [this] { return !has_pending_ || error_; });
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
    std::swap(pending_, filling_);
    has_pending_ = true;
    filling_.clear();
    lock.unlock();
    ready_.notify_one();
  }

  void run() {
    std::vector<Record> work;
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(mutex_);
        ready_.wait(lock, [this] { return has_pending_ || stopping_; });
        if (!has_pending_) return;
        std::swap(work, pending_);
      }
      std::exception_ptr failure;
      try {
        consume_(work);
      } catch (...) {
        failure = std::current_exception();
      }
      work.clear();
      {
        std::lock_guard<std::mutex> lock(mutex_);
        has_pending_ = false;
        if (failure) error_ = failure;
      }
      idle_.notify_all();
    }
  }

  std::function<void(const std::vector<Record>&)> consume_;
  std::size_t block_records_;
  std::vector<Record> filling_;  // producer side
  std::vector<Record> pending_;  // handed over, not yet taken
  bool has_pending_ = false;
  bool stopping_ = false;
  std::exception_ptr error_;
  std::mutex mutex_;
  std::condition_variable ready_, idle_;
  std::thread worker_;
};

}  // namespace driftless::io
