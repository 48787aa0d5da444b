// The rows of one log reader shared by two passes (`driftless estimate`, docs/estimator.md 1i):
// the six-state pass reads the log and offers every row here; until the self-calibrating pass is
// wanted (EarlyWatch) the rows are kept, at most kMaxSamples of them; once it attaches it takes the
// kept rows and then each new one, on its own thread, so the log is parsed once for both. More rows
// than that before it is wanted, and the tee turns off: the self-calibrating pass, if still wanted,
// reads the log again itself. Memory stays bounded either way (kMaxSamples rows, 19 MB).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <vector>

#include "estimator/sample.hpp"

namespace driftless::est {

class SampleTee {
 public:
  static constexpr std::size_t kChunk = 1024;         // rows handed over at a time
  static constexpr std::size_t kMaxSamples = 65536;   // rows kept or queued at most

  /// The reading pass: each row, in order, then end() (also when reading failed: see detach()).
  void offer(const Sample& s);
  void end();
  /// The second pass joins: true if every row from the first is still here for it (then next()
  /// gives them all, and the reading pass waits whenever kMaxSamples rows are queued).
  bool attach();
  /// Nobody will read on (a pass abandoned, or the reading pass failed): next() ends, offer() and
  /// end() do nothing more, the kept rows go.
  void detach();
  /// The second pass's rows: false at the end (or once detached).
  bool next(Sample& s);
  bool attached() const;

 private:
  void flush();
  mutable std::mutex m_;
  std::condition_variable cv_;
  std::deque<std::vector<Sample>> queue_;
  std::size_t queued_ = 0;
  bool attached_ = false, off_ = false, ended_ = false;
  std::atomic<bool> detached_{false};  // off_ by detach(): next() ends at once, mid-chunk too
  std::vector<Sample> chunk_;  // the reading pass's rows not yet handed over (its thread only)
  bool off_seen_ = false;      // the reading pass's copy of off_ (its thread only)
  std::vector<Sample> cur_;    // the second pass's chunk (its thread only)
  std::size_t pos_ = 0;
};

}  // namespace driftless::est
