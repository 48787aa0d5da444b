// The flip-turn check (docs/estimator.md section 6.4): over each flip of one platform, the
// moving sensor's bias-corrected rate minus the resting sensor's turned into the moving sensor's
// axes, integrated, is the platform's turn relative to the box: Δθ a_m (a_m its hinge in its own
// sensor axes; the box's own rate about the hinge cancels exactly, a turn about a_m keeps a_m).
// Its size and axis against the angle columns' Δθ give away what no bias update can: gyro columns
// in rad/s (ratio 1/57.3), angle columns in radians (57.3), stamps in ms or µs (1e3, 1e6), a
// platform that stuck while its angle column says it flipped (≈ 0), the angle sign (−1), a wrong
// hinge line or swapped sensor columns (another axis), a scale error along the hinge (1 ± a few
// %), flips slower than flip_max_s (the self-calibration's flip updates drop them) and platforms
// that always turn the same way with the angle wrapped at ±180° (handled: a note). A flip in which a
// gyro clipped (an MPU6050's ±250 deg/s in a 1 s flip) still shows the turn's axis and sign (the clip
// only shortens the clipped channel, whose sign stays): it is judged for those, not for the scale.
// Eigen + std only; push() allocates only when a flip ends (one record).
//
// The sums are linear in the readings: with C0 = M_m0^T M_s (resting sensor to moving sensor at
// its start angle, constant over the flip), sum (y_m - C0 y_s) dt = S_m - C0 S_s, so the check
// keeps S_1 and S_2 and decides which platform moved when the flip ends.
//
// The biases are taken from the rest just before the flip, not from the filter: there the same
// difference reads ȳ_m - C0 ȳ_s = b_m - C0 b_s (the box's rate cancels exactly, as in the flip), so
// v = (S_m - T ȳ_m) - C0 (S_s - T ȳ_s) over the window's T. The filter's estimate can be far off in
// a direction its updates do not observe (uncalibrated MPU6050 on paper_fig4: b1_z + b2_y kept its
// 14 deg/s prior when the g-sensitivity's rejections left two position pairs out), and that error
// times the flip's ~2 s read as a "scale error" of +17.5 % along hinge 1 whose truth is +0.5 %.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "estimator/clip_detector.hpp"
#include "estimator/sample.hpp"

namespace driftless::est {

/// What one flip's gyro turn says about the angle column's Δθ.
enum class FlipTurn : std::uint8_t {
  kAgrees,        // |turn/Δθ − 1| <= kFlipTurnTolerance, about the hinge
  kGyroRadPerS,   // turn/Δθ ≈ π/180: the gyro columns are in rad/s
  kAngleRadians,  // turn/Δθ ≈ 180/π: the angle columns are in radians
  kTimeMs,        // turn/Δθ ≈ 1e3: the stamps are in ms
  kTimeUs,        // turn/Δθ ≈ 1e6: the stamps are in µs
  kStuck,         // |turn| < kFlipTurnTolerance |Δθ|: the platform did not turn
  kSign,          // turn/Δθ ≈ −1: the angle columns count against the right-hand rule
  kWrapped,       // turn/Δθ ≈ −1 on a platform whose every flip turned the same way: wrapped at ±180
  kSwapped,       // the resting sensor's column turned about the moving hinge: gyro columns swapped
  kAxis,          // turned, but about another axis than the header's hinge
  kOther,         // about the hinge, by a ratio none of the above
};
inline constexpr int kFlipTurnKinds = 11;

/// A ratio within this fraction of its expected value matches it (as flip_rows()' 20 % test).
inline constexpr double kFlipTurnTolerance = 0.2;
/// The measured axis "is" the hinge when their angle is below acos of this (30 deg).
inline constexpr double kFlipAxisCos = 0.866;
inline constexpr double kFlipAxisTan = 0.577;  // tan 30 deg: the same bound as a turn across the hinge

/// One flip as the check measured it.
struct FlipTurnRecord {
  int platform = 0;            // 1 or 2
  double t_start_s = kNaN;     // s, the last sample at rest before the flip
  double duration_s = kNaN;    // s, from there to the first sample at rest after it
  double window_s = kNaN;      // s, the integrated window (duration and the settle time)
  double dtheta_deg = kNaN;    // the angle column's change (as read)
  double turn_deg = kNaN;      // the gyro turn about the hinge (a_m . v)
  double ratio = kNaN;         // turn_deg / dtheta_deg
  Eigen::Vector3d axis_sensor = Eigen::Vector3d::Zero();  // unit turn axis, moving sensor axes, sign of Δθ
  Eigen::Vector3d hinge_sensor = Eigen::Vector3d::Zero(); // the header's hinge in the same axes
  FlipTurn kind = FlipTurn::kAgrees;
  // a gyro clipped in the window: its turn reads short, so only the axis, the sign, the swap and
  // the units (a ratio beyond 1, which no clip gives) are judged; its ratio stays out of the scale
  bool clipped = false;
};

/// One platform's flips, summed up.
struct PlatformFlipSummary {
  std::uint64_t flips = 0;
  std::array<std::uint64_t, kFlipTurnKinds> count{};        // by FlipTurn
  std::array<double, kFlipTurnKinds> first_t_s{};           // s, the first of each kind (NaN: none)
  std::array<double, kFlipTurnKinds> median_ratio{};        // turn/Δθ, median over each kind (kAgrees:
                                                            // the flips without a clip, scale_flips)
  // the median's standard error from the ratios' spread (1.2533 x 1.4826 MAD / sqrt(n); NaN below 3)
  std::array<double, kFlipTurnKinds> median_ratio_sigma{};
  Eigen::Vector3d axis_sensor = Eigen::Vector3d::Zero();    // kAxis: mean measured axis (unit)
  Eigen::Vector3d hinge_sensor = Eigen::Vector3d::Zero();   // the header's hinge, sensor axes
  std::uint64_t slower_than_max = 0;                        // flips longer than flip_max_s
  std::uint64_t clipped = 0;                                // flips measured with a clip (axis and sign)
  std::uint64_t scale_flips = 0;                            // agreeing flips without a clip
  // s/deg, the largest window / |Δθ|: a rate error of x deg/s that the rest before a flip does not
  // give (a g-sensitivity term changing as the platform turns) moves its ratio by up to x times this
  double rate_to_ratio_s_per_deg = 0.0;
  double longest_s = 0.0;                                   // s, the longest flip
  std::uint64_t of(FlipTurn k) const { return count[static_cast<int>(k)]; }
};

/// The check at the end of a pass.
struct FlipCheckResult {
  std::array<PlatformFlipSummary, 2> platform;  // [0]: platform 1
  std::uint64_t flips = 0;                      // flips of one platform with both angles read
  std::uint64_t windows = 0;                    // motion between two rests with both angles read (any)
  std::uint64_t disagree = 0;                   // flips whose kind is neither kAgrees nor kWrapped
  std::uint64_t clipped = 0;                    // flips in which a gyro clipped (judged for axis and sign)
  // of those, flips left out: clipped so that their turn reads below kFlipTurnTolerance of Δθ, or
  // not about any axis the check can name (then nothing about the hinge can be said from them)
  std::uint64_t clipped_unusable = 0;
  double flip_max_s = kNaN;                     // s, the configured limit (slower_than_max)
};

/// Fed each sample of the estimate pass; finish() sums the flips up.
/// s: the rest mean before a flip weighs the last this many seconds (a bias's slow drift over a long
/// rest stays out; the white noise it averages is below 0.01 deg/s on an MPU6050 at 100 Hz)
inline constexpr double kRestMeanS = 10.0;

class FlipCheck {
 public:
  /// `settle_s`: integrate on this long after both rest again (a sensor's low-pass filter still
  /// releases the end of the turn then, as in the flip updates' window)
  FlipCheck(double flip_max_s, double settle_s) : flip_max_s_(flip_max_s), settle_s_(settle_s) {}
  /// Where the platforms' hinges are: body-from-sensor matrices at the flip's start angles.
  struct Frames {
    Eigen::Matrix3d M1_start, M2_start;   // sensor 1 / 2 at its angle before the flip
    Eigen::Vector3d hinge1_box, hinge2_box;
  };
  /// One sample: its time, the readings as logged (deg/s, sensor axes, NaN = invalid: no bias
  /// correction is needed, the rest before each flip gives it), the platform angles in force and
  /// whether both platforms rest. Returns true when a window just closed on a flip of exactly one
  /// platform: call close() with its frames.
  bool push(double t_s, const Eigen::Vector3d& y1_dps, const Eigen::Vector3d& y2_dps, double plat1_deg,
            double plat2_deg, bool both_rest);
  /// The platform angles at the start of the flip that push() just closed.
  double start_deg(int platform) const { return platform == 1 ? p1_start_ : p2_start_; }
  /// Measures the flip push() just closed (frames at its start angles).
  void close(const Frames& f);
  FlipCheckResult finish() const;
  const std::vector<FlipTurnRecord>& records() const { return records_; }

 private:
  double flip_max_s_, settle_s_;
  double t_back_s_ = kNaN;  // s, when both rested again (the settle time runs from there)
  bool was_rest_ = false, open_ = false;
  double t_last_s_ = kNaN, t_rest_s_ = kNaN, p1_rest_ = kNaN, p2_rest_ = kNaN;
  double p1_start_ = kNaN, p2_start_ = kNaN, p1_end_ = kNaN, p2_end_ = kNaN, t_start_s_ = kNaN, t_end_s_ = kNaN;
  Eigen::Vector3d s1_ = Eigen::Vector3d::Zero(), s2_ = Eigen::Vector3d::Zero();  // deg, integrated readings
  double window_s_ = 0.0;  // s, the window's length (the sum of its steps)
  // deg/s, the readings' mean over the current rest (a running mean, exponential after kRestMeanS)
  // and frozen at the flip's start; rest_n_: the rest's samples so far
  Eigen::Vector3d rest1_ = Eigen::Vector3d::Zero(), rest2_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d start_rest1_ = Eigen::Vector3d::Zero(), start_rest2_ = Eigen::Vector3d::Zero();
  double rest_n_ = 0.0;
  void rest_sample(const Eigen::Vector3d& y1_dps, const Eigen::Vector3d& y2_dps, double dt_s);
  std::vector<FlipTurnRecord> records_;
  ClipDetector clip_;             // the window's readings (a clipped flip reads short: axis and sign only)
  bool window_clipped_ = false;   // the flip push() just closed had a clip in it
  std::uint64_t clipped_ = 0, clipped_unusable_ = 0, windows_ = 0;
};

/// The kind of one flip from its sums (pure; exposed for the tests): `v` = S_m − C0 S_s and
/// `w` = S_s − C0^T S_m in the moving / resting sensor axes (deg), `a` the moving hinge in the
/// moving sensor's axes (unit), `dtheta_deg` the angle columns' change, `moving_raw_deg` and
/// `resting_raw_deg` the norms |S_m| and |S_s| (each column's own turn, box turn included),
/// `clipped` a gyro clipped in the window (the turn may then be cut short, never lengthened).
FlipTurn classify_flip(const Eigen::Vector3d& v, const Eigen::Vector3d& w, const Eigen::Vector3d& a, double dtheta_deg,
                       double moving_raw_deg, double resting_raw_deg, bool clipped);

}  // namespace driftless::est
