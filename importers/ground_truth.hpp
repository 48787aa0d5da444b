// Ground truth made by others, to join onto an IMU recording (`driftless convert --ref`): EuRoC's
// `state_groundtruth_estimate0/data.csv` and `vicon0/data.csv` (a `#timestamp [ns]` stamp, the
// position p x y z in m, the attitude quaternion q w x y z, any further columns ignored), stamps
// kept as whole ns; and the attitude at any time by slerp between the two stamps around it.
// docs/import.md, "Ground truth".
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace driftless::importers {

/// One ground-truth row: q_ref_from_body (scalar first in the file) and the body's position in the
/// reference frame.
struct PoseStamp {
  std::int64_t t_ns = 0;  // ns, as written in the file
  Eigen::Vector3d p_ref_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_ref_from_body = Eigen::Quaterniond::Identity();
};

/// A ground-truth track: strictly increasing stamps, unit quaternions.
struct GroundTruth {
  std::string source;
  std::vector<PoseStamp> poses;
  std::int64_t median_step_ns = 0;  // ns, the regular step (median)
  std::string quaternion_order = "w x y z";  // the file's order of columns 5..8, from its header's names
};

/// Reads a EuRoC / Vicon ground-truth CSV (the quaternion's column order from the header's names:
/// EuRoC's w x y z, or x y z w and others when the names end in those letters). Throws ImportError naming the file and line: no
/// `#timestamp` header, a row with fewer than 8 fields or a non-number, a quaternion whose norm is
/// not within 0.5..1.5, a stamp that does not increase, fewer than 2 rows.
GroundTruth read_ground_truth(const std::filesystem::path& path);

/// The attitude and position at time t (s since `epoch_s`, whole seconds, as ImuBlock::t_s).
struct PoseAt {
  enum class Where { kBefore, kInside, kGap, kAfter };
  Where where = Where::kInside;      // kGap: the stamps around t are more than max_gap_ns apart
  Eigen::Quaterniond q_ref_from_body = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p_ref_m = Eigen::Vector3d::Zero();
};

/// Looks poses up at increasing times: slerp of the attitude and linear interpolation of the
/// position between the two stamps around t (the differences to the stamps formed in integer ns).
class PoseInterpolator {
 public:
  /// `max_gap_ns`: a longer step between two stamps is a gap (no pose inside it).
  PoseInterpolator(const GroundTruth& gt, std::int64_t epoch_s, std::int64_t max_gap_ns);
  /// The pose at t_s (s since the epoch); calls with decreasing t_s are allowed but slower.
  PoseAt at(double t_s);
  /// The first and last stamp in s since the epoch.
  double first_s() const;
  double last_s() const;

 private:
  const GroundTruth& gt_;
  std::int64_t epoch_ns_;
  std::int64_t max_gap_ns_;
  std::size_t k_ = 0;  // the last bracket: poses[k_] <= t < poses[k_ + 1]
};

}  // namespace driftless::importers
