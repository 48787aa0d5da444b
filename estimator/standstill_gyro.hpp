// Platform positions from the gyros alone ('standstill: gyro', hardware without angle read-back),
// docs/estimator.md section 2. Each sensor's reading turned into box axes at its platform's last
// rest position, r_i = M_i y_i, agrees with the other's at rest (both read the box rate plus their
// biases). A platform i that turns by theta about its hinge a_i adds theta' a_i to its own r_i
// and nothing else along a_i (a turn about a_i keeps the a_i component of the box rate), so
//   (r1 - r2 - rest level) . a1 = theta1'   while platform 2 rests, whatever the box does,
// and the other platform's sensor then reads the box rate alone. Which platform started is told
// by splitting the difference along a1 and a2; a flip ends when its hinge rate stays below the
// threshold, and the platform's new position is its integrated turn snapped to the nearer stop.
// When both platforms move at once no sensor reads the box rate: the tracker says so (the
// attitude cannot be made then) and follows both turns from a least-squares fit of the box rate
// and both hinge rates to the six readings.
// Two things the gyros can tell about the configuration and the log: each flip's measured turn
// (a flip between +-f turns 2f; a turn unlike 2 flip_angle_deg is counted, its size kept), and a
// time gap (sample.hpp), in which a flip may have been lost: the positions are then unknown until
// a rest where exactly one of the four position pairs makes M1 (y1 - b1) - M2 (y2 - b2) vanish
// (on a turning box the wrong pairs leave (M M'^T - I) w; on a still one all fit: not recovered).
// A log that starts during a flip (the two sensors' rate norms differ by more than the threshold
// at the first sample) takes no rest level until the flip has ended; the platform then rests at
// the stop its turn went towards (start()).
// Eigen + std only; push() never throws nor allocates.
#pragma once

#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "estimator/box_geometry.hpp"
#include "estimator/sample.hpp"

namespace driftless::est {

/// Where the platforms are and which of them rest, from the two gyros' readings.
class GyroFlipTracker {
 public:
    // kUnknown: after a time gap, until the positions are recovered (no platform counts as resting)
  enum class Motion : std::uint8_t { kRest, kPlatform1, kPlatform2, kBoth, kUnknown };

  /// The first time gap and what became of the positions after it.
  struct GapRecord {
    std::uint64_t count = 0;       // gaps seen
    double t_s = kNaN;             // s, the sample before the first gap
    double length_s = kNaN;        // s, its length
    std::uint64_t recovered = 0;   // gaps after which the positions were found again
    std::uint64_t changed = 0;     // ... and differed from those before the gap (a flip was lost)
    double recovered_t_s = kNaN;   // s, when the positions after the first gap were found
  };
  /// A log that starts during a flip: the rest level is not taken while a platform turns (it
  /// would read the turn as the level); the positions are unknown until the first quiet interval.
  struct StartRecord {
    bool mid_flip = false;         // the log started while a platform turned
    int platform = 0;              // 1 or 2: the one that turned at the first sample
    double rate_dps = kNaN;        // deg/s, its hinge rate (a_i . (y_i - b_i)) at the first sample
    double t_first_s = kNaN;       // s, the first sample
    double t_known_s = kNaN;       // s, when the positions became known (the flip had ended)
    double position_deg = kNaN;    // deg, where its turn took it (the stop it turned towards)
    std::array<double, 2> positions_deg{kNaN, kNaN};  // deg, both platforms' from t_known_s
  };
  /// Flips whose measured turn is unlike 2 flip_angle_deg (count) and the mean half-turn, deg.
  struct FlipAngleRecord {
    std::uint64_t flips = 0, unlike = 0;
    double measured_flip_angle_deg = kNaN;  // |turn| / 2 of the first unlike flip
  };

  /// `threshold_dps`: a hinge rate above this is a platform moving (gyro_motion_threshold_dps);
  /// `p1_deg`/`p2_deg`: the positions at the start (initial_plat*_deg).
  GyroFlipTracker(const BoxGeometry& box, double threshold_dps, double p1_deg, double p2_deg);
  /// A new source: the motion and the rest level are forgotten, the positions kept. A source
  /// that starts during a flip waits for the flip to end (start()); its first record is kept.
  void restart(const BoxGeometry& box);

  /// One sample: raw readings y1/y2 (deg/s, sensor axes), the filter's bias estimate b1/b2 and
  /// the time since the previous sample (NaN for the first).
  /// `t_s` (optional) dates the gaps.
  void push(const Eigen::Vector3d& y1, const Eigen::Vector3d& y2, const Eigen::Vector3d& b1,
            const Eigen::Vector3d& b2, double dt_s, double t_s = kNaN);

  Motion motion() const { return motion_; }
  /// Platform `i` (1 or 2) at rest at position_deg(i).
  bool rest(int i) const;
  /// Platform `i` rests by the threshold, but its hinge rate already exceeds a fifth of it while
  /// the other's does not: the start of a flip, which the fused box rate leaves out (a raised-
  /// cosine 180 deg flip of 1 s turns 0.06 deg before reaching 5 deg/s, 0.005 deg before 1 deg/s).
  bool starting(int i) const { return motion_ == Motion::kRest && starting_ == i; }
  /// Position of platform `i` at its last rest, deg (the new one once its flip has ended).
  double position_deg(int i) const { return i == 1 ? p1_ : p2_; }
  /// Flips in which both platforms moved at once (counted when they began).
  std::uint64_t simultaneous_flips() const { return simultaneous_; }
  const GapRecord& gaps() const { return gap_; }
  const FlipAngleRecord& flip_angles() const { return angles_; }
  const StartRecord& start() const { return start_; }

 private:
  Eigen::Vector3d rest_difference(const Eigen::Vector3d& y1, const Eigen::Vector3d& y2) const;
  void start_motion(const Eigen::Vector2d& u);
  void track_one(const Eigen::Vector3d& diff, const Eigen::Vector3d& y1, const Eigen::Vector3d& y2,
                 const Eigen::Vector3d& b1, const Eigen::Vector3d& b2, double dt_s);
  void track_both(const Eigen::Vector3d& y1, const Eigen::Vector3d& y2, const Eigen::Vector3d& b1,
                  const Eigen::Vector3d& b2, double dt_s);
  void end_motion(const Eigen::Vector3d& y1, const Eigen::Vector3d& y2);
  void note_turn(double turn_deg);
  void start_gap(double dt_s, double t_s);
  void seek_positions(const Eigen::Vector3d& y1, const Eigen::Vector3d& y2, const Eigen::Vector3d& b1,
                      const Eigen::Vector3d& b2, double t_s);
  int quiet_samples() const;
  bool begin_start(const Eigen::Vector3d& y1, const Eigen::Vector3d& y2, const Eigen::Vector3d& b1,
                   const Eigen::Vector3d& b2, double t_s);
  void step_start(const Eigen::Vector3d& y1, const Eigen::Vector3d& y2, const Eigen::Vector3d& b1,
                  const Eigen::Vector3d& b2, double dt_s, double t_s);

  BoxGeometry box_;
  double thr_dps_;
  double p1_, p2_;                 // deg, positions at the last rest
  Motion motion_ = Motion::kRest;
  bool have_level_ = false;
  Eigen::Vector3d level_ = Eigen::Vector3d::Zero();  // deg/s, rest level of r1 - r2 (M1 b1 - M2 b2)
  Eigen::Matrix<double, 2, 3> split_ = Eigen::Matrix<double, 2, 3>::Zero();  // r1 - r2 -> (u1, u2)
  bool can_split_ = false;         // the hinges are far enough from parallel to tell them apart
  double turn1_deg_ = 0.0, turn2_deg_ = 0.0;  // deg, since the motion began
  int quiet_ = 0;
  int starting_ = 0;               // 1 or 2: that platform's hinge rate is above a fifth of the threshold
  std::uint64_t simultaneous_ = 0;
  GapRecord gap_;
  FlipAngleRecord angles_;
  // the start (kUnknown, starting_up_): the first sample of a source is taken as a rest only when
  // the two sensors' rate norms agree within the threshold; else the norms' difference must stay
  // within the threshold of its running mean for quiet_samples() (the flip has ended)
  bool fresh_ = true, starting_up_ = false;
  double norm_diff0_dps_ = kNaN, norm_diff_sum_dps_ = 0.0;
  int norm_diff_n_ = 0;
  Eigen::Vector2d rate0_dps_ = Eigen::Vector2d::Zero(), start_turn_deg_ = Eigen::Vector2d::Zero();
  StartRecord start_;
  // kUnknown: the four position pairs' differences summed over a block of quiet_samples()
  std::array<Eigen::Vector3d, 4> seek_sum_{};
  int seek_n_ = 0;
  double p1_before_gap_ = kNaN, p2_before_gap_ = kNaN;
};

}  // namespace driftless::est
