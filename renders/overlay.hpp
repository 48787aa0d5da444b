// What the overlay says: time, platform state and next flip, attitude error, and a strip chart of
// the residual (paper eq. (2)) against the residual the true biases predict.
#pragma once

#include <string>

#include <Eigen/Core>

#include "estimator/sample.hpp"
#include "renders/scene_renderer.hpp"
#include "renders/timeline.hpp"

namespace driftless::render {

/// Per-sample overlay state, taken when the sample is read (frames may show it later).
struct OverlayState {
  double plat_deg[2] = {kNaN, kNaN};
  bool moving[2] = {false, false};
  double next_flip_s = kNaN;   // predicted start of the next flip, s
  int next_platform = -1;      // 0/1, -1 unknown
  double attitude_error_deg = kNaN;  // angle between an attitude estimate and ref_q, deg
};

/// Snapshot of a tracker (fed the same sample) for the overlay.
OverlayState overlay_state(const PlatformTracker& tracker);

/// Text for one frame. speed: data s per video s; realtime_flip: a flip shown at x1.
OverlayText overlay_text(const std::string& title, double t_s, double speed, bool realtime_flip,
                         const OverlayState& st);

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

}  // namespace driftless::render
