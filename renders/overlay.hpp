// What the overlay says: time, platform state (with the direction of a flip) and next flip, the
// attitude error from the moment the filter locked (as `driftless estimate` defines it), and the
// strip charts: bias estimates against truth, attitude error, or the residual of eq. (2).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "estimator/sample.hpp"
#include "renders/chart.hpp"
#include "renders/timeline.hpp"

namespace driftless::render {

/// The attitude comparison as the overlay shows it (docs/estimator.md section 4).
struct AttitudeNow {
  bool available = false;    // the stream has ref_q and the filter runs
  bool started = false;      // the filter has locked on and the comparison runs
  double start_s = kNaN;     // s, when it started (lock)
  double corrected_deg = kNaN;  // deg, total attitude error with DriftLess
  double fixed_deg = kNaN;      // deg, with the bias fixed at the start
};

/// Per-sample overlay state, taken when the sample is read (frames may show it later).
struct OverlayState {
  double plat_deg[2] = {kNaN, kNaN};
  bool moving[2] = {false, false};
  double flip_from_deg[2] = {kNaN, kNaN};  // deg, where the current (or last) flip started
  double next_flip_s = kNaN;   // predicted start of the next flip, s
  int next_platform = -1;      // 0/1, -1 unknown
  AttitudeNow attitude;
};

/// Snapshot of a tracker (fed the same sample) for the overlay.
OverlayState overlay_state(const PlatformTracker& tracker);

/// How the frame is being played.
struct PlayState {
  double t_s = kNaN;           // data time of the frame, s
  double speed = 1.0;          // data s per video s
  bool realtime_flip = false;  // a flip shown at x1 inside a time-lapse
  double end_s = kNaN;         // s, where the data (or the video) ends; NaN unknown
  int close_up = -1;           // platform shown in close-up (0/1), -1 none
};

/// The overlay's text rows for one frame (time, platforms, next flip, attitude error).
std::vector<TextRow> overlay_rows(const PlayState& play, const OverlayState& st);

/// "-90 -> +90 deg" while a platform flips from an end stop, else its angle (deg) and state.
std::string platform_text(const OverlayState& st, int i);

/// eq. (2): r = R1 y1 - R2 y2, with R_i = Rot(a_i, plat_i) (box from sensor i), in box axes.
Eigen::Vector3d residual_dps(const Sample& s, const Eigen::Vector3d& hinge1_axis,
                             const Eigen::Vector3d& hinge2_axis);

/// Feeds the residual strip chart: the residual averaged over buckets while both platforms
/// rest, and the residual the logged true biases predict (R1 b1 - R2 b2), when the log has them.
class ResidualChart {
 public:
  /// window_s: chart width in data seconds; points: buckets per window.
  ResidualChart(const Eigen::Vector3d& hinge1_axis, const Eigen::Vector3d& hinge2_axis,
                double window_s, int points = 400);
  /// Adds one sample; `at_rest`: both platforms settled (the residual is meaningful).
  void push(const Sample& s, bool at_rest);
  const StripChart& chart() const { return chart_; }

 private:
  void flush_bucket();
  Eigen::Vector3d a1_, a2_;
  StripChart chart_;
  double bucket_s_;
  double bucket_start_s_ = kNaN;
  Eigen::Vector3d sum_r_ = Eigen::Vector3d::Zero(), sum_truth_ = Eigen::Vector3d::Zero();
  int n_r_ = 0, n_truth_ = 0;
  double last_t_s_ = kNaN;
};

/// The bias estimate of one sensor against its true bias (deg/s, sensor axes), one point per
/// bucket.
class BiasChart {
 public:
  BiasChart(int sensor, double window_s, int points = 400);
  /// est/truth: this sensor's bias, deg/s (NaN parts are skipped).
  void push(double t_s, const Eigen::Vector3d& est_dps, const Eigen::Vector3d& truth_dps);
  const StripChart& chart() const { return chart_; }

 private:
  StripChart chart_;
  double bucket_s_;
  double last_push_s_ = kNaN;
};

/// The attitude error since lock (deg): with DriftLess and with the bias fixed at lock (Fig. 9).
class AttitudeChart {
 public:
  explicit AttitudeChart(double window_s, int points = 400);
  void push(double t_s, const AttitudeNow& a);
  const StripChart& chart() const { return chart_; }

 private:
  StripChart chart_;
  double bucket_s_;
  double last_push_s_ = kNaN;
};

}  // namespace driftless::render
