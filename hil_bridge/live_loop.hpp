// The live loop: reads a source, keeps one time line, records the measurement log (with
// '# event:' lines for every fault, gap, reconnect and switch-over), drives the motors' flip
// schedule and feeds one DriftlessFilter. A switch-over at session time T hands the stream to a
// second source while the same filter object keeps running: the first source's last sample is
// the last one before T, the second source's first sample follows it one period later.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "estimator/filter.hpp"
#include "estimator/lock_state.hpp"
#include "estimator/log.hpp"
#include "hil_bridge/clock.hpp"
#include "hil_bridge/fdi_watch.hpp"
#include "hil_bridge/log_pump.hpp"
#include "hil_bridge/motors.hpp"
#include "hil_bridge/source.hpp"

namespace driftless::hil {

struct LiveParams {
  double duration_s = std::numeric_limits<double>::infinity();  // session time to run, s
  double switch_at_s = kNaN;         // session time of the switch-over, s (NaN: none)
  double reconnect_interval_s = 0.2; // between reconnect attempts, s (on the loop's clock)
  double give_up_after_s = 30.0;     // a device gone this long ends the run, s
  double log_flush_every_s = 0.5;    // the log's rows reach the OS at least this often, s of wall time
  void validate() const;
};

/// What a run did.
struct LiveStats {
  std::uint64_t samples = 0;         // rows written (and pushed)
  std::uint64_t samples_first = 0;   // of them from the first source
  std::uint64_t samples_second = 0;  // from the second source
  std::uint64_t events = 0;          // event lines written
  std::uint64_t faults = 0;          // fault events (bus, time-out, corrupt, overflow, disconnect)
  std::uint64_t lost_samples = 0;    // reported lost by the sources
  std::uint64_t gaps = 0;            // jumps in time of more than 1.5 periods
  std::uint64_t reconnects = 0;
  std::uint64_t log_waits = 0;       // times the loop waited for the log's thread (ring full)
  bool switched = false;
  double t_first_s = kNaN, t_last_s = kNaN;  // session time of first and last row, s
  double t_switch_s = kNaN;                  // session time of the first row of the second source
  bool complete = false;             // ended by duration, end of stream or Ctrl-C (not a failure)
  std::string end_reason;
  // the filter's lock, stepped at each update as 'estimate' steps it (estimator/lock_state.hpp:
  // the lock level with hysteresis), so a sigma that sits on the level does not read as no lock
  bool ever_locked = false;    // the correction locked at some update
  bool locked_at_end = false;  // and was locked after the session's last update
  double sigma_at_end_dps = kNaN;  // deg/s, the largest sigma of the correction at the end
};

class LiveLoop {
 public:
  /// `log`, `filter` and `motors` may be null. They and `clock` must outlive the loop. During
  /// run() the log is written on a thread of the loop's own (LogPump): nobody else may touch it
  /// until run() returns.
  LiveLoop(LiveParams p, Clock& clock, log::LogWriter* log, est::DriftlessFilter* filter);

  /// While `source` streams, drives `motors` through `schedule` (may be null) on session time and
  /// fills the platform angles of sources that do not know them (bare I2C sensors) from the
  /// end-stop switches.
  void set_motors(const SampleSource* source, Motors* motors, FlipSchedule* schedule) {
    rigs_.push_back({source, motors, schedule});
  }
  /// Runs fault detection beside the filter (needs a filter; `fdi` may be null and must outlive
  /// the loop): its state changes become event lines ("fdi: ...").
  void set_fdi(FdiWatch* fdi) { fdi_ = fdi; }
  /// Called after each sample is written and pushed (terminal display, benchmarks).
  void on_sample(std::function<void(const Sample&, SampleSource&)> f) { on_sample_ = std::move(f); }
  /// Called for every event line written.
  void on_event(std::function<void(double, const std::string&)> f) { on_event_ = std::move(f); }

  /// Runs: the sources must be configured; `first` is activated here, `second` at the switch.
  /// Every row and event is in the log when it returns (or throws).
  LiveStats run(SampleSource& first, SampleSource* second, const std::atomic<bool>& stop);

 private:
  LiveStats run_loop(SampleSource& first, SampleSource* second, const std::atomic<bool>& stop);
  void event(const std::string& text);
  void drain(SampleSource& src);
  bool reconnect(SampleSource& src, const std::atomic<bool>& stop);

  LiveParams p_;
  Clock& clock_;
  log::LogWriter* log_;
  LogPump* pump_ = nullptr;  // the log's thread while run() runs
  est::DriftlessFilter* filter_;
  FdiWatch* fdi_ = nullptr;
  struct MotorRig {
    const SampleSource* source;
    Motors* motors;
    FlipSchedule* schedule;
  };
  std::vector<MotorRig> rigs_;
  Motors* motors_ = nullptr;
  FlipSchedule* schedule_ = nullptr;
  void select_motors(const SampleSource* src);
  std::function<void(const Sample&, SampleSource&)> on_sample_;
  std::function<void(double, const std::string&)> on_event_;
  LiveStats stats_;
  est::LockState lock_;
  void step_lock(est::PushStatus pushed);
  double t_last_ = kNaN;  // session time of the last row
  std::vector<SourceEvent> pending_;
};

}  // namespace driftless::hil
