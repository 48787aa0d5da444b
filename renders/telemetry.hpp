// The numbers behind the overlay, computed from the sample stream as it is read: the DriftLess
// filter's bias estimate (when enabled) against the true biases, the residual of eq. (2), and
// the attitude error from lock on (est::AttitudeComparison: what `driftless estimate` reports).
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "estimator/attitude_comparison.hpp"
#include "estimator/config.hpp"
#include "estimator/pipeline.hpp"
#include "estimator/filter.hpp"
#include "estimator/log.hpp"
#include "renders/overlay.hpp"

namespace driftless::render {

/// What the overlay computes.
struct TelemetryParams {
  bool run_estimator = true;   // run the DriftLess filter on the stream
  est::EstimatorConfig estimator;  // its configuration (render --config / --selfcal; default: defaults)
  double window_s = 30.0;      // strip chart width, s of data time
  double settle_s = 0.3;       // residual counts this long after both platforms stopped, s

  /// Throws std::invalid_argument on a window or settle time <= 0.
  void validate() const;
};

/// Streams samples into the charts and the per-sample overlay state.
class Telemetry {
 public:
  /// meta: the stream's metadata (hinge axes, sample rate, latitude) for the filter.
  Telemetry(const TelemetryParams& p, const log::Metadata& meta);
  ~Telemetry();
  /// Adds one sample; `rest_s`: how long both platforms have been at rest (0 while moving).
  /// Fills the estimator-derived parts of `st` (attitude error).
  void push(const Sample& s, double rest_s, OverlayState& st);
  /// The charts to draw, top first: bias 1 and 2 estimates and the attitude error with the
  /// filter, else the residual.
  std::vector<const StripChart*> charts() const;
  /// The filter, when it runs (for tests and summaries).
  const est::DriftlessFilter* filter() const { return filter_.get(); }
  /// Data time at which every sigma of the filter's bias correction first fell below the lock
  /// level of `driftless estimate` (s; NaN: never, or no filter).
  double locked_from_s() const { return locked_from_s_; }

 private:
  TelemetryParams p_;
  ResidualChart residual_;
  std::unique_ptr<est::DriftlessFilter> filter_;
  std::optional<BiasChart> bias1_, bias2_;
  std::optional<AttitudeChart> attitude_chart_;
  std::optional<est::AttitudeComparison> attitude_;  // the comparison `driftless estimate` makes
  AttitudeNow attitude_now_;
  double lock_sigma_dps_ = est::EstimateRunOptions{}.attitude_start_sigma_dps;
  double locked_from_s_ = kNaN;
};

}  // namespace driftless::render
