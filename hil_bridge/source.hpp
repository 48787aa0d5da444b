// The sample-source interface every back end implements: the twin, a replayed log, two MPU6050s
// on I2C, a microcontroller on a serial link (and their emulators). Lifecycle:
//   configure() -> activate() -> read()... -> deactivate()   (reconnect() after kDisconnected)
// configure/activate report bad input or a missing device with a Status a user can act on;
// read() is the hot path: it returns a ReadStatus and never throws. Faults are reported as
// events (take_events) so the live loop can mark them in the log.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "estimator/log.hpp"
#include "estimator/sample.hpp"

namespace driftless::hil {

/// Outcome of a lifecycle call.
struct Status {
  enum class Code { kOk, kNotFound, kBadConfig, kDeviceError };
  Code code = Code::kOk;
  std::string message;  // what went wrong and what to do, naming the device
  bool ok() const { return code == Code::kOk; }
  static Status Ok() { return {}; }
  static Status NotFound(std::string m) { return {Code::kNotFound, std::move(m)}; }
  static Status BadConfig(std::string m) { return {Code::kBadConfig, std::move(m)}; }
  static Status DeviceError(std::string m) { return {Code::kDeviceError, std::move(m)}; }
};

/// Outcome of one read().
enum class ReadStatus {
  kSample,        // the output sample holds the next sample
  kPending,       // no sample within the poll time-out; call again
  kFault,         // a transient fault (bus error, corrupt frame...); see the events; call again
  kDisconnected,  // the device is gone; call reconnect() until it returns ok
  kEnd,           // the stream ended (replay finished, simulation over)
  kFailed,        // the stream cannot go on (a malformed row in a replayed log); see the events:
                  // the session ends there, its log says it is incomplete
};

const char* to_string(ReadStatus s);

/// What kind of thing happened (each becomes a '# event:' line in the log).
enum class EventKind {
  kBusError,      // NACK / EIO on a transaction
  kTimeout,       // no answer within the time-out
  kDisconnected,  // the device vanished
  kReconnected,   // the device is back (re-initialised)
  kCorruptFrame,  // a serial frame failed its CRC or framing
  kSequenceGap,   // frames missing (sequence numbers skipped)
  kFifoOverflow,  // the sensor FIFO overflowed: samples lost
  kSaturation,    // a gyro axis sat at full scale (values written as empty)
  kGap,           // samples missing from the stream (timestamps jump)
  kSwitch,        // the live loop switched sources
  kInfo,          // anything else worth recording
};

const char* to_string(EventKind k);

/// A fault or note from a source, stamped on the source's clock.
struct SourceEvent {
  EventKind kind = EventKind::kInfo;
  double t_s = kNaN;             // source time (s) of the last good sample before it, NaN if none
  std::string text;              // one line, no newline
  std::uint64_t lost_samples = 0;  // samples known or estimated to be lost
};

/// A stream of Samples from one back end.
class SampleSource {
 public:
  virtual ~SampleSource() = default;
  /// Short name for logs and messages, e.g. "i2c:/dev/i2c-1".
  virtual std::string name() const = 0;
  /// Nominal output rate, Hz (valid after configure()).
  virtual double sample_rate_hz() const = 0;
  /// Optional Sample fields this source fills (SampleField bits).
  virtual std::uint32_t fields() const = 0;
  /// False when the source cannot know the platform angles (bare sensors on I2C): the live loop
  /// then takes them from the motors' end-stop switches.
  virtual bool knows_platforms() const { return true; }
  /// Adds what the source knows about the box to the log metadata (hinge axes, latitude...).
  virtual void describe(log::Metadata& meta) const { meta.set("source", name()); }

  /// Checks the settings and probes the device (opens it, reads its identity).
  virtual Status configure() = 0;
  /// Starts the stream; samples time-stamped on the source clock, strictly increasing.
  virtual Status activate() = 0;
  /// Next sample into `out` (only written on kSample). Never throws.
  virtual ReadStatus read(Sample& out) = 0;
  /// After kDisconnected: one attempt to reopen and re-initialise. ok() when streaming again.
  virtual Status reconnect() { return Status::DeviceError(name() + ": cannot reconnect"); }
  /// Stops the stream and releases the device (safe to call twice).
  virtual void deactivate() = 0;
  /// After kFailed: why the stream cannot go on.
  virtual std::string failure() const { return "no cause given"; }

  /// Moves the events gathered since the last call into `out` (appends).
  void take_events(std::vector<SourceEvent>& out) {
    for (auto& e : events_) out.push_back(std::move(e));
    events_.clear();
  }
  bool has_events() const { return !events_.empty(); }

 protected:
  void report(EventKind kind, double t_s, std::string text, std::uint64_t lost = 0) {
    events_.push_back(SourceEvent{kind, t_s, std::move(text), lost});
  }

 private:
  std::vector<SourceEvent> events_;
};

}  // namespace driftless::hil
