// Standstill detection (docs/estimator.md section 2): decides, sample by sample, whether both
// platforms are at rest relative to the box, at which positions, and cuts the resting samples
// into the segments the filter turns into residuals. Three sources: the platform angle columns,
// the gyros alone (flips seen as a rate difference between the sensors), or a fixed schedule.
// Eigen + std only; allocates only at construction.
#pragma once

#include <cstddef>
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "estimator/box_geometry.hpp"
#include "estimator/config.hpp"
#include "estimator/sample.hpp"
#include "estimator/standstill_gyro.hpp"

namespace driftless::est {

/// Why a segment was handed to the filter.
enum class SegmentEnd : std::uint8_t {
  kMotion,   // a platform moved (or changed position): the end margin before it was dropped
  kSplit,    // a long standstill was split (max_standstill_s); the next segment continues it
  kSample,   // one committed sample (per_sample_updates)
  kFinish,   // the stream ended inside the standstill: every sample kept
};

/// Running sums of one standstill (or one piece of it). Means are sum / count.
struct StandstillSegment {
  double t_rest_s = kNaN;   // s, when both platforms came to rest
  double t_first_s = kNaN;  // s, first sample used
  double t_last_s = kNaN;   // s, last sample used
  double plat1_deg = kNaN;  // deg, positions (measured, tracked or scheduled)
  double plat2_deg = kNaN;
  std::int64_t tag = 0;     // schedule slot (standstill: schedule)
  std::size_t n = 0;        // samples used
  Eigen::Vector3d sum_gyro1_dps = Eigen::Vector3d::Zero();
  Eigen::Vector3d sum_gyro2_dps = Eigen::Vector3d::Zero();
  // specific force of the samples whose accel columns are finite (both sensors), m/s^2
  std::size_t n_accel = 0;
  Eigen::Vector3d sum_accel1_mps2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d sum_accel2_mps2 = Eigen::Vector3d::Zero();
  // the reference "up" direction in box axes, from ref_q (samples that have it)
  std::size_t n_up = 0;
  Eigen::Vector3d sum_up_box = Eigen::Vector3d::Zero();
  // temperatures of the samples where both are finite, degC
  std::size_t n_temp = 0;
  double sum_temp1_c = 0.0, sum_temp2_c = 0.0;
  SegmentEnd end = SegmentEnd::kMotion;

  Eigen::Vector3d mean_gyro1_dps() const { return sum_gyro1_dps / double(n); }
  Eigen::Vector3d mean_gyro2_dps() const { return sum_gyro2_dps / double(n); }
  /// Span of the samples used, s (0 for one sample).
  double span_s() const { return n >= 2 ? t_last_s - t_first_s : 0.0; }
};

/// What the detector made of one sample.
struct StandstillStep {
  enum class State : std::uint8_t { kMoving, kSettling, kAccumulating } state = State::kMoving;
  double plat1_deg = kNaN, plat2_deg = kNaN;  // deg, positions in force (NaN = unknown)
  bool plat1_rest = false, plat2_rest = false;  // each platform at rest with a known angle
  int closed = 0;  // segments handed over by this sample (0..2), see StandstillDetector::closed()
  // 'standstill: gyro': a platform at rest whose hinge rate has begun to rise (the start of a flip,
  // below the motion threshold): its sensor is left out of the fused box rate
  bool plat1_starting = false, plat2_starting = false;
  // both platforms move at once, so no sensor reads the box rate alone ('standstill: gyro': the
  // attitude is then unknown; platform columns: the moving sensors give it, see plat*_rate_dps)
  bool both_moving = false;
  // platform columns: each hinge rate, deg/s, such that the mean of two samples' rates is (nearly)
  // the angle change between them over their interval (the trapezoid the attitude integrator
  // applies), so a moving sensor gives the box rate M(theta) y - rate a; NaN where an angle is missing
  double plat1_rate_dps = kNaN, plat2_rate_dps = kNaN;
};

/// Streaming standstill detector. push() never throws.
class StandstillDetector {
 public:
  /// `cfg`'s standstill fields (settle_s, end_margin_s, min/max_standstill_s, angle_tolerance_deg,
  /// gyro_motion_threshold_dps, standstill_period_s, initial_plat*_deg, per_sample_updates) and
  /// the box geometry (hinges, rate, flip angle). Both were validated by the caller.
  StandstillDetector(const EstimatorConfig& cfg, const BoxGeometry& box);

  /// Consumes one sample with a finite time and finite gyros; `dt_s` is the time since the
  /// previous one (NaN for the first) and `bias1/2_dps` the filter's estimate (the gyro-only
  /// source removes it before looking for flips).
  StandstillStep push(const Sample& s, double dt_s, const Eigen::Vector3d& bias1_dps,
                      const Eigen::Vector3d& bias2_dps);
  /// The stream ended: the standstill in progress is handed over with every sample (no motion
  /// follows, so the end margin is good data). Returns the number of segments (0 or 1).
  int finish();
  /// A new source takes over: the standstill in progress is dropped, positions re-learned.
  void restart(const BoxGeometry& box);

  /// The segments handed over by the last push() or finish(): closed()[0 .. count-1].
  const StandstillSegment& closed(int i) const { return closed_[static_cast<std::size_t>(i)]; }
  /// Standstills too short to use (min_standstill_s), since construction.
  std::uint64_t too_short() const { return too_short_; }
  /// Those rests' lengths: as logged (first to last resting sample, s) and the part left once
  /// settle_s and end_margin_s are taken off (s), the longest of each and the logged mean.
  struct ShortRests {
    std::uint64_t count = 0;
    double longest_logged_s = 0.0, longest_usable_s = 0.0, sum_logged_s = 0.0;
    double mean_logged_s() const { return count > 0 ? sum_logged_s / double(count) : kNaN; }
  };
  const ShortRests& short_rests() const { return short_rests_; }
  /// A standstill was discarded by the last push()/finish() (paper mode counts it as a step).
  bool discarded_last() const { return discarded_last_; }
  /// 'standstill: gyro': flips in which both platforms moved at once, since construction.
  std::uint64_t simultaneous_flips() const { return gyro_.simultaneous_flips() + both_moving_; }
  /// 'standstill: gyro': the time gaps and each flip's measured turn (standstill_gyro.hpp).
  const GyroFlipTracker& gyro_tracker() const { return gyro_; }
  /// Platform columns: samples with both angles read after a row with both, and those in which an
  /// angle moved by more than angle_tolerance_deg but at most kAngleJitterDeg (an encoder's noise,
  /// not a flip), with the largest such change, deg.
  struct AngleJitter {
    std::uint64_t samples = 0, jittery = 0;
    double max_change_deg = 0.0;
  };
  static constexpr double kAngleJitterDeg = 0.1;
  const AngleJitter& angle_jitter() const { return jitter_; }
  /// Sample rate used for durations, Hz (the geometry's, else measured from the segment).
  double rate_hz(const StandstillSegment& seg) const;

 private:
  struct Pending {  // a resting sample inside the end margin, not yet committed
    Eigen::Vector3d y1, y2, f1, f2, up;
    double temp1, temp2, t_s;
  };
  bool classify(const Sample& s, double dt_s, StandstillStep& st);
  void note_jitter(double d1_deg, double d2_deg);
  static double hinge_rate_dps(double angle_deg, double prev_deg, double prev_rate_dps, bool rest, double dt_s);
  void schedule_positions(const Sample& s, StandstillStep& st);
  void start_segment(double t_s, double p1, double p2, std::int64_t tag);
  void end_standstill();
  void close_segment(SegmentEnd why);
  void accumulate(const Pending& p);
  void commit(const Pending& p);
  void hand_over(const StandstillSegment& seg);
  void note_short_rest(double logged_s, double usable_s);
  static Pending pending_of(const Sample& s);

  EstimatorConfig cfg_;
  BoxGeometry box_;
  StandstillSegment seg_;
  bool active_ = false;
  std::vector<Pending> ring_;  // the end margin, sized once
  std::size_t ring_head_ = 0, ring_count_ = 0, ring_capacity_ = 0;
  double prev_p1_ = kNaN, prev_p2_ = kNaN;
  double prev_rate1_dps_ = kNaN, prev_rate2_dps_ = kNaN;  // platform columns: the last hinge rates
  bool prev_both_moving_ = false;
  std::uint64_t both_moving_ = 0;  // platform columns: flips of both platforms at once
  AngleJitter jitter_;
  double sched_start_s_ = kNaN;
  GyroFlipTracker gyro_;  // positions from the gyros alone (standstill: gyro)
  std::array<StandstillSegment, 2> closed_{};
  int n_closed_ = 0;
  bool discarded_last_ = false;
  std::int64_t seg_tag_ = 0;  // schedule slot of the sample being pushed
  std::uint64_t too_short_ = 0;
  double t_rest_last_s_ = kNaN;  // s, the last resting sample of the segment in progress
  ShortRests short_rests_;
};

}  // namespace driftless::est
