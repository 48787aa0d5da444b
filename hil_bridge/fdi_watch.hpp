// Fault detection on the live stream (docs/fdi.md, docs/hil.md "Fault detection"): the
// estimator's FaultDetector beside the DriftLess filter of the live loop. Each sample the loop
// has pushed goes in with the filter's push status; what changed (the residual noise learned,
// the first alarm, the fault isolated) comes out as one event line for the log and the terminal.
// Like the filter's standstill (EstimatorConfig::end_margin_s), the rest samples just before a
// platform is seen moving are not used: an end-stop switch opens only after the platform has left
// its stop (the first sample of a flip can carry the hinge rate while the angle still reads the
// stop), so the watch holds each sample for the end margin and drops the held ones when motion
// shows. Detection comes that much later (0.1 s by default). Per sample it costs one CUSUM
// update; never throws.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>

#include "estimator/fdi.hpp"
#include "estimator/filter.hpp"
#include "estimator/sample.hpp"

namespace driftless::hil {

/// What the watch concluded by the end of a run.
enum class FdiVerdict {
  kNotMonitored,  // the detector never finished learning the residual noise (too little rest)
  kHealthy,       // monitored, no alarm
  kAlarm,         // an alarm that was not (yet) isolated to a sensor and axis
  kFault,         // a fault isolated: see detector().fault()
  kUncalibrated,  // alarms only, each explained by the platform positions: uncalibrated sensors,
                  // not a fault (detector().uncalibrated(); docs/fdi.md "The position check")
};
const char* to_string(FdiVerdict v);

class FdiWatch {
 public:
  /// `params.sample_rate_hz` must be the stream's rate (Hz); throws std::invalid_argument naming
  /// the field on a bad value.
  /// `end_margin_s`: rest samples held back, and dropped when motion follows, s (the filter's
  /// EstimatorConfig::end_margin_s).
  explicit FdiWatch(const est::FdiParams& params, double end_margin_s = 0.1);

  /// Feeds the sample the filter just took (`status` from its push); the detector sees it
  /// `end_margin_s` later. Returns an event text when the detector's state changed ("fdi: ..."),
  /// "" otherwise.
  std::string push(const Sample& s, est::PushStatus status, const est::DriftlessFilter& filter);

  FdiVerdict verdict() const;
  const est::FaultDetector& detector() const { return fdi_; }
  const est::FdiParams& params() const { return params_; }
  /// Samples in which the residual was tested (both platforms at rest, filter in a standstill).
  std::uint64_t rest_samples() const { return rest_samples_; }
  /// Session time at which the detector finished learning and started monitoring, s (NaN before).
  double t_learned_s() const { return t_learned_s_; }

 private:
  std::string feed(const est::FdiInput& in);

  est::FdiParams params_;
  est::FaultDetector fdi_;
  std::size_t margin_samples_;
  std::deque<est::FdiInput> held_;  // rest samples of the last end_margin_s
  est::FdiStatus last_ = est::FdiStatus::kLearning;
  bool learned_ = false, alarmed_ = false, explained_ = false;
  std::uint64_t rest_samples_ = 0;
  double t_learned_s_ = kNaN;
};

}  // namespace driftless::hil
