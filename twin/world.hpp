// The MuJoCo world of the DriftLess box: model loading (MJCF patched from BoxParams), RAII
// ownership of mjModel/mjData, named handles, the motion driver and posing for rendering.
// The model is described in docs/model.md; frames: world = local ENU, body = box.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <mujoco/mujoco.h>

namespace driftless::twin {

/// Piezo drive of one platform: a torque-limited position servo on a speed- and
/// acceleration-limited reference (the motor model; see docs/model.md).
struct MotorParams {
  double max_speed_dps = 120.0;        // reference speed limit, deg/s
  double max_accel_dps2 = 1200.0;      // reference acceleration limit, deg/s^2
  double kp_nm_per_rad = 0.08;         // servo stiffness, N m/rad
  double kv_nms_per_rad = 0.0025;      // servo damping, N m s/rad
  double stall_torque_nm = 0.02;       // torque limit, N m
  double rotor_inertia_kgm2 = 2e-5;    // reflected drive inertia (MuJoCo armature), kg m^2
  double damping_nms_per_rad = 1e-5;   // joint viscous damping, N m s/rad
  double overtravel_deg = 3.0;         // reference goes this far past an end stop (presses on it), deg

  /// Throws std::invalid_argument naming the field on a bad value.
  void validate() const;
};

/// Geometry and drives of the box (the scenario's `model.box` block).
struct BoxParams {
  Eigen::Vector3d hinge1_axis = Eigen::Vector3d::UnitZ();  // platform 1 hinge, box axes (unit)
  Eigen::Vector3d hinge2_axis = Eigen::Vector3d::UnitX();  // platform 2 hinge, box axes (unit)
  double end_stop_deg = 90.0;               // nominal end-stop angle, deg (stops at +/-)
  Eigen::Vector2d stop1_error_deg{0, 0};    // platform 1 stop errors [at -stop, at +stop], deg
  Eigen::Vector2d stop2_error_deg{0, 0};    // platform 2 stop errors [at -stop, at +stop], deg
  double stop_timeconst_s = 0.005;          // end-stop contact time constant (MuJoCo solref), s
  double stop_dampratio = 0.7;              // end-stop damping ratio, >= 0.5 (lower: chatter on the stop)
  MotorParams motor;

  /// Throws std::invalid_argument naming the field on a bad value.
  void validate() const;
  /// Hinge axis of platform i (1 or 2), unit length.
  Eigen::Vector3d hinge_axis(int i) const;
  /// True stop angle of platform i (1 or 2) on side sign (+1/-1), rad: nominal + its error.
  double stop_rad(int i, int sign) const;
};

/// What visibly carries the box in renders (physics ignores it: the motion drives the box).
enum class Carrier { none, pan_tilt, vehicle, ship };
const char* carrier_name(Carrier c);

/// The MJCF text of the box model with `box` applied (hinge axes, stops, motor gains).
std::string box_mjcf(const BoxParams& box);
/// The embedded models/driftless_box.xml as shipped (default configuration).
const std::string& embedded_box_mjcf();

/// What a World's model holds. `full`: the shipped MJCF (carriers, decorations, cameras, lights)
/// for rendering. `physics`: the same bodies, joints, inertias, actuators and sensors without the
/// carriers and decorations (massless, contact-free, mocap): stepping skips their kinematics,
/// and the dynamics are the same to the last bit.
enum class ModelScope { full, physics };

/// The MJCF text of `xml` without its decorations: mocap carrier bodies, geoms of the `visual`
/// class, cameras and lights (see ModelScope::physics).
std::string physics_only_mjcf(const std::string& xml);

struct MotionState;  // twin/motion.hpp

/// Hinge angles and rates at the start of a driven step (before MuJoCo integrates), rad, rad/s.
struct HingeState {
  double angle_rad[2] = {0, 0};
  double rate_radps[2] = {0, 0};
};

/// What a sensor site feels, in the site's axes: angular rate w.r.t. the non-rotating world
/// (rad/s, Earth not included) and specific force (m/s^2): what MuJoCo's gyro and accelerometer
/// report.
struct SiteMotion {
  Eigen::Vector3d w_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d f_mps2 = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_body_from_sensor = Eigen::Matrix3d::Identity();  // site axes to box axes
};

using ModelPtr = std::unique_ptr<mjModel, decltype(&mj_deleteModel)>;
using DataPtr = std::unique_ptr<mjData, decltype(&mj_deleteData)>;

/// Loads MJCF text through an in-memory VFS; throws std::runtime_error with MuJoCo's message.
ModelPtr load_mjcf_string(const std::string& xml, const std::string& name = "model.xml");

/// The box world: owns model and data, caches ids and addresses of every named element.
class World {
 public:
  /// Builds the model from `box` (validated) with the given physics time step (s); `scope`
  /// physics drops the carriers and decorations (no pose_carrier, nothing to render).
  explicit World(const BoxParams& box, double timestep_s = 0.001, ModelScope scope = ModelScope::full);
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  const mjModel* model() const { return model_.get(); }
  mjModel* model() { return model_.get(); }
  const mjData* data() const { return data_.get(); }
  mjData* data() { return data_.get(); }
  const BoxParams& box() const { return box_; }
  /// Body id of the box (base) body.
  int box_body() const { return body_box_; }

  /// Platform i (1 or 2) joint angle (rad) and rate (rad/s), from mjData.
  double platform_angle_rad(int i) const;
  double platform_rate_radps(int i) const;
  double platform_accel_radps2(int i) const;
  /// Sets platform i's joint angle (rad) and rate (rad/s).
  void set_platform(int i, double angle_rad, double rate_radps = 0.0);
  /// Motor command of platform i: the servo reference angle, rad.
  void set_motor_reference(int i, double ref_rad);

  /// The model's gravity in ENU, m/s^2.
  const Eigen::Vector3d& gravity_enu_mps2() const { return gravity_enu_mps2_; }

  /// Motion driver: box pose (ENU), velocity (ENU, m/s) and body-axes angular rate (rad/s).
  void set_base(const Eigen::Vector3d& p_enu_m, const Eigen::Quaterniond& q_enu_from_body,
                const Eigen::Vector3d& v_enu_mps, const Eigen::Vector3d& w_body_radps);
  /// After mj_step1: the generalized force that makes the box follow the given linear (ENU)
  /// and angular (body axes) acceleration exactly (the drive joints carry a huge armature).
  void drive_base(const Eigen::Vector3d& a_enu_mps2, const Eigen::Vector3d& dw_body_radps2);

  /// The driven step, the one place MuJoCo steps the box along a motion: at time t_s, poses the
  /// base at `base` (pose, velocity, rate), sets the servo references (rad), mj_step1, applies the
  /// drive force for the base's accelerations, mj_step2. Returns the hinge state at t_s. With
  /// `sensors`, MuJoCo's gyro/accelerometer hold their values at t_s afterwards; without, the
  /// sensor stage is skipped (it never feeds back into the dynamics).
  HingeState step_driven(double t_s, const MotionState& base, const Eigen::Vector2d& ref_rad,
                         bool sensors = true);

  /// Rigid-body kinematics of platform i's sensor site (1 or 2): from the base motion and the
  /// hinge angle (rad), rate (rad/s) and acceleration (rad/s^2), the site's rate and specific
  /// force in closed form. Equals MuJoCo's gyro/accelerometer for the same state (the kinematic
  /// rest path's truth; tests/twin/test_world.cpp ties the two).
  SiteMotion site_motion(int i, const MotionState& base, double angle_rad, double rate_radps = 0.0,
                         double accel_radps2 = 0.0) const;
  /// Hinge torque (N m, about hinge i's axis) that carries platform i rigidly at `angle_rad` on a
  /// base moving as `base`: the axis component of I dw + w x (I w) + m c x (a_c - g) about the
  /// hinge anchor (Newton-Euler for the platform body; the rotor armature sees only hinge motion).
  double rest_hinge_torque_nm(int i, const MotionState& base, double angle_rad) const;
  /// Torque (N m) the servo of platform i exerts at rest at `angle_rad` with reference `ref_rad`:
  /// kp (ref - angle), clipped to the stall torque (the MJCF actuator at zero rate).
  double motor_rest_torque_nm(double ref_rad, double angle_rad) const;

  /// Sensor readings of MuJoCo's gyro (rad/s, site axes; rate w.r.t. the non-rotating world)
  /// and accelerometer (specific force, m/s^2, site axes) of platform i, from sensordata.
  Eigen::Vector3d mj_gyro(int i) const;
  Eigen::Vector3d mj_accel(int i) const;
  /// Rotation of sensor site i (imu1/imu2) to world (ENU), from site_xmat.
  Eigen::Matrix3d R_enu_from_sensor(int i) const;

  /// Poses the carrier bodies (pan/tilt head, vehicle, ship) from the box pose and hides the
  /// carriers that are not `c`. Call before mj_forward / rendering. A physics-scope world has no
  /// carriers: std::logic_error unless `c` is Carrier::none.
  void pose_carrier(Carrier c, const Eigen::Vector3d& p_enu_m, const Eigen::Quaterniond& q_enu_from_body);

  /// Poses the whole world kinematically (box pose, platform angles in rad, carrier) and runs
  /// mj_forward, for replay and rendering.
  void pose(const Eigen::Vector3d& p_enu_m, const Eigen::Quaterniond& q_enu_from_body,
            double plat1_rad, double plat2_rad, Carrier c);

  /// Mount offsets of the box on its carriers (box origin in the carrier's frame), m.
  static Eigen::Vector3d pan_tilt_axis_enu_m();  // tilt axle centre, ENU
  static Eigen::Vector3d box_on_tilt_head_m();   // box centre in the tilt-yoke frame
  static Eigen::Vector3d box_on_vehicle_m();     // box centre in the vehicle frame
  static Eigen::Vector3d box_on_ship_m();        // box centre in the ship frame

 private:
  int id(int type, const char* name) const;
  void set_visible(int body_id, bool visible);

  BoxParams box_;
  ModelScope scope_;
  ModelPtr model_;
  DataPtr data_;
  int qadr_drive_ = 0, vadr_drive_ = 0;   // drive_x qpos / dof address (x, y, z, then ball)
  int qadr_hinge_[2] = {0, 0}, vadr_hinge_[2] = {0, 0};
  int act_motor_[2] = {0, 0};
  int site_imu_[2] = {0, 0};
  int sadr_gyro_[2] = {0, 0}, sadr_accel_[2] = {0, 0};
  int mocap_pan_ = -1, mocap_tilt_ = -1, mocap_vehicle_ = -1, mocap_ship_ = -1;
  int body_box_ = -1;
  int body_pan_ = -1, body_tilt_ = -1, body_vehicle_ = -1, body_ship_ = -1;
  // platform i's geometry and mass from the compiled model (platform axes at hinge angle 0)
  struct Platform {
    Eigen::Vector3d anchor_box_m;           // hinge anchor, box axes
    Eigen::Matrix3d R_box_from_plat0;       // platform axes at angle 0
    Eigen::Vector3d axis_plat;              // hinge axis, platform axes (unit)
    Eigen::Vector3d site_from_anchor_m;     // sensor site, from the anchor, platform axes
    Eigen::Matrix3d R_plat_from_site;
    double mass_kg = 0;
    Eigen::Vector3d com_from_anchor_m;      // centre of mass, from the anchor, platform axes
    Eigen::Matrix3d inertia_com_kgm2;       // about the centre of mass, platform axes
  };
  Platform plat_[2];
  Eigen::Vector3d gravity_enu_mps2_ = Eigen::Vector3d::Zero();
  void cache_platform(int i, int joint, int site);
  Eigen::Matrix3d R_box_from_plat(int i, double angle_rad) const;
  std::vector<float> geom_alpha_;                   // shipped alpha of every geom (carriers are hidden by alpha 0)
  std::vector<mjtNum> scratch_qacc_, scratch_res_;  // drive_base work space (no per-step allocation)
};

}  // namespace driftless::twin
