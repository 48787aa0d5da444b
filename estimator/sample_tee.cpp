#include "estimator/sample_tee.hpp"

#include <utility>

namespace driftless::est {

void SampleTee::offer(const Sample& s) {
  if (off_seen_) return;
  chunk_.push_back(s);
  if (chunk_.size() >= kChunk) flush();
}

void SampleTee::flush() {
  if (chunk_.empty()) return;
  std::unique_lock<std::mutex> lk(m_);
  if (!off_ && !attached_ && queued_ + chunk_.size() > kMaxSamples) {
    // too many rows before the second pass is wanted: it reads the log itself if it ever is
    off_ = true;
    queue_.clear();
    queued_ = 0;
  }
  // attached: the reading pass waits for the second to catch up (back-pressure, bounded memory)
  cv_.wait(lk, [&] { return off_ || queued_ + chunk_.size() <= kMaxSamples; });
  if (off_) {
    off_seen_ = true;
    chunk_ = {};
    return;
  }
  queued_ += chunk_.size();
  queue_.push_back(std::move(chunk_));
  chunk_ = {};
  chunk_.reserve(kChunk);
  cv_.notify_all();
}

void SampleTee::end() {
  flush();
  std::lock_guard<std::mutex> lk(m_);
  ended_ = true;
  cv_.notify_all();
}

bool SampleTee::attach() {
  std::lock_guard<std::mutex> lk(m_);
  if (off_) return false;
  attached_ = true;
  return true;
}

bool SampleTee::attached() const {
  std::lock_guard<std::mutex> lk(m_);
  return attached_ && !off_;
}

void SampleTee::detach() {
  std::lock_guard<std::mutex> lk(m_);
  detached_.store(true, std::memory_order_relaxed);
  off_ = true;
  queue_.clear();
  queued_ = 0;
  cv_.notify_all();
}

bool SampleTee::next(Sample& s) {
  if (detached_.load(std::memory_order_relaxed)) return false;
  if (pos_ == cur_.size()) {
    std::unique_lock<std::mutex> lk(m_);
    cv_.wait(lk, [&] { return off_ || ended_ || !queue_.empty(); });
    if (off_ || queue_.empty()) return false;
    cur_ = std::move(queue_.front());
    queue_.pop_front();
    queued_ -= cur_.size();
    pos_ = 0;
    cv_.notify_all();
  }
  s = cur_[pos_++];
  return true;
}

}  // namespace driftless::est
