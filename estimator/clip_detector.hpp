// Suspected clipping in a gyro log that states no full scale (docs/log-format.md, "Saturation";
// docs/estimator.md section 6.1, cause `saturation`). A gyro driven past its range repeats one
// value, its largest, for as long as the rate stays beyond it; a rate that only passes through its
// extreme, with noise on it, does not repeat it in runs. So a channel whose largest |reading| comes
// in runs of identical values is taken to saturate there. Eigen + std only.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

namespace driftless::est {

/// A channel that repeats its largest reading in runs: where it clips, and how often.
struct ClippedChannel {
  int channel = 0;               // 0..5 = gyro1_x .. gyro2_z
  double level_dps = 0.0;        // deg/s, the repeated |reading|
  std::uint64_t samples = 0;     // samples in runs of at least kMinRun at that level
  std::uint64_t samples_at_rest = 0;  // of those, while both platforms rested (or unknown)
};

/// A channel with no information: empty (NaN) in every row, or one value in every row while
/// another channel of the same sensor varies (a dead axis, a column-name typo, a stuck register).
struct DeadChannel {
  enum class Kind { kEmpty, kStuck } kind = Kind::kEmpty;
  int channel = 0;               // 0..5 = gyro1_x .. gyro2_z
  double value_dps = 0.0;        // kStuck: the one value it reads
  std::uint64_t rows = 0;        // rows seen
};

/// Watches the six gyro channels sample by sample (constant memory, a few compares a sample).
class ClipDetector {
 public:
  /// A level below this is not taken for a gyro's range (the smallest MEMS ranges are +-125 deg/s;
  /// a noise-free simulated log that holds one rate would otherwise look clipped).
  static constexpr double kMinLevelDps = 50.0;
  /// Identical readings in a row that count as a plateau (quantised noise at its largest value
  /// repeats twice now and then; three times at the extreme is a run of about 1e-12 per sample).
  static constexpr int kMinRun = 3;
  /// Plateau samples a channel needs before it is reported.
  static constexpr std::uint64_t kMinSamples = 10;

  /// One reading of channel 0..5 in deg/s (NaN: missing, ends a run); `platforms_resting`: both
  /// platforms at rest in this row (true when the log does not say), so a clip inside a
  /// standstill, which the bias updates average, is told from one during a flip.
  void push(int channel, double v_dps, bool platforms_resting);
  /// The channels whose largest |reading| came in runs, in channel order.
  std::vector<ClippedChannel> suspected() const;
  /// Rows a stuck channel needs before it is reported (a short log may hold one rate exactly).
  static constexpr std::uint64_t kMinStuckRows = 100;
  /// The dead channels (DeadChannel), in channel order; `channels`: 3 (one sensor) or 6.
  std::vector<DeadChannel> dead(int channels = 6) const;

 private:
  struct Channel {
    double max_abs_dps = 0.0;
    double run_value_dps = std::numeric_limits<double>::quiet_NaN();
    int run = 0;
    std::uint64_t plateau = 0;  // samples in runs >= kMinRun at max_abs_dps
    std::uint64_t plateau_at_rest = 0;
    int run_at_rest = 0;        // of the current run, samples with the platforms at rest
    std::uint64_t rows = 0, finite = 0;
    double first_dps = std::numeric_limits<double>::quiet_NaN();  // first finite reading
    bool varies = false;        // a finite reading other than the first
  };
  std::array<Channel, 6> ch_{};
};

}  // namespace driftless::est
