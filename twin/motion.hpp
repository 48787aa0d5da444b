// The motion library: how the box moves through the local ENU frame (static, pan/tilt, ground
// vehicle, ship, CSV/EuRoC trajectories). A motion is a pure function of time; derivatives come
// from the pose (analytic pose, numeric derivatives) so every motion obeys the same kinematics.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "twin/world.hpp"

namespace driftless::twin {

/// Box pose at one instant: position/attitude in ENU and their derivatives.
struct MotionState {
  Eigen::Vector3d p_enu_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_enu_from_body = Eigen::Quaterniond::Identity();
  Eigen::Vector3d v_enu_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d a_enu_mps2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d w_body_radps = Eigen::Vector3d::Zero();     // box rate w.r.t. ENU, box axes
  Eigen::Vector3d dw_body_radps2 = Eigen::Vector3d::Zero();   // its time derivative, box axes
};

/// A box trajectory. Implementations give the pose; at() adds the derivatives.
class Motion {
 public:
  virtual ~Motion() = default;
  /// Position (ENU, m) and attitude q_enu_from_body at time t (s).
  virtual void pose(double t_s, Eigen::Vector3d& p_enu_m, Eigen::Quaterniond& q_enu_from_body) const = 0;
  /// True when the box never moves (the simulator may then skip physics at standstill).
  virtual bool is_static() const { return false; }
  /// What carries the box in renders.
  virtual Carrier carrier() const = 0;
  /// Pose and derivatives at t: central differences of pose() (O(h^2), h = 0.1 ms for rates,
  /// 2 ms for accelerations), exact zeros for a static motion; motions in closed form (the
  /// ground vehicle) give their exact derivatives instead.
  virtual MotionState at(double t_s) const;
};

/// A box standing still (the paper's 14 h static test), on the pan/tilt pedestal.
struct StaticMotionParams {
  Eigen::Vector3d attitude_ypr_deg = Eigen::Vector3d::Zero();  // yaw (about up), pitch, roll; ZYX, deg
  Eigen::Vector3d position_m{0, 0, 0.772};                     // ENU, m (on the pan/tilt head)
  void validate() const;
};

/// The paper's lab pan/tilt unit, driven by a random but known (seeded) pattern of moves:
/// each axis moves to a random angle at a random rate (<= max_rate_dps) with trapezoidal rate
/// profiles, then dwells. Box attitude: q = Rz(pan) Rx(tilt) q_mount.
struct PanTiltParams {
  double max_rate_dps = 50.0;       // peak rate of a move, deg/s (paper: 50 deg/s)
  double min_rate_dps = 10.0;       // slowest move, deg/s
  double accel_dps2 = 200.0;        // rate ramp, deg/s^2
  double pan_range_deg = 170.0;     // |pan| limit, deg
  double tilt_range_deg = 60.0;     // |tilt| limit, deg
  double dwell_min_s = 1.0;         // pause after a move, s (uniform in [min, max])
  double dwell_max_s = 5.0;
  Eigen::Vector3d mount_ypr_deg = Eigen::Vector3d::Zero();  // box on the tilt head (XY/YZ/XZ), deg
  void validate() const;
};

/// A car driving on flat ground: stops, accelerations, cruises, constant-speed turns, road bumps
/// (heave and pitch as the axles pass) and engine/road vibration. Seeded, known pattern.
struct GroundVehicleParams {
  double max_speed_mps = 15.0;         // m/s
  double max_accel_mps2 = 2.5;         // longitudinal, m/s^2
  double max_yaw_rate_dps = 25.0;      // deg/s
  double max_lateral_accel_mps2 = 3.0; // limits the turn rate at speed, m/s^2
  double stop_probability = 0.15;      // chance that a leg ends in a stop
  double bumps_per_km = 30.0;          // mean bump density, 1/km
  double bump_height_m = 0.03;         // peak body lift of a bump (each 30..100 %, 1.5..4 m long), m
  double wheelbase_m = 2.7;            // m
  double vibration_deg = 0.03;         // attitude vibration amplitude at max speed, deg
  double vibration_heave_m = 0.0008;   // vertical vibration amplitude at max speed, m
  double idle_vibration_deg = 0.005;   // engine vibration at standstill, deg
  double heading_deg = 0.0;            // initial heading, deg from east (ENU yaw)
  void validate() const;
};

/// A ship under way: constant course and speed with wave-driven roll, pitch, yaw and heave.
struct ShipParams {
  double speed_mps = 6.0;              // m/s
  double course_deg = 30.0;            // deg from east (ENU yaw)
  double roll_amplitude_deg = 6.0;     // deg
  double roll_period_s = 9.0;          // s
  double pitch_amplitude_deg = 2.0;    // deg
  double pitch_period_s = 6.5;         // s
  double yaw_amplitude_deg = 1.5;      // deg
  double yaw_period_s = 14.0;          // s
  double heave_amplitude_m = 0.6;      // m
  double heave_period_s = 8.0;         // s
  void validate() const;
};

/// A recorded trajectory: CSV with t (s), px, py, pz (m, ENU), qw, qx, qy, qz (q_enu_from_body),
/// or the EuRoC MAV ground-truth layout (#timestamp [ns], p_RS_R_x [m], ..., q_RS_w [], ...).
/// Position: Catmull-Rom cubic; attitude: slerp. Before the first / after the last row: held.
struct CsvMotionParams {
  std::string file;                    // path, relative to the scenario file's folder
  double time_offset_s = 0.0;          // simulation t = 0 maps to this trajectory time, s
  void validate() const;
};

enum class MotionType { static_box, pan_tilt, ground_vehicle, ship, csv };
/// YAML name of a motion type ("static", "pan_tilt", ...).
const char* motion_type_name(MotionType t);

/// The scenario's `motion:` block: the type and every type's parameters.
struct MotionConfig {
  MotionType type = MotionType::static_box;
  StaticMotionParams static_box;
  PanTiltParams pan_tilt;
  GroundVehicleParams ground_vehicle;
  ShipParams ship;
  CsvMotionParams csv;
  void validate() const;  // validates the selected type's parameters
};

/// One row of a recorded trajectory.
struct TrajectoryPoint {
  double t_s = 0;
  Eigen::Vector3d p_enu_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_enu_from_body = Eigen::Quaterniond::Identity();
};

/// Reads a trajectory CSV (our layout or EuRoC's); errors name the file and line.
std::vector<TrajectoryPoint> read_trajectory_csv(const std::filesystem::path& path);

/// Builds the motion of `cfg` for a run of `duration_s` seconds; `seed` draws random patterns;
/// `base_dir` resolves a relative CSV path.
std::unique_ptr<Motion> make_motion(const MotionConfig& cfg, double duration_s, std::uint64_t seed,
                                    const std::filesystem::path& base_dir = {});

/// A trajectory from points (t strictly increasing), interpolated as for CSV files.
std::unique_ptr<Motion> make_trajectory_motion(std::vector<TrajectoryPoint> points,
                                               double time_offset_s = 0.0);

/// q_enu_from_body from yaw, pitch, roll (ZYX, rad).
Eigen::Quaterniond quat_from_ypr(double yaw_rad, double pitch_rad, double roll_rad);

}  // namespace driftless::twin
