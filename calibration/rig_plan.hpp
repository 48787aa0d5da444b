// The rig plan: which time span of a calibration log holds which rig segment (box orientation on
// the pan/tilt unit, platform end stops, rate table square wave). Format: docs/calibration.md.
#pragma once

#include <array>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "estimator/calibration.hpp"
#include "estimator/fields.hpp"
#include "estimator/log.hpp"

namespace driftless::calib {

inline constexpr const char* kRigPlanFormat = "driftless-rig-plan 1";

/// Box axis the table turns about in a named orientation: XY (XY plane level) -> z, YZ -> x, XZ -> y.
/// Throws std::invalid_argument on another name.
Eigen::Vector3d orientation_axis(const std::string& orientation);
/// The box attitude on the table at pan angle 0: the orientation's axis points up (ENU z).
Eigen::Quaterniond orientation_mount(const Eigen::Vector3d& axis_box);

/// One segment: the box mounted in one orientation, both platforms at an end stop, the table
/// reversing its rate every half period starting at t_start_s.
struct PlanSegment {
  std::string name;                  // unique, e.g. "XY@-90"
  std::string orientation = "XY";    // XY | YZ | XZ | custom (then axis_box is given)
  Eigen::Vector3d axis_box = Eigen::Vector3d::UnitZ();  // table axis in box axes (unit)
  double plat1_deg = -90.0;          // deg, end stop of platform 1 (-90 or +90)
  double plat2_deg = -90.0;          // deg, end stop of platform 2
  double t_start_s = 0.0;            // s, first reversal of the square wave (log time)
  double t_end_s = 60.0;             // s, end of the segment
  double rate_dps = 50.0;            // deg/s, table rate magnitude
  double half_period_s = 2.0;        // s, time between rate reversals
  double first_sign = 1.0;           // +1: the table starts at +rate_dps about axis_box
  double settle_s = 0.3;             // s, samples this soon after a reversal are not used

  /// Commanded rate sign at t (+1/-1; 0 outside [t_start_s, t_end_s)).
  double sign_at(double t_s) const;
  /// True when t lies on a plateau: inside the segment and settle_s past the last reversal.
  bool on_plateau(double t_s) const;
  /// Position index (est::kPosMinus90/kPosPlus90) of platform i (0/1).
  int position(int i) const { return est::position_index(i == 0 ? plat1_deg : plat2_deg, 1e-9); }
};

/// A whole rig plan.
struct RigPlan {
  std::vector<PlanSegment> segments;
  double gyro_full_scale_dps = 250.0;  // deg/s, sensor full scale (MPU6050 FS_SEL=0: 250)
  double max_rate_fraction = 0.8;      // the table rate may use at most this fraction of it
  double latitude_deg = driftless::kNaN;  // deg, overrides the log's latitude when set
  /// Throws std::invalid_argument naming the segment and key: positions not +-90, times out of
  /// order or overlapping, a rate table that saturates the gyro, unknown orientation.
  void validate() const;
};

/// The procedure of paper section 4 as a rig plan: both sensors at -90, the box in XY, YZ, XZ,
/// each for segment_s of +-rate_dps; then the same at +90. `gap_s` between segments (remounting).
struct ProcedureParams {
  double rate_dps = 50.0;        // deg/s
  double segment_s = 60.0;       // s, square wave length per orientation
  double half_period_s = 2.0;    // s
  double settle_s = 0.3;         // s
  double gap_s = 4.0;            // s, time between segments (remounting / flipping), box at rest
  double start_s = 2.0;          // s, rest before the first segment
  std::vector<std::string> orientations{"XY", "YZ", "XZ"};
  double gyro_full_scale_dps = 250.0;
  void validate() const;
};
RigPlan standard_plan(const ProcedureParams& p);

/// Reads a plan from a parsed YAML document (throws InputError naming `file`, line and key).
RigPlan read_rig_plan(const fields::Node& root, const std::string& file);
/// Reads a plan from YAML text (`file` names it in errors).
RigPlan parse_rig_plan(const std::string& yaml_text, const std::string& file);
RigPlan load_rig_plan(const std::filesystem::path& path);
/// The plan as YAML text (load_rig_plan reads it back).
std::string rig_plan_yaml(const RigPlan& plan);
/// Writes rig_plan_yaml(plan) to `path`.
void save_rig_plan(const std::filesystem::path& path, const RigPlan& plan);

/// The rows a plan segment and a calib.yaml segment share, in this order: plat1_deg, plat2_deg
/// (deg), t_start_s, t_end_s (s), rate_dps (deg/s). `seg` gives the PlanSegment inside a T.
template <class T, class Seg>
void append_span_rows(fields::Table<T>& rows, Seg seg) {
  using S = PlanSegment;
  const auto field = [seg](double S::*m) {
    return [seg, m](auto& t) -> auto& { return std::invoke(seg, t).*m; };
  };
  rows.push_back(fields::number<T>("plat1", "deg", field(&S::plat1_deg)));
  rows.push_back(fields::number<T>("plat2", "deg", field(&S::plat2_deg)));
  rows.push_back(fields::number<T>("t_start", "s", field(&S::t_start_s)));
  rows.push_back(fields::number<T>("t_end", "s", field(&S::t_end_s)));
  rows.push_back(fields::number<T>("rate", "dps", field(&S::rate_dps)));
}

/// What extract_segments found.
struct ExtractReport {
  bool earth_rate_removed = false;  // ref_q and a latitude were available
  double latitude_deg = driftless::kNaN;
  double sample_rate_hz = driftless::kNaN;
  std::vector<std::size_t> samples_used;  // per segment
  std::size_t rows_skipped_nan = 0;
  std::array<double, 2> mean_temp_c{driftless::kNaN, driftless::kNaN};
  std::vector<std::string> notes;         // non-fatal remarks for the user
};

/// Checks a log against the plan and cuts it into fit segments (plateau samples only).
/// Throws std::invalid_argument "plan does not match the log" naming the segment when: a segment
/// lies outside the log; plat*_deg disagrees with the plan's end stops; ref_q shows another
/// turn axis or rate; a sensor's output does not follow the planned square wave; the gyro
/// saturates. `hinge*` are the platform axes (box frame) from the log's metadata.
std::vector<est::CalibSegment> extract_segments(const std::vector<Sample>& log,
                                                const log::Metadata& meta, const RigPlan& plan,
                                                const std::string& log_name,
                                                ExtractReport* report = nullptr);

}  // namespace driftless::calib
